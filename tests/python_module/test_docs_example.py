"""The worked example of docs/python.md runs as it is written: the first ```python block under
"## Worked example", executed by the module's interpreter in a temporary folder with
matplotlib's Agg backend (no window). Its outputs are checked: the plot and preview images
decode, the fitted material opens, the LUT is written, and the plotted curves hold values."""

import os
import pathlib
import re
import subprocess
import sys

import numpy as np

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "python.md"


def example_code():
    text = DOC.read_text()
    section = text.split("## Worked example", 1)[1]
    m = re.search(r"```python\n(.*?)```", section, re.S)
    assert m, "docs/python.md: no ```python block under '## Worked example'"
    return m.group(1)


def test_worked_example_runs(tmp_path):
    code = example_code()
    script = tmp_path / "example.py"
    script.write_text(code)
    env = dict(os.environ, MPLBACKEND="Agg", MPLCONFIGDIR=str(tmp_path / "mpl"))
    p = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "4 slices" in p.stdout and "usable:" in p.stdout, p.stdout
    import matplotlib.image as mpimg
    plot = mpimg.imread(tmp_path / "red_slice.png")
    assert plot.shape[:2] == (400, 600)
    assert np.ptp(plot[..., :3]) > 0.5  # curves drawn on white
    preview = mpimg.imread(tmp_path / "red_preview.png")
    assert preview.shape[:2] == (128, 128) and preview[..., 0].max() > preview[..., 2].max()
    assert (tmp_path / "lut" / "red.ktx2").is_file() and (tmp_path / "red.ggx.json").is_file()
    sys.path.insert(0, str(tmp_path))
    import brdf
    fitted = brdf.open(tmp_path / "red.ggx.json")
    assert fitted.evaluation == "analytic"
    f = fitted.eval_deg(40, 0, 40, 180)
    assert f[0] > f[2] > 0  # a red plastic's highlight
