"""brdf.info / Source.info() against `brdf info --json` on the same files: the same document
(parsed) for a capture, a material, an exported LUT and an RGL file, and for a capture cut short
(usable, refusals, advice). Where the description offers a remedy the module phrases it for
Python (docs/python.md, "Errors"); the test swaps the two documented phrasings and then
requires equality."""

import json

import pytest

import brdf
from conftest import run_cli, sim_capture


def cli_info(tool, path):
    code, out, err = run_cli(tool, "info", "--json", path)
    # A damaged capture: the description is printed and the exit code says "problems".
    assert code in (0, 1), err
    return json.loads(out)


def capture(tool, tmp_path, material="gold"):
    return sim_capture(tool, tmp_path, material, phi_out_step=10)


def assert_same_document(tool, path):
    expected = cli_info(tool, path)
    got = brdf.info(path)
    assert list(got) == list(expected)  # the same keys in the same order
    assert got == expected
    return got


def test_capture_info_equals_cli(brdf_tool, tmp_path):
    path = capture(brdf_tool, tmp_path)
    got = assert_same_document(brdf_tool, str(path))
    assert got["format"] == "bpc" and "usable" in got
    # Source.info() is the same call on the opened file's path.
    assert brdf.open(path).info() == got


def test_material_info_equals_cli(brdf_tool):
    got = assert_same_document(brdf_tool, "gold")
    assert got["file"].endswith("gold.json")


def test_exported_lut_info_equals_cli(brdf_tool, tmp_path):
    code, _, err = run_cli(brdf_tool, "convert", "copper", "--out", tmp_path / "lut", "--quiet")
    assert code == 0, err
    got = assert_same_document(brdf_tool, str(tmp_path / "lut" / "copper.ktx2"))
    assert got["format"] == "lut"


def test_rgl_info_equals_cli_with_python_remedy(brdf_tool, data_dir):
    rgl = str(data_dir / "rgl" / "aurora_white_rgb.bsdf")
    expected = cli_info(brdf_tool, rgl)
    got = brdf.info(rgl)
    cli_words, python_words = "'brdf eval' evaluates it directly", "brdf.open evaluates it directly"
    assert expected["advice"].endswith(cli_words) and got["advice"].endswith(python_words)
    expected["advice"] = expected["advice"][:-len(cli_words)] + python_words
    assert got == expected
    assert brdf.open(rgl).info() == got


def test_interrupted_capture_info_equals_cli_with_python_remedy(brdf_tool, tmp_path):
    whole = capture(brdf_tool, tmp_path, "copper").read_bytes()
    cut = tmp_path / "cut.bpc"
    cut.write_bytes(whole[: len(whole) * 2 // 3])  # a capture killed mid-way
    expected = cli_info(brdf_tool, cut)
    got = brdf.info(cut)
    # The CLI's remedy names its command line, the module's names brdf.capture(resume=True).
    cli_words = "rerun the 'brdf capture ... --out " + str(cut) + "' command that made it with --resume"
    python_words = "call brdf.capture(...) again with the arguments that made it and resume=True"
    assert cli_words in expected["advice"] and python_words in got["advice"]
    expected["advice"] = expected["advice"].replace(cli_words, python_words)
    assert len(expected["refusals"]) == 1 and cli_words in expected["refusals"][0]
    expected["refusals"] = [expected["refusals"][0].replace(cli_words, python_words)]
    assert got == expected
    assert expected["problems"], "the cut capture must be described as damaged"


def test_info_errors_raise_like_open(brdf_tool, tmp_path):
    with pytest.raises(OSError) as e:
        brdf.info(tmp_path / "missing.bpc")
    code, _, err = run_cli(brdf_tool, "info", tmp_path / "missing.bpc")
    assert code == 1 and err.strip() == "brdf: error: " + str(e.value)
