"""brdf.open(...).eval_deg / .eval against `brdf eval --pairs` on the same files.

`brdf eval --pairs` prints each value with printf "%.9g"; the module's float64 values are
formatted the same way and the texts compared exactly (both are correctly rounded, so equal
texts at 9 significant digits is what "bit for bit" can mean through the CLI's output)."""

import numpy as np
import pytest

import brdf
from conftest import run_cli

N_PAIRS = 4000


def random_pairs(seed):
    rng = np.random.default_rng(seed)
    theta_in = rng.uniform(0, 90, N_PAIRS)
    phi_in = rng.uniform(-360, 360, N_PAIRS)
    theta_out = rng.uniform(0, 90, N_PAIRS)
    phi_out = rng.uniform(0, 360, N_PAIRS)
    # The ends of the polar range and the normal itself, exactly.
    theta_in[:4] = [0, 90, 0, 60]
    theta_out[:4] = [0, 0, 90, 60]
    return theta_in, phi_in, theta_out, phi_out


def cli_values(tool, source, pairs, tmp_path):
    pairs_file = tmp_path / "pairs.txt"
    # repr() writes the shortest text that reads back as the same double.
    pairs_file.write_text(
        "".join(f"{a!r} {b!r} {c!r} {d!r}\n" for a, b, c, d in zip(*(p.tolist() for p in pairs))))
    code, out, err = run_cli(tool, "eval", source, "--pairs", pairs_file)
    assert code == 0, err
    lines = out.splitlines()
    assert len(lines) == N_PAIRS
    return lines


def module_lines(values):
    return [" ".join("%.9g" % v for v in row) for row in values.tolist()]


def assert_same_as_cli(tool, source, tmp_path, seed):
    pairs = random_pairs(seed)
    expected = cli_values(tool, source, pairs, tmp_path)
    s = brdf.open(source)
    got = s.eval_deg(*pairs)
    assert got.shape == (N_PAIRS, 3) and got.dtype == np.float64
    mismatches = [(i, e, g) for i, (e, g) in enumerate(zip(expected, module_lines(got))) if e != g]
    assert not mismatches, f"{len(mismatches)} of {N_PAIRS} differ, first: {mismatches[:3]}"
    # Non-trivial values: not all zero, and they vary over the pairs.
    assert np.count_nonzero(got) > N_PAIRS and np.ptp(got) > 0
    return s, pairs, got


def directions(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def test_library_material_matches_cli(brdf_tool, tmp_path):
    s, pairs, got = assert_same_as_cli(brdf_tool, "gold", tmp_path, seed=1)
    assert s.evaluation == "analytic"
    # eval with numpy's unit vectors: the same directions up to numpy's sin/cos rounding.
    wi, wo = directions(pairs[0], pairs[1]), directions(pairs[2], pairs[3])
    np.testing.assert_allclose(s.eval(wi, wo), got, rtol=1e-9, atol=1e-12)


def test_noise_free_capture_matches_cli(brdf_tool, tmp_path):
    capture = tmp_path / "plastic.bpc"
    code, _, err = run_cli(brdf_tool, "capture", "--device", "sim", "--material",
                           "plastic_glossy_red", "--sample", "red", "--noise", "0",
                           "--phi-out-step", "5", "--out", capture, "--quiet")
    assert code == 0, err
    s, _, _ = assert_same_as_cli(brdf_tool, str(capture), tmp_path, seed=2)
    assert s.evaluation == "resampled_lut"
    assert s.measured_theta_in_deg == [0, 20, 40, 60]


def test_rgl_file_matches_cli(brdf_tool, data_dir, tmp_path):
    rgl = data_dir / "rgl" / "aurora_white_rgb.bsdf"
    assert rgl.is_file(), f"{rgl} is missing from the brdf-data folder"
    s, _, _ = assert_same_as_cli(brdf_tool, str(rgl), tmp_path, seed=3)
    assert s.evaluation == "measured_database"


def test_eval_deg_broadcasts_like_numpy(brdf_tool):
    s = brdf.open("gold")
    theta_out = np.linspace(0, 90, 7)
    grid = s.eval_deg(30, 0, theta_out[:, None], np.array([0.0, 90.0, 180.0])[None, :])
    assert grid.shape == (7, 3, 3)
    one_by_one = np.array([[s.eval_deg(30, 0, t, p) for p in (0.0, 90.0, 180.0)]
                           for t in theta_out])
    assert np.array_equal(grid, one_by_one)
    assert s.eval_deg(30, 0, 30, 180).shape == (3,)


def test_large_batch_on_threads_equals_small_batches():
    # Above the threading threshold the batch is shared out; the values must not change.
    s = brdf.open("gold")
    rng = np.random.default_rng(4)
    n = 100_000
    args = (rng.uniform(0, 90, n), rng.uniform(0, 360, n), rng.uniform(0, 90, n),
            rng.uniform(0, 360, n))
    whole = s.eval_deg(*args)
    pieces = np.concatenate([s.eval_deg(*(a[i:i + 1000] for a in args))
                             for i in range(0, n, 1000)])
    assert np.array_equal(whole, pieces)
    assert np.array_equal(s.eval_deg(*args, jobs=1), whole)
    assert np.array_equal(s.eval_deg(*args, jobs=3), whole)
    with pytest.raises(ValueError, match=r"^jobs: expected 0 \(one thread per core\) or a positive count, got -1$"):
        s.eval_deg(*args, jobs=-1)


def test_exported_lut_matches_cli(brdf_tool, tmp_path):
    out = tmp_path / "lut"
    code, _, err = run_cli(brdf_tool, "convert", "copper", "--out", out)
    assert code == 0, err
    s, _, _ = assert_same_as_cli(brdf_tool, str(out / "copper.ktx2"), tmp_path, seed=5)
    assert s.evaluation == "exported_lut"


def test_strided_and_empty_inputs():
    s = brdf.open("gold")
    rng = np.random.default_rng(6)
    wi = directions(rng.uniform(0, 89, 50), rng.uniform(0, 360, 50))
    wo = directions(rng.uniform(0, 89, 50), rng.uniform(0, 360, 50))
    contiguous = s.eval(wi, wo)
    # Fortran order and a strided view (every other row of a larger array) read the same values.
    assert np.array_equal(s.eval(np.asfortranarray(wi), np.asfortranarray(wo)), contiguous)
    doubled = np.repeat(wi, 2, axis=0)
    assert np.array_equal(s.eval(doubled[::2], wo), contiguous)
    assert s.eval(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0, 3)
    assert s.eval_deg(np.zeros(0), 0, 0, 0).shape == (0, 3)
