#!/usr/bin/python3
"""Independent value of a capture evaluated through its LUT (tests/processing/measurement_brdf_test.cpp).

Written from docs/design.md §5 (the LUT, its texel centres, the GPU-style trilinear lookup and
the reciprocity rule beyond the measured θin), §6 with p = 1 (the value at θb held up to the
horizon and below it) and §9 (GGX) with NumPy only; nothing here calls or mirrors the C++ code.

The capture is the noise-free reference grid of one GGX material: for each θin of the list,
θout = 0…THETA_B in 1° steps, φout = 0…359° in 1° steps, values rounded to float32 as a .bpc
file stores them. A slice is read between its grid nodes bilinearly in (θout, φout) (φ wraps),
each LUT texel is that reading at the texel's outgoing direction (rounded to float32), and a
query reads the texels trilinearly at the centre-exact coordinates of §5.

  capture_eval_oracle.py KD F0 ALPHA THETA_IN_LIST THETA_B  TI,TO,PO ...
      KD, F0, ALPHA: one number each (a grey material); THETA_IN_LIST: comma-separated degrees,
      ascending; each query: light at (TI, 0), view at (TO, PO), degrees.
Prints one f_r value per query, one per line.
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from preview_oracle import ggx  # noqa: E402  (the §9 formula, NumPy)

DEG = math.pi / 180.0


def direction(theta_deg, phi_deg):
    t, p = theta_deg * DEG, phi_deg * DEG
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def specular(theta_m_deg, w):
    """S(θm)·w of §5; S is its own inverse."""
    c, s = math.cos(theta_m_deg * DEG), math.sin(theta_m_deg * DEG)
    return np.array([-c * w[0] - s * w[2], -w[1], -s * w[0] + c * w[2]])


class Capture:
    def __init__(self, kd, f0, alpha, theta_in, theta_b):
        self.theta_in = theta_in
        self.theta_b = theta_b
        self.grid = []  # per slice: (θb + 1, 360) float32
        rows = np.arange(theta_b + 1, dtype=float)
        cols = np.arange(360, dtype=float)
        tt, pp = np.meshgrid(rows * DEG, cols * DEG, indexing="ij")
        v = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)]).reshape(3, -1)
        for ti in theta_in:
            l = np.repeat(direction(ti, 0.0)[:, None], v.shape[1], axis=1)
            f = ggx(l, v.copy(), kd, f0, alpha).reshape(len(rows), 360)
            self.grid.append(f.astype(np.float32).astype(float))
        self.texel_cache = {}

    def slice_value(self, k, theta_deg, phi_deg):
        """Bilinear on slice k's (θout, φout) grid; θ held at θb beyond it (§6, p = 1)."""
        g = self.grid[k]
        t = min(theta_deg, float(self.theta_b))
        j0 = min(int(math.floor(t)), self.theta_b - 1)
        ft = t - j0
        u = phi_deg % 360.0
        i0 = int(math.floor(u)) % 360
        fu = u - math.floor(u)
        i1 = (i0 + 1) % 360
        a = g[j0, i0] + (g[j0, i1] - g[j0, i0]) * fu
        b = g[j0 + 1, i0] + (g[j0 + 1, i1] - g[j0 + 1, i0]) * fu
        return a + (b - a) * ft

    def texel(self, k, j, i):
        key = (k, j, i)
        if key not in self.texel_cache:
            st = 0.0 if j in (0, 180) else math.sin(j * DEG)
            wd = np.array([st * math.cos(i * DEG), st * math.sin(i * DEG), math.cos(j * DEG)])
            w = specular(self.theta_in[k], wd)
            if w[2] < 0 and math.hypot(w[0], w[1]) < 1e-9:  # the nadir: mean over φout
                value = float(np.mean(self.grid[k][self.theta_b]))
            else:
                theta = math.degrees(math.acos(max(-1.0, min(1.0, w[2]))))
                phi = math.degrees(math.atan2(w[1], w[0])) % 360.0
                value = self.slice_value(k, theta, phi)
            self.texel_cache[key] = float(np.float32(value))
        return self.texel_cache[key]

    def slice_coordinate(self, ti):
        t = self.theta_in
        if len(t) < 2:
            return 0.0
        delta = t[1] - t[0]
        if all(abs(t[n] - (t[0] + n * delta)) <= 1e-9 * max(1.0, t[n]) for n in range(len(t))):
            return (ti - t[0]) / delta
        i = min(max(int(np.searchsorted(t, ti, side="right")), 1), len(t) - 1)
        return (i - 1) + (ti - t[i - 1]) / (t[i] - t[i - 1])

    def lookup(self, ti, to, po):
        """The texture read of §5: trilinear, clamp-to-edge, centre-exact."""
        wd = specular(ti, direction(to, po))
        theta_d = math.degrees(math.acos(max(-1.0, min(1.0, wd[2]))))
        phi_d = math.degrees(math.atan2(wd[1], wd[0])) % 360.0

        def taps(x, n):
            i0 = math.floor(x)
            return min(max(i0, 0), n - 1), min(max(i0 + 1, 0), n - 1), x - i0

        x0, x1, tx = taps(phi_d, 361)
        y0, y1, ty = taps(theta_d, 181)
        z0, z1, tz = taps(self.slice_coordinate(ti), len(self.theta_in))

        def bilinear(k):
            top = self.texel(k, y0, x0) + (self.texel(k, y0, x1) - self.texel(k, y0, x0)) * tx
            bottom = self.texel(k, y1, x0) + (self.texel(k, y1, x1) - self.texel(k, y1, x0)) * tx
            return top + (bottom - top) * ty

        s0, s1 = bilinear(z0), bilinear(z1)
        return s0 + (s1 - s0) * tz

    def evaluate(self, ti, to, po):
        """§5's evaluation rule: reciprocity beyond the measured θin range, then the lookup."""
        lo, hi = self.theta_in[0], self.theta_in[-1]

        def outside(t):
            return max(lo - t, t - hi, 0.0)

        if outside(ti) > 1e-3 and outside(to) < outside(ti):  # §5: within 1e-3° is inside
            return self.lookup(to, ti, -po)
        return self.lookup(ti, to, po)


def main(argv):
    kd, f0, alpha = (float(x) for x in argv[1:4])
    theta_in = [float(x) for x in argv[4].split(",")]
    theta_b = int(argv[5])
    capture = Capture(kd, f0, alpha, theta_in, theta_b)
    for query in argv[6:]:
        ti, to, po = (float(x) for x in query.split(","))
        print("%.12g" % capture.evaluate(ti, to, po))


if __name__ == "__main__":
    main(sys.argv)
