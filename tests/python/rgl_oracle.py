#!/usr/bin/python3
"""Independent NumPy evaluation of RGL-EPFL .bsdf files (Dupuy & Jakob 2018), used as an
oracle for the C++ reader (brdf::RglBrdf).

Written from the published algorithm rather than from the C++ code:
  * the file is a "tensor file" (README of ../shared/brdf-data: magic, version, fields);
  * angles map to the unit square as u(theta) = sqrt(theta / (pi/2)), u(phi) = (phi + pi) / 2pi;
  * the VNDF table of each incidence slice is a density on the unit square whose bilinear
    interpolant is normalised to integrate to 1; the "warp" maps a half-vector position
    (u_theta, u_phi) to (X, Y) where Y is the marginal CDF of that density along the phi axis
    and X the conditional CDF along theta at that phi.  Here both are computed as exact integrals
    of the bilinear interpolant, slice by slice, and only then blended between incidence slices
    (integration is linear, so this equals integrating the blended density);
  * f_r * cos(theta_o) = rgb(X, Y) * ndf(u_m) / (4 sigma(u_i)), negative rgb clipped to 0,
    the ndf/sigma factor applied when the file's `jacobian` flag is set.
Everything is float64 and vectorised over direction pairs.

Run as a test:  rgl_oracle.py --driver PATH/rgl_eval_points --data-dir BRDF_DATA_DIR [--pairs N]
The driver evaluates f_r with the C++ code for the same direction pairs; the script fails
(exit 1) when any pair whose f_r is not tiny differs by more than --rtol.
"""
import argparse
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np

DTYPES = {1: np.uint8, 2: np.int8, 3: np.uint16, 4: np.int16, 5: np.uint32, 6: np.int32,
          7: np.uint64, 8: np.int64, 9: np.float16, 10: np.float32, 11: np.float64}


def read_tensor_file(path):
    """Returns {name: numpy array} for every field of a tensor file."""
    raw = open(path, 'rb').read()
    if raw[:12] != b'tensor_file\0' or raw[12:14] != b'\x01\x00':
        raise ValueError(path + ': not a version 1.0 tensor file')
    (count,) = struct.unpack_from('<I', raw, 14)
    pos, out = 18, {}
    for _ in range(count):
        (name_len,) = struct.unpack_from('<H', raw, pos)
        name = raw[pos + 2:pos + 2 + name_len].decode('utf-8')
        pos += 2 + name_len
        rank, dtype, offset = struct.unpack_from('<HBQ', raw, pos)
        pos += 11
        shape = struct.unpack_from('<%dQ' % rank, raw, pos)
        pos += 8 * rank
        dt = np.dtype(DTYPES[dtype]).newbyteorder('<')
        n = int(np.prod(shape)) if shape else 1
        out[name] = np.frombuffer(raw, dt, n, offset).reshape(shape)
    return out


def lerp_weights(grid, x):
    """Left index i (clamped to [0, len-2]) and weight of grid[i+1] for linear interpolation of
    the tabulated parameter `grid` at x; a single-entry grid gives (0, 0)."""
    grid = np.asarray(grid, np.float64)
    if len(grid) == 1:
        return np.zeros(x.shape, np.int64), np.zeros(x.shape)
    i = np.clip(np.searchsorted(grid, x, side='right') - 1, 0, len(grid) - 2)
    w = np.clip((x - grid[i]) / (grid[i + 1] - grid[i]), 0.0, 1.0)
    return i, w


def cell_position(u, n):
    """Vertex index (clamped so that i+1 exists) and fraction for position u in [0, 1] on a grid
    of n vertices spanning the unit interval."""
    x = np.clip(u, 0.0, 1.0) * (n - 1)
    i = np.minimum(np.floor(x).astype(np.int64), n - 2)
    return i, x - i


def bilinear(table, ux, uy, lead=()):
    """Bilinear interpolation of table[..., y, x] (vertices spanning the unit square) at the
    points (ux, uy). `lead` holds per-point index arrays for the leading axes of `table`."""
    ny, nx = table.shape[-2:]
    ix, fx = cell_position(ux, nx)
    iy, fy = cell_position(uy, ny)
    v00, v10 = table[lead + (iy, ix)], table[lead + (iy, ix + 1)]
    v01, v11 = table[lead + (iy + 1, ix)], table[lead + (iy + 1, ix + 1)]
    return (1 - fy) * ((1 - fx) * v00 + fx * v10) + fy * ((1 - fx) * v01 + fx * v11)


class RglOracle:
    def __init__(self, path):
        t = read_tensor_file(path)
        self.theta_i = t['theta_i'].astype(np.float64)
        self.phi_i = t['phi_i'].astype(np.float64)
        self.isotropic = len(self.phi_i) <= 2
        self.jacobian = bool(t['jacobian'][0])
        self.ndf = t['ndf'].astype(np.float64)
        self.sigma = t['sigma'].astype(np.float64)
        self.rgb = t['rgb'].astype(np.float64)          # (P, T, 3, N, N)
        d = t['vndf'].astype(np.float64)                 # (P, T, ny, nx)
        # Exact integral of the bilinear interpolant over the index domain: the mean of the
        # four corners of every cell, summed.
        cells = 0.25 * (d[..., :-1, :-1] + d[..., :-1, 1:] + d[..., 1:, :-1] + d[..., 1:, 1:])
        d = d / cells.sum(axis=(-2, -1))[..., None, None]
        self.density = d
        # Integral along x (theta axis) of each row from 0 to every vertex, and row totals.
        seg = 0.5 * (d[..., :-1] + d[..., 1:])
        self.row_cum = np.concatenate([np.zeros(d.shape[:-1] + (1,)), np.cumsum(seg, -1)], -1)
        self.row_total = self.row_cum[..., -1]
        seg_y = 0.5 * (self.row_total[..., :-1] + self.row_total[..., 1:])
        self.marg_cum = np.concatenate([np.zeros(d.shape[:-2] + (1,)), np.cumsum(seg_y, -1)], -1)

    def slices(self, phi_i, theta_i):
        """(index into P, index into T, weight) for the up to four incidence slices."""
        out = []
        if len(self.phi_i) == 1:
            pcs = [(np.zeros(phi_i.shape, np.int64), np.ones(phi_i.shape))]
        else:
            ip, wp = lerp_weights(self.phi_i, phi_i)
            pcs = [(ip, 1 - wp), (ip + 1, wp)]
        if len(self.theta_i) == 1:
            tcs = [(np.zeros(theta_i.shape, np.int64), np.ones(theta_i.shape))]
        else:
            it, wt = lerp_weights(self.theta_i, theta_i)
            tcs = [(it, 1 - wt), (it + 1, wt)]
        for ip, wp in pcs:
            for it, wt in tcs:
                out.append((ip, it, wp * wt))
        return out

    def warp_inverse(self, um_theta, um_phi, slices):
        """Maps the half-vector position to the unit-square sample of the VNDF warp."""
        ny, nx = self.density.shape[-2:]
        ix, fx = cell_position(um_theta, nx)
        iy, fy = cell_position(um_phi, ny)
        x_num = np.zeros(um_theta.shape)
        x_den = np.zeros(um_theta.shape)
        y_val = np.zeros(um_theta.shape)
        for ip, it, w in slices:
            d, rc = self.density, self.row_cum
            rt, mc = self.row_total, self.marg_cum
            # Integral from 0 to x of row iy and of row iy + 1 (piecewise-linear rows).
            part0 = (rc[ip, it, iy, ix] + fx * d[ip, it, iy, ix] +
                     0.5 * fx * fx * (d[ip, it, iy, ix + 1] - d[ip, it, iy, ix]))
            part1 = (rc[ip, it, iy + 1, ix] + fx * d[ip, it, iy + 1, ix] +
                     0.5 * fx * fx * (d[ip, it, iy + 1, ix + 1] - d[ip, it, iy + 1, ix]))
            r0, r1 = rt[ip, it, iy], rt[ip, it, iy + 1]
            x_num += w * ((1 - fy) * part0 + fy * part1)
            x_den += w * ((1 - fy) * r0 + fy * r1)
            y_val += w * (mc[ip, it, iy] + fy * r0 + 0.5 * fy * fy * (r1 - r0))
        with np.errstate(invalid='ignore', divide='ignore'):
            x_val = np.where(x_den > 0, x_num / x_den, 0.0)
        return x_val, y_val

    def eval_cos(self, wi, wo):
        """f_r * cos(theta_o) for arrays of unit vectors (n, 3); 0 below the horizon."""
        ok = (wi[:, 2] > 0) & (wo[:, 2] > 0)
        h = wi + wo
        h = h / np.linalg.norm(h, axis=1)[:, None]
        theta_i = np.arccos(np.clip(wi[:, 2], -1, 1))
        phi_i = np.arctan2(wi[:, 1], wi[:, 0])
        theta_m = np.arccos(np.clip(h[:, 2], -1, 1))
        phi_m = np.arctan2(h[:, 1], h[:, 0])
        u_theta = lambda th: np.sqrt(th / (np.pi / 2))
        u_phi = lambda ph: (ph + np.pi) / (2 * np.pi)
        um_t = u_theta(theta_m)
        um_p = u_phi(phi_m - phi_i if self.isotropic else phi_m)
        um_p = um_p - np.floor(um_p)
        sl = self.slices(phi_i, theta_i)
        sx, sy = self.warp_inverse(um_t, um_p, sl)
        out = np.zeros((len(wi), 3))
        for c in range(3):
            acc = np.zeros(len(wi))
            for ip, it, w in sl:
                acc += w * bilinear(self.rgb, sx, sy, (ip, it, np.full(len(wi), c)))
            out[:, c] = np.maximum(acc, 0.0)
        if self.jacobian:
            ndf = bilinear(self.ndf, um_t, um_p)
            sig = bilinear(self.sigma, u_theta(theta_i), u_phi(phi_i))
            out *= (ndf / (4 * sig))[:, None]
        out[~ok] = 0
        return out

    def eval(self, wi, wo):
        """f_r (1/sr), not multiplied by cos(theta_o)."""
        out = self.eval_cos(wi, wo)
        ok = wo[:, 2] > 0
        out[ok] /= wo[ok, 2][:, None]
        return out


def sph(theta, phi):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)


def direction_pairs(n, seed):
    """Direction pairs for the comparison: a third uniform over both hemispheres, a third near
    the mirror direction (where glossy lobes live), a third with wi on the file's own incidence
    angles of a typical table (0.49, 0.71 ... rad) and wo uniform."""
    rng = np.random.default_rng(seed)
    k = n // 3
    def uniform(m):
        z = rng.uniform(0.02, 1.0, m)
        ph = rng.uniform(-np.pi, np.pi, m)
        return sph(np.arccos(z), ph)
    wi1, wo1 = uniform(k), uniform(k)
    ti = rng.uniform(0.0, np.radians(85), k)
    pi_ = rng.uniform(-np.pi, np.pi, k)
    wi2 = sph(ti, pi_)
    to = np.clip(ti + rng.normal(0, np.radians(4), k), 0.0, np.radians(88))
    wo2 = sph(to, pi_ + np.pi + rng.normal(0, np.radians(4), k))
    m = n - 2 * k
    wi3 = sph(rng.choice([0.0, 0.4913228, 0.70840764, 1.0527185, 1.2138498], m),
              rng.uniform(-np.pi, np.pi, m))
    wo3 = uniform(m)
    wi = np.concatenate([wi1, wi2, wi3])
    wo = np.concatenate([wo1, wo2, wo3])
    return wi, wo


def compare(driver, path, n, seed, rtol, tiny_fraction):
    wi, wo = direction_pairs(n, seed)
    oracle = RglOracle(path)
    expected = oracle.eval(wi, wo)
    with tempfile.TemporaryDirectory() as tmp:
        pairs = os.path.join(tmp, 'pairs.f64')
        result = os.path.join(tmp, 'result.f64')
        np.concatenate([wi, wo], 1).astype('<f8').tofile(pairs)
        subprocess.run([driver, path, pairs, result], check=True)
        got = np.fromfile(result, '<f8').reshape(-1, 3)
    # "Tiny": below tiny_fraction of the largest value in this sample, per channel, where float
    # tables and the clip at 0 make relative error meaningless.
    scale = np.max(np.abs(expected), axis=0)
    floor = tiny_fraction * scale
    big = np.abs(expected) > floor
    rel = np.abs(got - expected) / np.maximum(np.abs(expected), floor)
    worst = float(rel[big].max()) if big.any() else 0.0
    abs_small = float(np.max(np.abs(got - expected)[~big] / scale[np.nonzero(~big)[1]])) \
        if (~big).any() else 0.0
    print('%-34s pairs %5d  compared %5d  max rel err %.2e  (tiny ones: max err/scale %.1e)'
          % (os.path.basename(path), n, int(big.sum()), worst, abs_small))
    return worst <= rtol and abs_small <= rtol


def write_tensor_file(path, fields):
    """Writes [(name, numpy array)] as a version 1.0 tensor file (data 8-byte aligned)."""
    codes = {np.dtype(v).newbyteorder('<'): k for k, v in DTYPES.items()}
    header = 18 + sum(2 + len(n) + 2 + 1 + 8 + 8 * a.ndim for n, a in fields)
    offset, blocks, head = (header + 7) // 8 * 8, [], b''
    for name, a in fields:
        a = np.ascontiguousarray(a, a.dtype.newbyteorder('<'))
        head += struct.pack('<H', len(name)) + name.encode()
        head += struct.pack('<HBQ', a.ndim, codes[a.dtype], offset)
        head += b''.join(struct.pack('<Q', d) for d in a.shape)
        blocks.append((offset, a.tobytes()))
        offset = (offset + a.nbytes + 7) // 8 * 8
    out = bytearray(b'tensor_file\0\x01\x00' + struct.pack('<I', len(fields)) + head)
    for off, data in blocks:
        out += bytes(off - len(out)) + data
    open(path, 'wb').write(bytes(out))


def synthetic_file(path, seed, anisotropic, jacobian):
    """A random but smooth material: exercises what the real files do not (several phi_i
    slices, jacobian = 0, non-square tables, negative RGB)."""
    rng = np.random.default_rng(seed)
    phi = np.array([-np.pi, -1.0, 0.5, np.pi], np.float32) if anisotropic else \
        np.array([0.0], np.float32)
    theta = np.array([0.0, 0.3, 0.8, 1.2, np.pi / 2], np.float32)
    p, t, vy, vx, ny, nx = len(phi), len(theta), 17, 23, 9, 12
    x = np.linspace(0, 1, vx)[None, None, None, :]
    y = np.linspace(0, 1, vy)[None, None, :, None]
    a = rng.uniform(0.5, 3.0, (p, t, 1, 1))
    vndf = (np.exp(-a * x * 3) * (1.2 + np.cos(2 * np.pi * (y - rng.uniform(0, 1, (p, t, 1, 1)))))
            * x).astype(np.float32)
    rgb = rng.uniform(-0.05, 1.0, (p, t, 3, ny, nx)).astype(np.float32)
    ndf = rng.uniform(0.1, 5.0, (2, 31)).astype(np.float32)
    sigma = rng.uniform(0.2, 1.0, (2, 31)).astype(np.float32)
    write_tensor_file(path, [
        ('description', np.frombuffer(b'oracle synthetic', np.uint8)),
        ('phi_i', phi), ('theta_i', theta), ('sigma', sigma), ('ndf', ndf), ('vndf', vndf),
        ('rgb', rgb), ('jacobian', np.array([jacobian], np.uint8))])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--driver', required=True)
    ap.add_argument('--data-dir', required=True,
                    help='the brdf-data folder (its rgl/ is read); $BRDF_DATA_DIR overrides it')
    ap.add_argument('--files', nargs='*', default=[
        'paper_white_rgb.bsdf', 'chm_mint_rgb.bsdf', 'cg_sunflower_rgb.bsdf',
        'irid_flake_paint1_fine_rgb.bsdf', 'ilm_solo_m_68_rgb.bsdf', 'cc_ibiza_sunset_rgb.bsdf'])
    ap.add_argument('--extra', nargs='*', default=[], help='further .bsdf files (any path)')
    ap.add_argument('--pairs', type=int, default=3000)
    ap.add_argument('--rtol', type=float, default=1e-6)
    ap.add_argument('--tiny', type=float, default=1e-6)
    args = ap.parse_args()
    ok = True
    data_dir = os.environ.get('BRDF_DATA_DIR') or args.data_dir
    rgl_dir = os.path.join(data_dir, 'rgl')
    if not os.path.isdir(rgl_dir):
        sys.exit(f"third-party data folder '{rgl_dir}' not found: set BRDF_DATA_DIR to the "
                 "brdf-data folder (see README.md, 'Test data')")
    paths = [os.path.join(rgl_dir, f) for f in args.files] + args.extra
    with tempfile.TemporaryDirectory() as tmp:
        for name, aniso, jac in [('synthetic_anisotropic.bsdf', True, 1),
                                 ('synthetic_jacobian0.bsdf', False, 0)]:
            paths.append(os.path.join(tmp, name))
            synthetic_file(paths[-1], len(paths), aniso, jac)
        for i, path in enumerate(paths):
            ok &= compare(args.driver, path, args.pairs, 1234 + i, args.rtol, args.tiny)
    if not ok:
        print('FAILED: C++ and the NumPy oracle differ by more than rtol %.1e' % args.rtol)
        return 1
    print('OK')
    return 0


if __name__ == '__main__':
    sys.exit(main())
