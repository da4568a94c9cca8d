"""The main job's environment-lit web page, served as the README tells (ctest: demo_web_page,
labels browser, integration).

A demo-like output is made with the commands of tools/run-demo.sh on two library materials
(gold, paper_white): `brdf capture --device sim` of each into out/demo/captures, `brdf convert
out/demo/captures --out out/demo/luts --engine all`, three.js copied in by
tools/copy-web-three.sh (the script run-demo.sh runs). The README's server command (the line
`python3 -m http.server -d out/demo/luts/web PORT`) and the address under it are read from
README.md and run as written, from a folder holding that out/demo, with only the port changed to
a free one; headless Chromium (tests/node/screenshot_page.mjs) opens the README's address once
the server answers and waits until document.title is "ready".

Asserted: the README has the command and an address with env=studio, ibl=1 and lights=0 (no
directional light: whatever lights the sphere is the environment); the server answered every
request of the page but the favicon with 200 (three.js, the module, the KTX2, the pack); the
screenshot (512 x 512) shows the sphere lit: over the disc of 0.8 of the sphere's radius
(the viewer's sphere spans 0.9 of the window) the mean sRGB value is at least 40/255 (not
black), the standard deviation of the pixels' luminance at least 8/255 (not uniform: the
studio's soft boxes are reflected), and the median over those pixels of linear red over linear
blue (sRGB decoded) at least 1.5: gold's F0 is (0.963, 0.787, 0.408) (data-samples/materials/
gold.json, from Johnson and Christy's optical constants), red 2.36 times blue, under a nearly
grey map (pixels where both clip at 1 pull the median towards 1; most of the sphere reflects
the map's 0.05-0.25 gradient and does not clip).
Usage: demo_web_test.py BRDF_TOOL SOURCE_DIR CHROMIUM [--keep]  (Debian python3)
"""
import os
import re
import shlex
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

import numpy as np
import OpenImageIO as oiio

from check_support import expect, finish, run

MATERIALS = ["gold", "paper_white"]
WINDOW = 512


def readme_commands(readme):
    """The README's server command and the address under it (PORT in both as written)."""
    text = open(readme, encoding="utf-8").read()
    server = re.search(r"^\s*(python3 -m http\.server -d (\S+) (\d+))", text, re.M)
    if not server:
        print(f"FAILED: {readme}: no line 'python3 -m http.server -d FOLDER PORT' (the demo page's server)")
        sys.exit(1)
    url = re.search(r"http://localhost:" + server.group(3) + r"/index\.html\?\S+", text[server.end():])
    if not url:
        print(f"FAILED: {readme}: no address http://localhost:{server.group(3)}/index.html?... after the server command")
        sys.exit(1)
    return server.group(1), server.group(2), server.group(3), url.group(0)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    tool, source, chromium = sys.argv[1:4]
    keep = "--keep" in sys.argv
    started = time.time()
    command, folder, port, url = readme_commands(os.path.join(source, "README.md"))
    print(f"README: `{command}`, then {url}")
    query = url.split("?", 1)[1]
    params = dict(p.split("=", 1) for p in query.split("&"))
    expect(params.get("env") == "studio" and params.get("ibl") == "1" and params.get("lights") == "0",
           f"README address {url}: expected env=studio, ibl=1, lights=0")
    material = params.get("material", "")
    expect(material == "gold", f"README address {url}: material={material}, this test makes gold")

    work = tempfile.mkdtemp(prefix="brdf_demo_web_")
    # The README's folder is out/demo/luts/web, run-demo.sh's default output under the checkout.
    expect(folder.endswith("/luts/web"), f"README server folder {folder}: expected OUT/luts/web")
    demo = os.path.join(work, os.path.dirname(os.path.dirname(folder)))
    os.makedirs(os.path.join(demo, "captures"))
    for m in MATERIALS:  # tools/run-demo.sh's commands (its φout step of the test job: 2°)
        run([tool, "capture", "--device", "sim", "--material", m, "--sample", m, "--out",
             os.path.join(demo, "captures", m + ".bpc"), "--seed", "1", "--force", "--phi-out-step", "2"])
    run([tool, "convert", os.path.join(demo, "captures"), "--out", os.path.join(demo, "luts"), "--force",
         "--engine", "all", "--quiet"])
    run([os.path.join(source, "tools", "copy-web-three.sh"), os.path.join(demo, "luts", "web")])
    made_s = time.time() - started

    # The README's command as written, but on a free port.
    mine = free_port()
    argv = shlex.split(command)
    argv[-1] = str(mine)
    server = subprocess.Popen(argv, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        address = url.replace(f"localhost:{port}", f"localhost:{mine}")
        for _ in range(100):
            try:
                urllib.request.urlopen(f"http://localhost:{mine}/index.html", timeout=2).read()
                break
            except OSError:
                if server.poll() is not None:
                    print(f"FAILED: `{' '.join(argv)}` in {work} exited with {server.returncode}:\n{server.stdout.read()}")
                    return 1
                time.sleep(0.1)
        shot = os.path.join(work, "page.png")
        r = subprocess.run(["node", os.path.join(source, "tests", "node", "screenshot_page.mjs"), "--url", address,
                            "--out", shot, "--width", str(WINDOW), "--height", str(WINDOW), "--chromium", chromium,
                            "--timeout-s", "150"], capture_output=True, text=True)
    finally:
        server.terminate()
        log = server.communicate(timeout=10)[0]
    if r.returncode != 0:
        print(f"FAILED: {address}: the page did not become ready\n{r.stdout}\n{r.stderr[-4000:]}\nserver log:\n{log[-3000:]}")
        return 1
    print("browser:", r.stdout.strip())
    requests = re.findall(r'"GET (\S+) HTTP/[\d.]+" (\d+)', log)
    failed = [(p, c) for p, c in requests if c not in ("200", "304") and not p.startswith("/favicon")]
    expect(not failed, f"server: requests not answered with 200: {failed}")
    served = [p for p, _ in requests]
    for want in ("/node_modules/three/build/three.module.js", f"/{material}.ktx2"):
        expect(any(p.startswith(want) for p in served), f"server: the page never asked for {want}")
    print(f"server: {len(requests)} requests, {len(failed)} not 200 (favicon aside)")

    img = oiio.ImageBuf(shot).get_pixels(oiio.UINT8)[..., :3].astype(float)
    h, w = img.shape[:2]
    expect((h, w) == (WINDOW, WINDOW), f"screenshot {w}x{h}, expected {WINDOW}x{WINDOW}")
    j, i = np.mgrid[0:h, 0:w]
    radius = 0.9 * min(h, w) / 2
    disc = np.hypot(i + 0.5 - w / 2, j + 0.5 - h / 2) < 0.8 * radius
    pixels = img[disc]
    mean = pixels.mean(0)
    luminance = pixels @ np.array([0.2126, 0.7152, 0.0722])
    spread = float(luminance.std())
    c = pixels / 255
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    red_blue = float(np.median(linear[:, 0] / np.maximum(linear[:, 2], 1e-4)))
    print(f"sphere (disc of {0.8 * radius:.0f} px, {int(disc.sum())} pixels): mean sRGB {np.round(mean, 1)}, "
          f"luminance std {spread:.1f}, median linear red/blue {red_blue:.2f}")
    expect(mean.mean() >= 40, f"{address}: the sphere is dark: mean sRGB {np.round(mean, 1)} (at least 40 expected)")
    expect(spread >= 8, f"{address}: the sphere is uniform: luminance std {spread:.1f} (at least 8 expected)")
    expect(red_blue >= 1.5, f"{address}: the sphere is not gold: median linear red/blue {red_blue:.2f} (at least 1.5 expected)")
    print(f"times: demo output {made_s:.1f} s, total {time.time() - started:.1f} s")
    return finish(work, keep)


if __name__ == "__main__":
    sys.exit(main())
