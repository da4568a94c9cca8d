#!/usr/bin/python3
"""Independent reference values for the preview tests (tests/processing/preview_test.cpp).

Written from the formulas of docs/design.md §9 and the map definitions of docs/preview.md with
NumPy only; nothing here calls or mirrors the C++ code under test.

  albedo MODEL KD KS SHAPE THETA_O_DEG...   directional albedo ∫ f_r(ω_i, ω_o) cosθ_i dω_i for
                                             one channel, per viewer polar angle (φ_o = 0)
  axes NX NY NZ                              radiance of a white Lambertian with normal n under
                                             the axis-coded map (continuous, not pixelised), RGB
  write-axes DIR W H                         the axis-coded map at W × H pixel centres, written
                                             as DIR/axes.exr (OpenImageIO, float) and as
                                             DIR/axes.hdr (Radiance RGBE with run-length
                                             encoded scanlines, written here byte by byte), in
                                             the orientation of docs/preview.md: row 0 at θ = 0,
                                             column 0 at φ = 0, φ increasing to the right
Prints one line of space-separated numbers (write-axes: the file names).
"""
import sys

import numpy as np


def ggx(l, v, kd, f0, alpha):
    h = l + v
    h /= np.linalg.norm(h, axis=0)
    cos_h = h[2]
    tan2_h = (1.0 - cos_h ** 2) / cos_h ** 2
    d = alpha ** 2 / (np.pi * cos_h ** 4 * (alpha ** 2 + tan2_h) ** 2)

    def g1(c):
        tan2 = (1.0 - c ** 2) / c ** 2
        return 2.0 / (1.0 + np.sqrt(1.0 + alpha ** 2 * tan2))

    vh = np.sum(v * h, axis=0)
    f = f0 + (1.0 - f0) * (1.0 - vh) ** 5
    return kd / np.pi + f * g1(l[2]) * g1(v[2]) * d / (4.0 * l[2] * v[2])


def brdf(model, l, v, kd, ks, shape):
    if model == "lambert":
        return np.full(l.shape[1], kd / np.pi)
    if model == "ggx":
        return ggx(l, v, kd, ks, shape)
    if model == "lafortune":
        r = np.stack([-l[0], -l[1], l[2]])
        c = np.maximum(np.sum(v * r, axis=0), 0.0)
        return kd / np.pi + ks * (shape + 2.0) / (2.0 * np.pi) * c ** shape
    if model == "ward":
        h = l + v
        h /= np.linalg.norm(h, axis=0)
        tan2 = (1.0 - h[2] ** 2) / h[2] ** 2
        return kd / np.pi + ks * np.exp(-tan2 / shape ** 2) / (
            4.0 * np.pi * shape ** 2 * np.sqrt(l[2] * v[2]))
    raise SystemExit("unknown model " + model)


def albedo(model, kd, ks, shape, theta_o_deg):
    # Midpoint rule in (cosθ_i, φ_i): dω = dμ dφ, so the quadrature weights are uniform.
    n_mu, n_phi = 600, 600
    mu = (np.arange(n_mu) + 0.5) / n_mu
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2.0 * np.pi
    mu_g, phi_g = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - mu_g ** 2)
    l = np.stack([s * np.cos(phi_g), s * np.sin(phi_g), mu_g]).reshape(3, -1)
    weight = (1.0 / n_mu) * (2.0 * np.pi / n_phi)
    out = []
    for t in theta_o_deg:
        tr = np.radians(t)
        v = np.array([np.sin(tr), 0.0, np.cos(tr)])[:, None] * np.ones((1, l.shape[1]))
        f = brdf(model, l, v, kd, ks, shape)
        out.append(float(np.sum(f * l[2]) * weight))
    return out


def axes_map(w):
    px, py, pz = (np.maximum(0.0, w[k]) for k in range(3))
    nx, ny, nz = (np.maximum(0.0, -w[k]) for k in range(3))
    return np.stack([px + 0.5 * (ny + nz), py + 0.5 * (nx + nz), pz + 0.5 * (nx + ny)])


def axes_lambert(n):
    n = np.asarray(n, float)
    n /= np.linalg.norm(n)
    n_t, n_p = 600, 1200
    theta = (np.arange(n_t) + 0.5) / n_t * np.pi
    phi = (np.arange(n_p) + 0.5) / n_p * 2.0 * np.pi
    t_g, p_g = np.meshgrid(theta, phi, indexing="ij")
    w = np.stack([np.sin(t_g) * np.cos(p_g), np.sin(t_g) * np.sin(p_g), np.cos(t_g)]).reshape(3, -1)
    d_omega = (np.sin(t_g) * (np.pi / n_t) * (2.0 * np.pi / n_p)).reshape(-1)
    cos = np.maximum(0.0, n @ w)
    radiance = axes_map(w)
    return list(np.sum(radiance * cos * d_omega, axis=1) / np.pi)


def axes_pixels(width, height):
    """(H, W, 3) float32 radiance of the axis-coded map at the pixel centres."""
    theta = (np.arange(height) + 0.5) / height * np.pi
    phi = (np.arange(width) + 0.5) / width * 2.0 * np.pi
    t_g, p_g = np.meshgrid(theta, phi, indexing="ij")
    w = np.stack([np.sin(t_g) * np.cos(p_g), np.sin(t_g) * np.sin(p_g), np.cos(t_g)])
    return np.ascontiguousarray(np.moveaxis(axes_map(w), 0, -1), dtype=np.float32)


def rgbe(pixels):
    """Radiance RGBE bytes (H, W, 4) of float RGB: mantissas of the shared exponent e with
    max = m·2^(e−128) per Greg Ward's format (frexp: max = f·2^k, f in [0.5, 1))."""
    top = pixels.max(axis=-1)
    f, k = np.frexp(top)
    scale = np.where(top > 1e-32, f * 256.0 / np.maximum(top, 1e-38), 0.0)
    out = np.zeros(pixels.shape[:2] + (4,), np.uint8)
    out[..., :3] = np.clip(pixels * scale[..., None], 0, 255).astype(np.uint8)
    out[..., 3] = np.where(top > 1e-32, k + 128, 0).astype(np.uint8)
    return out


def rle_channel(values):
    """One channel of a scanline in the new RLE: runs (128 + n, value) for n ≥ 3 equal bytes,
    literals (n, bytes…) otherwise, n ≤ 127."""
    out, i, n = bytearray(), 0, len(values)
    while i < n:
        run = 1
        while i + run < n and run < 127 and values[i + run] == values[i]:
            run += 1
        if run >= 3:
            out += bytes([128 + run, values[i]])
            i += run
            continue
        start = i
        while i < n and i - start < 127:
            if i + 2 < n and values[i] == values[i + 1] == values[i + 2]:
                break
            i += 1
        out += bytes([i - start]) + bytes(values[start:i])
    return out


def write_axes(out_dir, width, height):
    import OpenImageIO as oiio  # Debian python3-openimageio
    pixels = axes_pixels(width, height)
    exr = out_dir + "/axes.exr"
    spec = oiio.ImageSpec(width, height, 3, "float")
    out = oiio.ImageOutput.create(exr)
    if out is None or not out.open(exr, spec):
        raise SystemExit("preview_oracle.py: cannot write " + exr + ": " + oiio.geterror())
    if not out.write_image(pixels) or not out.close():
        raise SystemExit("preview_oracle.py: cannot write " + exr + ": " + out.geterror())
    hdr = out_dir + "/axes.hdr"
    assert 8 <= width < 32768
    data = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    data += ("-Y %d +X %d\n" % (height, width)).encode()
    codes = rgbe(pixels)
    for row in codes:
        data += bytes([2, 2, width >> 8, width & 255])
        for c in range(4):
            data += rle_channel(row[:, c].tobytes())
    open(hdr, "wb").write(bytes(data))
    return [exr, hdr]


def main(argv):
    if argv[0] == "albedo":
        model, kd, ks, shape = argv[1], float(argv[2]), float(argv[3]), float(argv[4])
        values = albedo(model, kd, ks, shape, [float(t) for t in argv[5:]])
    elif argv[0] == "axes":
        values = axes_lambert([float(x) for x in argv[1:4]])
    elif argv[0] == "write-axes":
        print(" ".join(write_axes(argv[1], int(argv[2]), int(argv[3]))))
        return
    else:
        raise SystemExit("usage: preview_oracle.py albedo|axes ...")
    print(" ".join(repr(x) for x in values))


if __name__ == "__main__":
    main(sys.argv[1:])
