"""brdf.fit, brdf.convert, brdf.preview and brdf.capture against the `brdf` commands on the same
input: the same fit result file (parsed), the same LUT files byte for byte, the same preview
pixels as the command's .exr (read with OpenImageIO, not with the toolchain), the same capture
samples bit for bit, and a capture either side can resume."""

import json
import warnings

import numpy as np
import pytest

import brdf
from conftest import run_cli


def cli(tool, *args):
    code, out, err = run_cli(tool, *args)
    assert code == 0, err
    return out


@pytest.fixture(scope="module")
def small_capture(brdf_tool, tmp_path_factory):
    out = tmp_path_factory.mktemp("capture") / "red.bpc"
    cli(brdf_tool, "capture", "--device", "sim", "--material", "plastic_glossy_red", "--sample",
        "red", "--phi-out-step", "10", "--theta-out-step", "2", "--out", out, "--quiet")
    return out


@pytest.mark.parametrize("model, loss", [("ggx", "ngan"), ("lambert", "log")])
def test_fit_equals_cli_result_file(brdf_tool, small_capture, tmp_path, model, loss):
    out = tmp_path / "fit.json"
    cli(brdf_tool, "fit", small_capture, "--model", model, "--loss", loss, "--out", out)
    expected = json.loads(out.read_text())
    got = brdf.fit(small_capture, model=model, loss=loss)
    assert got == expected
    assert got["model"] == model and got["fit"]["rmse"] > 0
    # A Source is fitted as its file; the thread count does not change the numbers.
    assert brdf.fit(brdf.open(small_capture), model=model, loss=loss, jobs=1) == expected


def test_fit_errors_have_cli_message(brdf_tool, tmp_path):
    damaged = tmp_path / "damaged.bpc"
    damaged.write_bytes(b"\x89BPC\r\n\x1a\n" + bytes(200))
    with pytest.raises(ValueError) as e:
        brdf.fit(damaged)
    code, _, err = run_cli(brdf_tool, "fit", damaged, "--model", "ggx", "--out",
                           tmp_path / "x.json")
    # A batch command names the input, then "FAILED: " and the reason.
    prefix = f"{damaged}: "
    assert str(e.value).startswith(prefix)
    assert code == 1 and err.splitlines()[0] == prefix + "FAILED: " + str(e.value)[len(prefix):]
    with pytest.raises(ValueError, match="^loss: "):
        brdf.fit("gold", loss="l7")


def test_convert_writes_the_cli_files(brdf_tool, small_capture, tmp_path):
    cli(brdf_tool, "convert", small_capture, "--out", tmp_path / "cli", "--quiet")
    written = brdf.convert(small_capture, tmp_path / "py")
    names = ["red.ktx2", "red.dds", "red.exr", "red.png", "red.json"]
    assert [p.rsplit("/", 1)[1] for p in written] == names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # The options of the command, the same way.
    cli(brdf_tool, "convert", "copper", "--out", tmp_path / "cli2", "--formats", "ktx2,json",
        "--extrapolate", "0.8,0.25", "--quiet")
    written = brdf.convert("copper", tmp_path / "py2", formats="ktx2,json",
                           extrapolate=(0.8, 0.25))
    assert len(written) == 2
    for name in ("copper.ktx2", "copper.json"):
        assert (tmp_path / "py2" / name).read_bytes() == (tmp_path / "cli2" / name).read_bytes()
    # The overwrite rule: refused without overwrite=True, with the module's remedy.
    with pytest.raises(OSError, match=r"already exist.*; pass overwrite=True to replace them$"):
        brdf.convert("copper", tmp_path / "py2", formats="ktx2,json")
    assert brdf.convert("copper", tmp_path / "py2", formats="ktx2,json", extrapolate="0.8,0.25",
                        overwrite=True) == written


def read_exr(path):
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(str(path))
    assert image is not None, oiio.geterror()
    try:
        return image.read_image(format="float")
    finally:
        image.close()


@pytest.mark.parametrize("source, options, args", [
    ("gold", {}, []),
    ("copper", dict(light=(40, 30), mesh="plane"), ["--light", "40,30", "--mesh", "plane"]),
    ("paper_white", dict(spp=4, seed=7, env="sky"), ["--spp", "4", "--seed", "7", "--env", "sky"]),
])
def test_preview_pixels_equal_the_cli_exr(brdf_tool, tmp_path, source, options, args):
    out = tmp_path / "p.exr"
    cli(brdf_tool, "preview", source, "--size", "40", "--out", out, "--quiet", *args)
    expected = read_exr(out)
    got = brdf.preview(source, size=40, **options)
    assert got.shape == (40, 40, 3) and got.dtype == np.float32
    assert np.array_equal(got, expected)
    assert np.count_nonzero(got) > 100


def capture_args(seed):
    return ["--material", "gold", "--sample", "g", "--phi-out-step", "9", "--theta-out-step", "3",
            "--seed", str(seed)]


def test_capture_equals_cli_capture(brdf_tool, tmp_path):
    a, b = tmp_path / "cli.bpc", tmp_path / "py.bpc"
    cli(brdf_tool, "capture", "--device", "sim", *capture_args(5), "--out", a, "--quiet")
    r = brdf.capture("gold", b, sample="g", phi_out_step=9, theta_out_step=3, seed=5)
    assert r["finished"] and r["slices_saved"] == 4 and r["new_samples"] > 1000
    x, y = brdf.read_capture(a), brdf.read_capture(b)
    for key in ("theta_in_deg", "phi_in_deg", "theta_out_deg", "phi_out_deg", "rgb", "sigma",
                "flags"):
        assert np.array_equal(x[key].view(np.uint8), y[key].view(np.uint8)), key
    times = ("calibration_time", "capture_start", "capture_end")
    mx, my = x["metadata"], y["metadata"]
    assert {k: v for k, v in mx.items() if k not in times + ("extra",)} == \
        {k: v for k, v in my.items() if k not in times + ("extra",)}
    assert {k: v for k, v in mx["extra"].items() if not k.endswith("_time")} == \
        {k: v for k, v in my["extra"].items() if not k.endswith("_time")}


def test_cli_resumes_a_module_capture(brdf_tool, tmp_path):
    whole, cut = tmp_path / "whole.bpc", tmp_path / "cut.bpc"
    brdf.capture("gold", whole, sample="g", phi_out_step=9, theta_out_step=3, seed=6)
    data = whole.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    assert brdf.info(cut)["missing_theta_in_deg"], "the cut file must miss slices"
    # The CLI accepts the module's recorded settings and completes the capture ...
    cli(brdf_tool, "capture", "--device", "sim", *capture_args(6), "--out", cut, "--resume",
        "--quiet")
    x, y = brdf.read_capture(whole), brdf.read_capture(cut)
    assert np.array_equal(x["rgb"], y["rgb"]) and x["slices"] == y["slices"]
    # ... and the module refuses to resume with other settings, in its own words.
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(brdf.Error, match="; call it again with the original settings$"):
        brdf.capture("gold", cut, sample="g", phi_out_step=9, theta_out_step=3, seed=7,
                     resume=True)
    r = brdf.capture("gold", cut, sample="g", phi_out_step=9, theta_out_step=3, seed=6,
                     resume=True)
    assert r["resumed"] and r["finished"]
    assert np.array_equal(brdf.read_capture(cut)["rgb"], x["rgb"])


@pytest.mark.parametrize("call, message", [
    (lambda p: brdf.capture("gold", p, theta_in=[0, 95]),
     "theta_in: angles must be in [0, 90) degrees, got 95"),
    (lambda p: brdf.capture("gold", p, noise=-1),
     "noise: expected a level ≥ 0 (1 = reference instrument), got -1"),
    (lambda p: brdf.capture("gold", p, exposure="fast"),
     "exposure: expected auto, auto-slice or a time in ms, got 'fast'"),
    (lambda p: brdf.preview("gold", size=0), "size: expected 1 to 8192 pixels, got 0"),
    (lambda p: brdf.preview("gold", estimator="x"),
     "estimator: expected auto, hierarchical, mis, env, brdf or quadrature, got 'x'"),
])
def test_bad_arguments_raise_valueerror(tmp_path, call, message):
    with pytest.raises(ValueError) as e:
        call(tmp_path / "c.bpc")
    assert str(e.value) == message


def test_capture_of_an_existing_file_needs_overwrite(tmp_path):
    path = tmp_path / "c.bpc"
    brdf.capture("gold", path, phi_out_step=30, theta_out_step=15)
    with pytest.raises(OSError, match="pass overwrite=True to replace it$"):
        brdf.capture("gold", path, phi_out_step=30, theta_out_step=15)
    assert brdf.capture("gold", path, phi_out_step=30, theta_out_step=15,
                        overwrite=True)["finished"]


def test_ctrl_c_stops_a_capture_and_leaves_it_resumable(data_dir, tmp_path):
    # In a child interpreter, so that a late signal cannot reach pytest: SIGINT as soon as the
    # first slice is in the file, during a capture of an RGL sample at 0.5° steps (4 slices of
    # about 55,000 samples).
    import os
    import subprocess
    import sys
    rgl = data_dir / "rgl" / "aurora_white_rgb.bsdf"
    path = tmp_path / "big.bpc"
    script = (
        "import os, signal, threading, time, brdf\n"
        f"path = {str(path)!r}\n"
        "def interrupt():\n"
        "    while not (os.path.exists(path) and os.path.getsize(path) > 100000):\n"
        "        time.sleep(0.001)\n"
        "    os.kill(os.getpid(), signal.SIGINT)\n"
        "threading.Thread(target=interrupt, daemon=True).start()\n"
        "try:\n"
        f"    brdf.capture({str(rgl)!r}, path, phi_out_step=0.5)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n")
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                       timeout=300, env=os.environ)
    assert p.returncode == 0 and p.stdout.strip() == "interrupted", p.stdout + p.stderr
    about = brdf.info(path)
    assert about["finished"] is False and about["missing_theta_in_deg"], about
    r = brdf.capture(rgl, path, phi_out_step=0.5, resume=True)
    assert r["resumed"] and r["finished"]
    whole = tmp_path / "whole.bpc"
    brdf.capture(rgl, whole, phi_out_step=0.5)
    assert np.array_equal(brdf.read_capture(path)["rgb"], brdf.read_capture(whole)["rgb"])
