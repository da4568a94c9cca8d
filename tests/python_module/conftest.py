"""Shared fixtures of the brdf Python module tests: the CLI they compare with, the third-party
data folder, and the rule that a skipped test fails the run (a missing tool or file must be
installed, never silently skipped)."""

import os
import pathlib
import subprocess

import pytest

_skipped = []


def pytest_runtest_logreport(report):
    if report.skipped:
        _skipped.append(report.nodeid)


def pytest_sessionfinish(session, exitstatus):
    if _skipped:
        print("\nskipped tests count as failures here: " + ", ".join(_skipped))
        session.exitstatus = 1


def _required_env(name):
    value = os.environ.get(name, "")
    if not value:
        pytest.fail(f"{name} is not set (ctest sets it; see tests/python_module/CMakeLists.txt)")
    return value


@pytest.fixture(scope="session")
def brdf_tool():
    tool = _required_env("BRDF_TOOL")
    if not os.access(tool, os.X_OK):
        pytest.fail(f"BRDF_TOOL={tool} is not an executable")
    return tool


@pytest.fixture(scope="session")
def data_dir():
    # $BRDF_DATA_DIR when the user sets it, else the folder the build was configured with.
    d = pathlib.Path(os.environ.get("BRDF_DATA_DIR") or _required_env("BRDF_DATA_DIR_DEFAULT"))
    if not d.is_dir():
        pytest.fail(f"BRDF_DATA_DIR={d} is not a folder (the brdf-data measurements)")
    return d


def run_cli(tool, *args):
    """Runs `brdf ARGS`; returns (exit code, stdout, stderr)."""
    p = subprocess.run([tool, *map(str, args)], capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def sim_capture(tool, folder, material, *extra, phi_out_step=6):
    """`brdf capture --device sim` of a library material into folder/MATERIAL.bpc (sample name
    = material); returns the path. `extra`: further options (--noise 0, --seed N, ...)."""
    out = folder / f"{material}.bpc"
    code, _, err = run_cli(tool, "capture", "--device", "sim", "--material", material, "--sample",
                           material, "--phi-out-step", str(phi_out_step), "--out", out, "--quiet",
                           *extra)
    assert code == 0, err
    return out
