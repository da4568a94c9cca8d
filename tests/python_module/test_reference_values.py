"""Values against references from outside the module: a MERL file (written here in numpy in
MERL's published layout, no MERL .binary being available) against `brdf eval --pairs` and
against MERL's own lookup rule (nearest bin in Rusinkiewicz half/difference angles, transcribed
in numpy from the brdf-data README's format notes); RGL files against the numpy transcription
of RGL's reference evaluator the C++ tests use (tests/python/rgl_oracle.py); an exported LUT
against a numpy trilinear lookup of the same texture written from docs/design.md §5
(bench/python/numpy_trilinear.py, the eval_deg speed baseline)."""

import pathlib
import sys

import numpy as np
import pytest

import brdf
from conftest import run_cli
from test_eval_against_cli import assert_same_as_cli, directions, random_pairs

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python"))
sys.path.insert(0, str(ROOT / "bench" / "python"))
import rgl_oracle  # noqa: E402
from numpy_trilinear import NumpyLut  # noqa: E402

TH, TD, PD = 90, 90, 180
SCALE = np.array([1 / 1500, 1.15 / 1500, 1.66 / 1500])


def merl_table():
    """Raw per-channel planes (3, 90, 90, 180): a smooth function of the bin indices, with a
    corner of unmeasured (negative) bins."""
    h, d, p = np.meshgrid(np.arange(TH), np.arange(TD), np.arange(PD), indexing="ij")
    base = 40.0 + 300.0 * np.exp(-h / 6.0) * (1 + 0.3 * np.cos(np.radians(2 * p))) + 0.5 * d
    planes = np.stack([base, 0.8 * base, 0.6 * base + 5.0])
    planes[:, 80:, 85:, :] = -1.0
    return planes


def write_merl(path, planes):
    with open(path, "wb") as f:
        np.array([TH, TD, PD], "<i4").tofile(f)
        planes.astype("<f8").tofile(f)


def merl_lookup(planes, wi, wo):
    """MERL's reference rule: half vector h, difference vector d in the frame of h; bins
    i_θh = floor(sqrt(θh/90°)·90), i_θd = floor(θd/90°·90), i_φd = floor(φd/180°·180) with φd
    folded into [0°, 180°) (reciprocity); value × scale; unmeasured bins (< 0) as 0."""
    h = wi + wo
    h /= np.linalg.norm(h, axis=1)[:, None]
    theta_h = np.arccos(np.clip(h[:, 2], -1, 1))
    phi_h = np.arctan2(h[:, 1], h[:, 0])

    def rot_z(v, a):
        c, s = np.cos(a), np.sin(a)
        return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1], v[:, 2]], 1)

    def rot_y(v, a):
        c, s = np.cos(a), np.sin(a)
        return np.stack([c * v[:, 0] + s * v[:, 2], v[:, 1], -s * v[:, 0] + c * v[:, 2]], 1)

    d = rot_y(rot_z(wi, -phi_h), -theta_h)
    theta_d = np.arccos(np.clip(d[:, 2], -1, 1))
    phi_d = np.mod(np.arctan2(d[:, 1], d[:, 0]), np.pi)
    ih = np.clip(np.floor(np.sqrt(theta_h / (np.pi / 2)) * TH), 0, TH - 1).astype(int)
    idd = np.clip(np.floor(theta_d / (np.pi / 2) * TD), 0, TD - 1).astype(int)
    ip = np.clip(np.floor(phi_d / np.pi * PD), 0, PD - 1).astype(int)
    raw = planes[:, ih, idd, ip].T
    return np.where(raw < 0, 0.0, raw * SCALE)


def test_merl_file_matches_cli_and_merl_lookup(brdf_tool, tmp_path):
    path = tmp_path / "synthetic.binary"
    planes = merl_table()
    write_merl(path, planes)
    s, pairs, got = assert_same_as_cli(brdf_tool, str(path), tmp_path, seed=11)
    assert s.evaluation == "measured_database"
    # Away from bin edges (where the two roundings of the angles may pick neighbouring bins)
    # the values are MERL's.
    wi, wo = directions(pairs[0], pairs[1]), directions(pairs[2], pairs[3])
    above = (wi[:, 2] > 1e-3) & (wo[:, 2] > 1e-3)
    expected = merl_lookup(planes, wi[above], wo[above])
    values = s.eval(wi[above], wo[above])
    agree = np.all(np.isclose(values, expected, rtol=1e-12, atol=0), axis=1)
    assert agree.mean() > 0.99, f"{(~agree).sum()} of {agree.size} pairs differ"
    assert np.count_nonzero(expected) > 0.9 * expected.size


@pytest.mark.parametrize("name", ["aurora_white_rgb.bsdf", "chm_mint_rgb.bsdf",
                                  "cc_ibiza_sunset_rgb.bsdf"])
def test_rgl_values_match_the_reference_evaluator(data_dir, name):
    path = data_dir / "rgl" / name
    wi, wo = rgl_oracle.direction_pairs(3000, seed=77)
    expected = rgl_oracle.RglOracle(str(path)).eval(wi, wo)
    got = brdf.open(path).eval(wi, wo)
    # rgl_oracle's comparison rule: relative error where f_r is not tiny (1e-6 of the largest).
    scale = np.max(np.abs(expected), axis=0)
    big = np.abs(expected) > 1e-6 * scale
    rel = np.abs(got - expected) / np.maximum(np.abs(expected), 1e-6 * scale)
    assert big.sum() > 0.5 * big.size
    assert rel[big].max() <= 1e-6, rel[big].max()


def test_exported_lut_matches_numpy_trilinear_lookup(brdf_tool, tmp_path):
    out = tmp_path / "lut"
    code, _, err = run_cli(brdf_tool, "convert", "copper", "--out", out, "--formats",
                           "ktx2,json", "--quiet")
    assert code == 0, err
    ktx2 = out / "copper.ktx2"
    pairs = random_pairs(seed=12)
    expected = NumpyLut.from_ktx2(str(ktx2)).eval_deg(*pairs)
    got = brdf.open(ktx2).eval_deg(*pairs)
    # float32 interpolation weights in the library, float64 in numpy.
    np.testing.assert_allclose(got, expected, rtol=2e-6, atol=1e-7 * expected.max())
    assert np.ptp(expected) > 0.1
