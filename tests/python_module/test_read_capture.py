"""brdf.read_capture against the independent .bpc reader tests/python/bpc_reader.py (written
from docs/formats/bpc.md, not from the C++ code): every sample field bit for bit, the slices
and the metadata; errors with the CLI's message."""

import pathlib
import sys

import numpy as np
import pytest

import brdf
from conftest import run_cli, sim_capture

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python"))
import bpc_reader  # noqa: E402


def capture(tool, tmp_path, name, *extra):
    return sim_capture(tool, tmp_path, name, *extra)


@pytest.mark.parametrize("material, extra", [("gold", ()), ("paper_white", ("--noise", "0"))])
def test_samples_equal_the_independent_reader(brdf_tool, tmp_path, material, extra):
    path = capture(brdf_tool, tmp_path, material, *extra)
    got = brdf.read_capture(path)
    ref = bpc_reader.read_bpc(str(path))
    assert not ref["problems"]
    records = np.concatenate([s["records"] for s in ref["slices"]])
    n = len(records)
    assert n > 1000
    for name in ("theta_in_deg", "phi_in_deg", "theta_out_deg", "phi_out_deg"):
        assert got[name].dtype == np.float32 and got[name].shape == (n,)
        assert np.array_equal(got[name].view(np.uint32), records[name].astype("<f4").view(np.uint32))
    rgb = np.stack([records[c] for c in "rgb"], axis=1).astype("<f4")
    assert got["rgb"].shape == (n, 3)
    assert np.array_equal(got["rgb"].view(np.uint32), rgb.view(np.uint32))
    if "sigma_r" in records.dtype.names:
        sigma = np.stack([records["sigma_" + c] for c in "rgb"], axis=1).astype("<f4")
        assert np.array_equal(got["sigma"].view(np.uint32), sigma.view(np.uint32))
        if "--noise" not in extra:  # the noisy detector records non-zero uncertainties
            assert np.any(sigma > 0)
    else:
        assert not np.any(got["sigma"])
    assert np.array_equal(got["flags"], records["flags"])
    counts = [len(s["records"]) for s in ref["slices"]]
    assert np.array_equal(got["slice"], np.repeat(np.arange(len(counts)), counts))
    assert [s["samples"] for s in got["slices"]] == counts
    assert [s["theta_in_deg"] for s in got["slices"]] == [s["theta_in_deg"] for s in ref["slices"]]
    assert [s["has_sigma"] for s in got["slices"]] == [s["has_sigma"] for s in ref["slices"]]
    assert all(s["complete"] for s in got["slices"])
    for key in bpc_reader.METADATA_KEYS:
        if key in ref["metadata"]:
            assert got["metadata"][key] == ref["metadata"][key], key
    assert got["metadata"]["sample_name"] == material


def test_read_capture_errors_have_cli_message(brdf_tool, tmp_path):
    missing = tmp_path / "none.bpc"
    with pytest.raises(OSError) as e:
        brdf.read_capture(missing)
    code, _, err = run_cli(brdf_tool, "export-csv", missing, "--out", tmp_path / "x.csv")
    assert code == 1 and err.strip().startswith("brdf: error: " + str(e.value)), err
    good = capture(brdf_tool, tmp_path, "copper")
    damaged = tmp_path / "damaged.bpc"
    data = good.read_bytes()
    damaged.write_bytes(data[:8] + b"\xff" + data[9:])  # the version field
    with pytest.raises(ValueError) as e:
        brdf.read_capture(damaged)
    assert str(damaged) in str(e.value)
    code, _, err = run_cli(brdf_tool, "export-csv", damaged, "--out", tmp_path / "y.csv")
    assert code == 1 and err.strip().startswith("brdf: error: " + str(e.value)), err
    # Not a capture: a material file.
    with pytest.raises(ValueError, match=r"gold\.json: a .*; read_capture reads \.bpc captures"):
        brdf.read_capture("gold")
