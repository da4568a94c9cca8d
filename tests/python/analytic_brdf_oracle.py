#!/usr/bin/python3
"""Independent numpy transcription of the Blinn-Phong and Ward rows of docs/design.md §9, for
tests/device/driver_test.cpp (written from the formulas, not from brdf-toolchain's C++).

Reads lines "MODEL KD_R KD_G KD_B KS_R KS_G KS_B SHAPE THETA_IN PHI_IN THETA_OUT PHI_OUT" on
stdin (angles in degrees, directions pointing away from the surface, z the normal) and prints
one line "R G B" of f_r (1/sr, not multiplied by cos theta) per input line:
  blinn-phong  kd/pi + ks (n+8)/(8 pi) max(n.h, 0)^n
  ward         rho_d/pi + rho_s exp(-tan^2(theta_h)/alpha^2) / (4 pi alpha^2 sqrt(cos_i cos_o))
with h = normalize(l + v); zero when either direction is at or below the horizon.
"""
import sys

import numpy as np


def direction(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


def f_r(model, kd, ks, shape, l, v):
    if l[2] <= 0 or v[2] <= 0:
        return np.zeros(3)
    h = (l + v) / np.linalg.norm(l + v)
    cos_h = h[2]
    if model == "blinn-phong":
        return kd / np.pi + ks * (shape + 8) / (8 * np.pi) * max(cos_h, 0.0) ** shape
    if model == "ward":
        tan2_h = (1 - cos_h * cos_h) / (cos_h * cos_h)
        a2 = shape * shape
        return kd / np.pi + ks * np.exp(-tan2_h / a2) / (4 * np.pi * a2 * np.sqrt(l[2] * v[2]))
    raise SystemExit("unknown model " + model)


for line in sys.stdin:
    f = line.split()
    if not f:
        continue
    vals = [float(x) for x in f[1:]]
    kd, ks, shape = np.array(vals[0:3]), np.array(vals[3:6]), vals[6]
    l, v = direction(vals[7], vals[8]), direction(vals[9], vals[10])
    r = f_r(f[0], kd, ks, shape, l, v)
    print("%.17g %.17g %.17g" % (r[0], r[1], r[2]))
