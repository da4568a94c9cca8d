"""The installed package (`cmake --install` into a temporary prefix): importable from
PREFIX/lib/python3/dist-packages, and it finds the installed material library relative to
itself, not the source tree the build tree falls back to."""

import os
import pathlib
import subprocess

import pytest

import brdf


def test_installed_package_uses_installed_materials(tmp_path):
    build = os.environ.get("BRDF_BINARY_DIR")
    python = os.environ.get("BRDF_PYTHON")
    assert build and python, "BRDF_BINARY_DIR and BRDF_PYTHON are set by ctest"
    prefix = tmp_path / "prefix"
    p = subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    package = prefix / "lib" / "python3" / "dist-packages"
    assert (package / "brdf" / "__init__.py").is_file()
    materials = prefix / "share" / "brdf-toolchain" / "materials"
    assert (materials / "gold.json").is_file()

    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "BRDF_MATERIALS_DIR")}
    env["PYTHONPATH"] = str(package)
    script = (
        "import brdf, sys\n"
        "print(brdf.__file__)\n"
        "print(repr(brdf.open('gold').eval_deg(30, 0, 40, 180).tolist()))\n"
        "try:\n"
        "    brdf.open('no_such_material_anywhere')\n"
        "except OSError as e:\n"
        "    print(e)\n"
        # The second compiled part (fit, convert, preview, capture) is installed beside it and
        # finds the installed library too.
        "print(brdf.preview('gold', size=8, estimator='quadrature').shape)\n")
    p = subprocess.run([python, "-c", script], capture_output=True, text=True, cwd=tmp_path,
                       env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    file_line, values_line, error_line, preview_line = p.stdout.splitlines()
    assert preview_line == "(8, 8, 3)"
    assert pathlib.Path(file_line).resolve().is_relative_to(package.resolve())
    assert f"(library {materials.resolve()}: " in error_line, error_line
    # The installed module answers as the build tree's does.
    assert values_line == repr(brdf.open("gold").eval_deg(30, 0, 40, 180).tolist())
