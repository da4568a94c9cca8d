"""Errors raise Python exceptions with the message the CLI prints after "brdf: error: "."""

import numpy as np
import pytest

import brdf
from conftest import run_cli

PREFIX = "brdf: error: "


def cli_error_line(tool, *args):
    code, _, err = run_cli(tool, *args)
    assert code == 1, err
    lines = [l for l in err.splitlines() if l.startswith(PREFIX)]
    assert len(lines) == 1, err
    return lines[0][len(PREFIX):]


def assert_cli_message(cli_line, message):
    # The CLI may add "; <what to do>" naming its options; the message itself is the same.
    assert cli_line == message or cli_line.startswith(message + "; "), (cli_line, message)


def test_missing_file_raises_oserror_with_cli_message(brdf_tool, tmp_path):
    missing = tmp_path / "nothing-here.bpc"
    with pytest.raises(OSError) as e:
        brdf.open(missing)
    assert isinstance(e.value, brdf.IoError)
    assert str(missing) in str(e.value)
    assert_cli_message(cli_error_line(brdf_tool, "eval", missing, "--in", "0,0", "--out", "0,0"),
                       str(e.value))


def test_damaged_capture_raises_valueerror_with_cli_message(brdf_tool, tmp_path):
    damaged = tmp_path / "damaged.bpc"
    damaged.write_bytes(b"BPC1" + bytes(range(256)) * 3)
    with pytest.raises(ValueError) as e:
        brdf.open(damaged)
    assert str(damaged) in str(e.value)
    assert_cli_message(cli_error_line(brdf_tool, "eval", damaged, "--in", "0,0", "--out", "0,0"),
                       str(e.value))


def test_unknown_library_name_raises_with_cli_message(brdf_tool):
    with pytest.raises(OSError) as e:  # neither a file nor a library material
        brdf.open("no_such_material_anywhere")
    assert_cli_message(
        cli_error_line(brdf_tool, "eval", "no_such_material_anywhere", "--in", "0,0", "--out",
                       "0,0"), str(e.value))


def test_polar_angle_out_of_range_has_cli_wording(brdf_tool):
    s = brdf.open("gold")
    with pytest.raises(ValueError) as e:
        s.eval_deg([10, 95], 0, 10, 0)
    assert str(e.value) == "theta_in[1]: polar angle must be in [0, 90] degrees, got 95"
    cli = cli_error_line(brdf_tool, "eval", "gold", "--in", "95,0", "--out", "10,0")
    assert cli == "--in: polar angle must be in [0, 90] degrees, got 95"
    with pytest.raises(ValueError, match=r"^phi_out\[0\]: azimuth must be finite, got nan$"):
        s.eval_deg(10, 0, 10, np.nan)


@pytest.mark.parametrize("wi, message", [
    (np.zeros((4, 2)), "wi: expected an N×3 array of float64, got shape (4, 2)"),
    (np.zeros(3), "wi: expected an N×3 array of float64, got shape (3,)"),
    (np.zeros((4, 3), dtype=np.float32), "wi: expected an N×3 array of float64, got dtype float32"),
    (np.zeros((4, 3), dtype=np.int64), "wi: expected an N×3 array of float64, got dtype int64"),
    (np.array([[0.0, 0.0, 2.0]] * 4), "wi[0]: expected a unit vector, got length 2"),
])
def test_bad_vectors_raise_valueerror(wi, message):
    s = brdf.open("gold")
    wo = np.tile([0.0, 0.0, 1.0], (4, 1))
    with pytest.raises(ValueError) as e:
        s.eval(wi, wo)
    assert str(e.value) == message


def test_mismatched_counts_and_bad_dtypes_raise_valueerror():
    s = brdf.open("gold")
    up = np.tile([0.0, 0.0, 1.0], (4, 1))
    with pytest.raises(ValueError, match="same number of directions, got 4 and 3"):
        s.eval(up, up[:3])
    with pytest.raises(ValueError, match=r"^theta_in: expected real numbers \(degrees\), got dtype <U"):
        s.eval_deg(np.array(["ten"]), 0, 0, 0)
    with pytest.raises(ValueError, match="do not broadcast together"):
        s.eval_deg(np.zeros(3), np.zeros(4), 0, 0)


def test_interpreter_survives_errors(tmp_path):
    # After every kind of failure the module still answers.
    for bad in (lambda: brdf.open(tmp_path / "x.bpc"), lambda: brdf.open("gold").eval(1, 2)):
        with pytest.raises((OSError, ValueError)):
            bad()
    assert brdf.open("gold").eval_deg(0, 0, 0, 0).shape == (3,)


def test_value_no_surface_has_raises_as_eval_refuses_it(brdf_tool, tmp_path):
    # docs/design.md §4: f_r = −1e30 is refused by every reader, naming slice and sample.
    table = tmp_path / "negative.csv"
    table.write_text("theta_in,phi_in,theta_out,phi_out,r,g,b\n"
                     "0,0,10,0,0.1,0.1,0.1\n0,0,20,0,-1e30,0.1,0.1\n0,0,30,90,0.1,0.1,0.1\n")
    with pytest.raises(ValueError) as e:
        brdf.open(table)
    assert "slice 0" in str(e.value) and "sample 1" in str(e.value), str(e.value)
    assert_cli_message(cli_error_line(brdf_tool, "eval", table, "--in", "0,0", "--out", "10,0"),
                       str(e.value))
