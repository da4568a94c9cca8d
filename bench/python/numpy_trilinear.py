#!/usr/bin/python3
"""A pure-numpy evaluation of an exported LUT (.ktx2, RGB9E5), written from docs/design.md §5,
not from the C++ code: the baseline eval_deg's speed is compared with
(docs/benchmarks/python.md), and the independent reference tests/python_module compares
eval_deg's angle-space sampling with.

The rule: light at (θin, φin), view at (θout, φout); only φ = φout − φin matters. Beyond the
measured θin range, when the view is nearer that range than the light, light and view are
exchanged (reciprocity; φ → −φ). The view is expressed in the specular frame of θin,
ω_d = S(θin)·ω_out with S = [[−cos, 0, −sin], [0, −1, 0], [−sin, 0, cos]] (θd its polar angle,
φd its azimuth in [0°, 360°)); texel centres sit at φd = i·1°, θd = j·1°, θin = θin,0 + k·Δin;
the lookup is trilinear with clamp-to-edge addressing, as a GPU samples the 3D texture.

    lut = NumpyLut.from_ktx2("copper.ktx2")   # θin list from the sidecar copper.json beside it
    f = lut.eval_deg(theta_in, phi_in, theta_out, phi_out)   # (N, 3) float64
"""
import json
import os
import struct

import numpy as np

THETA_IN_TOLERANCE_DEG = 1e-3  # docs/design.md §5: within this, θin counts as measured


def ktx2_rgb9e5(path):
    """The texels of a KTX2 file's single RGB9E5 level as float64 (depth, height, width, 3)."""
    data = open(path, "rb").read()
    if data[:12] != b"\xabKTX 20\xbb\r\n\x1a\n":
        raise ValueError(path + ": not a KTX 2.0 file")
    vk_format, _, width, height, depth = struct.unpack_from("<5I", data, 12)
    if vk_format != 123:  # VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
        raise ValueError(f"{path}: vkFormat {vk_format}, not RGB9E5")
    offset, length = struct.unpack_from("<QQ", data, 80)
    words = np.frombuffer(data, "<u4", length // 4, offset).astype(np.int64)
    scale = np.exp2(((words >> 27) & 31) - 24.0)
    rgb = np.stack([(words & 511) * scale, ((words >> 9) & 511) * scale,
                    ((words >> 18) & 511) * scale], axis=-1)
    return rgb.reshape(depth, height, width, 3)


class NumpyLut:
    def __init__(self, texels, theta_in_deg):
        self.texels = np.ascontiguousarray(texels, dtype=np.float64)
        self.theta_in = np.asarray(theta_in_deg, dtype=np.float64)
        k, h, w, _ = self.texels.shape
        if k != len(self.theta_in):
            raise ValueError(f"{k} slices but {len(self.theta_in)} θin values")
        self.k, self.h, self.w = k, h, w

    @classmethod
    def from_ktx2(cls, path):
        sidecar = os.path.splitext(path)[0] + ".json"
        return cls(ktx2_rgb9e5(path), json.load(open(sidecar))["theta_in_deg"])

    def slice_coordinate(self, theta_in):
        """k + t: (θin − θin,0)/Δin for an evenly spaced list, else piecewise linear between
        neighbours (extended beyond the ends with the end intervals; the lookup clamps)."""
        if self.k < 2:
            return np.zeros_like(theta_in)
        th = self.theta_in
        d = th[1] - th[0]
        if np.allclose(th, th[0] + d * np.arange(self.k), rtol=0, atol=1e-9):
            return (theta_in - th[0]) / d
        i = np.clip(np.searchsorted(th, theta_in, side="right"), 1, self.k - 1)
        return (i - 1) + (theta_in - th[i - 1]) / (th[i] - th[i - 1])

    def eval_deg(self, theta_in, phi_in, theta_out, phi_out):
        ti, pi, to, po = (np.asarray(a, dtype=np.float64) for a in (theta_in, phi_in, theta_out,
                                                                     phi_out))
        phi = np.where(ti > 0, np.mod(po - pi, 360.0), np.mod(po, 360.0))
        lo, hi = self.theta_in[0], self.theta_in[-1]
        outside_in = np.maximum.reduce([lo - ti, ti - hi, np.zeros_like(ti)])
        outside_out = np.maximum.reduce([lo - to, to - hi, np.zeros_like(to)])
        swap = (outside_in > THETA_IN_TOLERANCE_DEG) & (outside_out < outside_in)
        ti, to, phi = np.where(swap, to, ti), np.where(swap, ti, to), np.where(swap, -phi, phi)
        t, p, a = np.radians(to), np.radians(phi), np.radians(ti)
        x, y, z = np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)
        c, s = np.cos(a), np.sin(a)
        xd, yd, zd = -c * x - s * z, -y, -s * x + c * z
        theta_d = np.degrees(np.arccos(np.clip(zd, -1.0, 1.0)))
        phi_d = np.mod(np.degrees(np.arctan2(yd, xd)), 360.0)
        return self.trilinear(phi_d, theta_d, self.slice_coordinate(ti))

    def trilinear(self, x, y, z):
        """Texel coordinates (texel centres at integers), clamp-to-edge."""
        def taps(v, n):
            f = np.floor(v)
            i0 = f.astype(np.int64)
            return np.clip(i0, 0, n - 1), np.clip(i0 + 1, 0, n - 1), (v - f)[:, None]
        x0, x1, tx = taps(np.ravel(x), self.w)
        y0, y1, ty = taps(np.ravel(y), self.h)
        z0, z1, tz = taps(np.ravel(z), self.k)
        L = self.texels

        def bilinear(zi):
            top = L[zi, y0, x0] * (1 - tx) + L[zi, y0, x1] * tx
            bottom = L[zi, y1, x0] * (1 - tx) + L[zi, y1, x1] * tx
            return top * (1 - ty) + bottom * ty
        return bilinear(z0) * (1 - tz) + bilinear(z1) * tz
