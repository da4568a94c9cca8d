"""brdf.write_capture: read_capture → numpy → write_capture → `brdf info --json` equal; data
made in numpy (a Lambertian surface, f_r = ρ/π) evaluates to ρ/π through `brdf eval`; wrong
shapes, dtypes and values raise ValueError with one line naming the argument; an existing file
is replaced only on request, and a refused write leaves it untouched."""

import json
import os

import numpy as np
import pytest

import brdf
from conftest import run_cli, sim_capture

# What differs between two files of the same samples: their names and the header chunk's
# metadata text (a capture's header records the metadata it started with, a whole-file write
# the final metadata), hence the byte counts.
FILE_KEYS = ("file", "file_bytes", "valid_bytes")


def info(tool, path):
    code, out, err = run_cli(tool, "info", "--json", path)
    assert code == 0, err
    return json.loads(out)


def arrays_of(d):
    return (d["theta_in_deg"], d["phi_in_deg"], d["theta_out_deg"], d["phi_out_deg"], d["rgb"])


@pytest.mark.parametrize("material, extra", [("gold", ()), ("plastic_glossy_red", ("--noise", "0"))])
def test_round_trip_gives_the_same_info(brdf_tool, tmp_path, material, extra):
    original = sim_capture(brdf_tool, tmp_path, material, *extra, phi_out_step=8)
    d = brdf.read_capture(original)
    copy = tmp_path / "copy.bpc"
    slices = brdf.write_capture(copy, *arrays_of(d), sigma=d["sigma"], flags=d["flags"],
                                metadata=d["metadata"])
    assert slices == len(d["slices"]) == 4
    a, b = info(brdf_tool, original), info(brdf_tool, copy)
    assert a["sample_count"] > 1000
    for key in FILE_KEYS:
        a.pop(key), b.pop(key)
    assert a == b  # samples, slices, statistics, flags, metadata, verdict
    # The arrays themselves, bit for bit.
    e = brdf.read_capture(copy)
    for key in ("theta_in_deg", "phi_in_deg", "theta_out_deg", "phi_out_deg", "rgb", "sigma",
                "flags", "slice"):
        assert np.array_equal(e[key].view(np.uint8), d[key].view(np.uint8)), key
    assert e["metadata"] == d["metadata"] and e["slices"] == d["slices"]
    # brdf eval answers the same on both files.
    assert brdf.open(copy).eval_deg(30, 0, 30, 180).tolist() == \
        brdf.open(original).eval_deg(30, 0, 30, 180).tolist()


def lambertian_grid(theta_in, rho):
    theta_out, phi_out = np.meshgrid(np.arange(0.0, 76.0, 1.0), np.arange(0.0, 360.0, 5.0),
                                     indexing="ij")
    n = theta_out.size
    t_in = np.repeat(np.asarray(theta_in, dtype=float), n)
    k = len(theta_in)
    return (t_in, np.zeros(k * n), np.tile(theta_out.ravel(), k), np.tile(phi_out.ravel(), k),
            np.tile(np.asarray(rho) / np.pi, (k * n, 1)))


def test_numpy_data_evaluates_as_measured(brdf_tool, tmp_path):
    rho = [0.8, 0.5, 0.2]
    path = tmp_path / "lambert.bpc"
    assert brdf.write_capture(path, *lambertian_grid([0, 20, 40, 60], rho),
                              metadata={"sample_name": "numpy lambert",
                                        "extra": {"source": "numpy"}}) == 4
    d = info(brdf_tool, path)
    assert d["sample_count"] == 4 * 76 * 72
    assert d["metadata"]["sample_name"] == "numpy lambert"
    assert d["metadata"]["extra"]["source"] == "numpy"
    # f_r = ρ/π at pairs inside the measured range, by the CLI and by the module.
    code, out, err = run_cli(brdf_tool, "eval", path, "--in", "30,0", "--out", "45,120")
    assert code == 0, err
    cli = np.array([float(x) for x in out.split()])
    np.testing.assert_allclose(cli, np.array(rho) / np.pi, rtol=1e-6)
    np.testing.assert_allclose(brdf.open(path).eval_deg(30, 0, 45, 120), cli, rtol=1e-8)


@pytest.mark.parametrize("change, message", [
    (dict(rgb=np.zeros((10, 2))),
     "rgb: expected an N×3 array (N = 10, the length of theta_in), got shape (10, 2)"),
    (dict(rgb=np.zeros((9, 3))),
     "rgb: expected an N×3 array (N = 10, the length of theta_in), got shape (9, 3)"),
    (dict(theta_out=np.zeros((10, 1))),
     "theta_out: expected a 1-D array (N) (N = 10, the length of theta_in), got shape (10, 1)"),
    (dict(theta_in=np.zeros((2, 5))), "theta_in: expected a 1-D array (N), got shape (2, 5)"),
    (dict(rgb=np.array([["a", "b", "c"]] * 10)),
     "rgb: expected an N×3 array of real numbers, got dtype <U1"),
    (dict(sigma=np.zeros((10, 3), dtype=complex)),
     "sigma: expected an N×3 array of real numbers, got dtype complex128"),
    (dict(flags=np.zeros(10, dtype=np.float32)),
     "flags: expected a 1-D array (N) of integers, got dtype float32"),
    (dict(flags=np.array([0] * 9 + [16])),
     "flags[9]: expected bits 0-3 only (saturated 1, below noise floor 2, interpolated 4, "
     "invalid 8), got 16"),
    (dict(theta_in=np.array([0.0] * 9 + [90.0])),
     "theta_in[9]: expected a light polar angle in [0, 90) degrees, got 90"),
    (dict(theta_out=np.array([0.0] * 3 + [-1.0] + [0.0] * 6)),
     "theta_out[3]: expected a polar angle in [0, 90] degrees, got -1"),
    (dict(phi_out=np.array([np.nan] * 10)),
     "phi_out[0]: expected a finite azimuth in degrees, got nan"),
    (dict(metadata={"sample": "x"}),
     "metadata: unknown key 'sample' (expected sample_name, instrument_model, instrument_serial, "
     "firmware_version, protocol_version, calibration_reference, calibration_time, "
     "capture_start, capture_end, operator_notes, units, software_version, extra)"),
    (dict(metadata={"sample_name": 3}), "metadata['sample_name']: expected text, got int"),
    (dict(path="x.csv"), "x.csv: a capture is written as a .bpc file (the extension .bpc)"),
])
def test_wrong_shapes_dtypes_and_values_raise_one_line(tmp_path, change, message):
    args = dict(path=tmp_path / "bad.bpc", theta_in=np.zeros(10), phi_in=np.zeros(10),
                theta_out=np.zeros(10), phi_out=np.zeros(10), rgb=np.zeros((10, 3)))
    args.update(change)
    with pytest.raises(ValueError) as e:
        brdf.write_capture(**args)
    assert str(e.value) == message
    assert "\n" not in str(e.value)
    assert not os.listdir(tmp_path), "nothing is written when the arguments are refused"


def test_existing_file_is_replaced_only_on_request(brdf_tool, data_dir, tmp_path):
    path = tmp_path / "lambert.bpc"
    grid = lambertian_grid([0, 20], [0.5, 0.5, 0.5])
    brdf.write_capture(path, *grid)
    before = path.read_bytes()
    with pytest.raises(OSError) as e:
        brdf.write_capture(path, *grid)
    # The CLI's message for the same rule, with its remedy in its words.
    code, _, err = run_cli(brdf_tool, "import", data_dir / "rgl" / "aurora_white_rgb.bsdf", "--out", path)
    assert code == 1
    cli = err.strip().removeprefix("brdf: error: ")
    assert str(e.value).split("; ")[0] == cli.split("; ")[0]
    assert str(e.value).endswith("; pass overwrite=True to replace it")
    # A refused overwrite (bad values) leaves the old file as it was; no temporary is left.
    bad = list(grid)
    bad[2] = np.full_like(grid[2], 91.0)
    with pytest.raises(ValueError):
        brdf.write_capture(path, *bad, overwrite=True)
    assert path.read_bytes() == before
    brdf.write_capture(path, *lambertian_grid([0, 20, 40], [0.5, 0.5, 0.5]), overwrite=True)
    assert info(brdf_tool, path)["theta_in_deg"] == [0, 20, 40]
    assert sorted(os.listdir(tmp_path)) == ["lambert.bpc"]
