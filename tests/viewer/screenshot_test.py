#!/usr/bin/python3
"""Screenshots of brdf-view, checked from outside the program.

Each case runs the real executable with DISPLAY unset (so it must re-run itself under
xvfb-run), in its own temporary folder, and reads the PNG back with OpenImageIO. Where a case
checks *where* something is drawn, the position is predicted here from the camera the program
records beside the picture (position, focal point, up, vertical view angle / parallel scale),
with a pinhole projection written in this file, and from the analytic shape of the object
(a Lambertian lobe is a hemisphere of radius rho/pi).

usage: screenshot_test.py CASE BRDF_VIEW SOURCE_DIR
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio
from scipy import ndimage
from scipy.spatial import Delaunay

BACKGROUND = np.array([0.08, 0.08, 0.10]) * 255


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run_view(brdf_view, args, tmp, expect_rc=0):
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    env.pop("BRDF_VIEW_UNDER_XVFB", None)
    proc = subprocess.run([brdf_view] + args, cwd=tmp, env=env, capture_output=True, text=True,
                          timeout=120)
    if proc.returncode != expect_rc:
        fail(f"brdf-view {' '.join(args)} exited {proc.returncode}, expected {expect_rc}\n"
             f"stderr: {proc.stderr}")
    return proc


def read_png(path, width, height):
    if not os.path.exists(path):
        fail(f"{path} was not written")
    inp = oiio.ImageInput.open(path)
    if inp is None:
        fail(f"cannot read {path}: {oiio.geterror()}")
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, 3, "uint8")
    inp.close()
    if (spec.width, spec.height) != (width, height):
        fail(f"{path} is {spec.width}x{spec.height}, expected {width}x{height}")
    return np.asarray(pixels, dtype=float).reshape(height, width, 3)


def non_background(img):
    return np.abs(img - BACKGROUND).max(axis=2) > 12


def check_not_blank(img, min_fraction=0.02):
    nb = non_background(img)
    if nb.mean() < min_fraction:
        fail(f"only {nb.mean():.4f} of the pixels differ from the background")
    if img.std() < 5:
        fail(f"image is nearly uniform (std {img.std():.2f})")


def project_perspective(points, cam, width, height):
    pos = np.array(cam["position"])
    focal = np.array(cam["focal_point"])
    up = np.array(cam["view_up"])
    f = focal - pos
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    d = points - pos
    z = d @ f
    t = np.tan(np.radians(cam["view_angle_deg"]) / 2)
    aspect = width / height
    ndc_x = (d @ r) / (z * t * aspect)
    ndc_y = (d @ u) / (z * t)
    px = (ndc_x + 1) / 2 * width
    py = (1 - ndc_y) / 2 * height  # rows from the top
    return np.stack([px, py], axis=1)


def convex_mask(points_2d, width, height):
    hull = Delaunay(points_2d)
    yy, xx = np.mgrid[0:height, 0:width]
    centres = np.stack([xx.ravel() + 0.5, yy.ravel() + 0.5], axis=1)
    return (hull.find_simplex(centres) >= 0).reshape(height, width)


def case_lobe_lambert(brdf_view, source_dir, tmp):
    width, height = 640, 480
    material = os.path.join(tmp, "lambert.json")
    with open(material, "w") as fh:
        json.dump({"name": "lambert", "model": "lambert", "rho": 0.8}, fh)
    shot = os.path.join(tmp, "lobe.png")
    run_view(brdf_view, [material, "--mode", "lobe", "--theta-in", "30", "--size",
                         f"{width}x{height}", "--screenshot", shot], tmp)
    img = read_png(shot, width, height)
    check_not_blank(img)
    meta = json.load(open(shot + ".json"))
    if (meta["width"], meta["height"]) != (width, height):
        fail(f"camera file says {meta['width']}x{meta['height']}")
    # The lobe of a Lambertian rho = 0.8 (luminance of grey = 0.8) is the hemisphere of radius
    # rho/pi over the surface; its projection is the convex hull of its surface points.
    radius = 0.8 / np.pi
    theta, phi = np.meshgrid(np.radians(np.linspace(0, 90, 91)), np.radians(np.arange(0, 360, 2)))
    dirs = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)],
                    axis=-1).reshape(-1, 3)
    predicted = convex_mask(project_perspective(radius * dirs, meta["camera"], width, height),
                            width, height)
    if predicted.sum() < 2000:
        fail(f"the predicted lobe covers only {predicted.sum()} pixels: camera too far")
    # The lobe is one colour (the top of the colour map, yellow), shaded: pick pixels whose
    # chromaticity is yellow. The legend bar (right edge) also holds that colour: ignore it.
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    yellow = (r > 40) & (g > 35) & (b < 0.6 * g) & (np.abs(r - g) < 0.35 * np.maximum(r, g))
    yellow[:, int(0.85 * width):] = False
    inner = ndimage.binary_erosion(predicted, iterations=3)
    outer = ndimage.binary_dilation(predicted, iterations=4)
    covered = yellow[inner].mean()
    if covered < 0.9:
        fail(f"only {covered:.3f} of the predicted lobe region shows the lobe")
    stray = (yellow & ~outer).sum()
    if stray > 0.01 * predicted.sum():
        fail(f"{stray} lobe-coloured pixels lie outside the predicted region "
             f"({predicted.sum()} pixels)")
    print(f"lobe: {covered:.4f} of the predicted region covered, {stray} stray pixels")


def ggx_mirror_luminance(material, theta_in_deg):
    """Rec.709 luminance of a docs/design.md §9 ggx material's f_r in the mirror direction of a
    light at theta_in (h = n: D = 1/(pi a^2), Smith G1 per direction, Schlick F at v.h = cos)."""
    m = json.load(open(material))
    kd, f0, a = (np.asarray(m[k], float) * np.ones(3) for k in ("kd", "f0", "alpha"))
    c = np.cos(np.radians(theta_in_deg))
    tan2 = (1 - c * c) / (c * c)
    g1 = 2 / (1 + np.sqrt(1 + a * a * tan2))
    f = kd / np.pi + (f0 + (1 - f0) * (1 - c) ** 5) * g1 * g1 / (np.pi * a * a) / (4 * c * c)
    return float(f @ np.array([0.2126, 0.7152, 0.0722]))


def lobe_coloured(img, p, radius=2):
    """Whether any pixel within `radius` of image point p differs from the background."""
    x, y = int(round(p[0])), int(round(p[1]))
    h, w = img.shape[:2]
    if not (radius <= x < w - radius and radius <= y < h - radius):
        fail(f"point {p} projects outside the picture")
    return bool(non_background(img[y - radius:y + radius + 1, x - radius:x + radius + 1]).any())


def wireframe(img, p, radius=3):
    """Whether the pixels around p hold the comparison lobe's wireframe (near-white lines: the
    viewer's default for the second source)."""
    x, y = int(round(p[0])), int(round(p[1]))
    patch = img[y - radius:y + radius + 1, x - radius:x + radius + 1].reshape(-1, 3)
    return bool(((patch.min(axis=1) > 150) & (np.ptp(patch, axis=1) < 40)).any())


def beside(points, axis_from, axis_to, offset):
    """`points` (image coordinates) moved `offset` pixels perpendicular to the image-space axis
    from axis_from to axis_to: off the mirror arrow the viewer draws along that axis."""
    d = np.asarray(axis_to, float) - np.asarray(axis_from, float)
    n = np.array([-d[1], d[0]]) / np.linalg.norm(d)
    return [np.asarray(q) + offset * n for q in points]


def case_lobe_glossy(brdf_view, source_dir, tmp):
    """Gold alone, then gold compared with silver, light at theta_in = 40 deg (a measured slice
    of the reference geometry, so the lobe's mirror vertex is the LUT texel at theta_d = 0 and
    holds the material's own value). The lobe's radius in a direction is f_r's luminance there,
    so each lobe's mirror peak is at r_peak (ggx_mirror_luminance) along the mirror direction
    (theta_in, 180 deg). Projected through the recorded camera (and a few pixels beside the
    mirror arrow drawn along that axis), the gold lobe covers 85 % of its peak and not 115 %.
    Silver (alpha 0.1 against gold's 0.15) peaks more than twice as far: with --compare, the
    mirror direction at 1.3 and 1.5 x gold's peak shows the comparison lobe's wireframe, where the
    gold-only picture is background."""
    width, height = 800, 600
    materials = os.path.join(source_dir, "data-samples", "materials")
    gold, silver = os.path.join(materials, "gold.json"), os.path.join(materials, "silver.json")
    theta = 40.0
    mirror = np.array([-np.sin(np.radians(theta)), 0, np.cos(np.radians(theta))])
    r_gold, r_silver = ggx_mirror_luminance(gold, theta), ggx_mirror_luminance(silver, theta)
    if not r_silver > 1.8 * r_gold:
        fail(f"silver's peak {r_silver:.3f} is not well beyond gold's {r_gold:.3f}")
    shots = {}
    for label, args in (("alone", [gold]), ("compare", [gold, "--compare", silver])):
        shot = os.path.join(tmp, f"gold-{label}.png")
        run_view(brdf_view, args + ["--theta-in", str(theta), "--size", f"{width}x{height}",
                                    "--screenshot", shot], tmp)
        img = read_png(shot, width, height)
        check_not_blank(img, 0.01)
        shots[label] = (img, json.load(open(shot + ".json"))["camera"])
    img, cam = shots["alone"]
    p_origin, p_mirror = project_perspective(np.array([[0, 0, 0], 0.01 * mirror]), cam, width,
                                             height)
    # The light is at +x and the camera looks from -y: the mirror side is left of the normal.
    if not p_mirror[0] < p_origin[0]:
        fail("camera: the mirror direction does not project left of the origin")
    inside, beyond = project_perspective(np.array([0.85 * r_gold * mirror, 1.15 * r_gold * mirror]),
                                         cam, width, height)
    for side in (-5, 5):
        q = beside([inside], p_origin, p_mirror, side)[0]
        if not lobe_coloured(img, q, 1):
            fail(f"gold alone: nothing drawn at 0.85 x its mirror peak ({r_gold:.3f} 1/sr), "
                 f"pixel {q}")
    for side in (-8, 8):
        q = beside([beyond], p_origin, p_mirror, side)[0]
        if lobe_coloured(img, q, 1):
            fail(f"gold alone: the lobe reaches beyond 1.15 x its mirror peak ({r_gold:.3f} 1/sr), "
                 f"pixel {q}")
    along = [f * r_gold * mirror for f in (1.3, 1.5)]
    for label, (img, cam) in shots.items():
        o, m = project_perspective(np.array([[0, 0, 0], 0.01 * mirror]), cam, width, height)
        points = project_perspective(np.array(along), cam, width, height)
        for q, p in zip(along, points):
            for pb in beside([p], o, m, 6) + beside([p], o, m, -6):
                shown = wireframe(img, pb)
                if label == "compare" and not shown:
                    fail(f"--compare: the comparison lobe (silver, peak {r_silver:.3f} 1/sr) is not "
                         f"drawn at {np.linalg.norm(q):.3f} 1/sr along the mirror direction, pixel "
                         f"{pb}: RGB {img[int(pb[1]), int(pb[0])]}")
                if label == "alone" and (shown or lobe_coloured(img, pb, 1)):
                    fail(f"gold alone shows a lobe at {np.linalg.norm(q):.3f} 1/sr, pixel {pb}")
    print(f"glossy lobe: gold's peak {r_gold:.3f} 1/sr where projected, silver's comparison lobe "
          f"(peak {r_silver:.3f} 1/sr) drawn at 1.3 and 1.5 x gold's")


def case_slices(brdf_view, source_dir, tmp):
    width, height = 900, 560
    shot = os.path.join(tmp, "slices.png")
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    run_view(brdf_view, [gold, "--mode", "slices", "--theta-in", "20", "--size",
                         f"{width}x{height}", "--screenshot", shot], tmp)
    img = read_png(shot, width, height)
    check_not_blank(img)
    cam = json.load(open(shot + ".json"))["camera"]
    if not cam["parallel_projection"]:
        fail("slices view is expected to use a parallel projection")
    # Parallel projection: world (x, y) -> pixels with H / (2 * parallel_scale) pixels per unit.
    # The heat map of one slice covers x in [0, 360] (phi_d), y in [0, 180] (180 - theta_d).
    s = height / (2 * cam["parallel_scale"])
    fx, fy = cam["focal_point"][0], cam["focal_point"][1]
    x0 = int(np.ceil(width / 2 + (0 - fx) * s)) + 2
    x1 = int(np.floor(width / 2 + (360 - fx) * s)) - 2
    y0 = int(np.ceil(height / 2 - (180 - fy) * s)) + 2  # top row: theta_d = 0
    y1 = int(np.floor(height / 2 - (0 - fy) * s)) - 2
    if x1 - x0 < 100 or y1 - y0 < 50:
        fail(f"the predicted heat map is only {x1 - x0}x{y1 - y0} pixels")
    region = img[y0:y1, x0:x1]
    filled = non_background(region).mean()
    if filled < 0.98:
        fail(f"only {filled:.3f} of the predicted heat-map region is drawn")
    # Gold is glossy: theta_d = 0 (the mirror direction, top rows) is far brighter in the
    # colour map (viridis: brighter = larger) than theta_d near 90 deg (middle rows).
    lum = region @ np.array([0.2126, 0.7152, 0.0722])
    top = lum[:4].mean()
    middle = lum[lum.shape[0] // 2 - 3: lum.shape[0] // 2 + 3].mean()
    if not top > middle + 40:
        fail(f"top rows (mirror) {top:.1f} not brighter than middle rows {middle:.1f}")
    print(f"slices: heat map filled {filled:.4f}, mirror rows {top:.1f} vs middle {middle:.1f}")


def case_preview(brdf_view, source_dir, tmp):
    width, height = 640, 480
    shot = os.path.join(tmp, "preview.png")
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    run_view(brdf_view, [gold, "--mode", "preview", "--size", f"{width}x{height}",
                         "--screenshot", shot], tmp)
    img = read_png(shot, width, height)
    check_not_blank(img)
    meta = json.load(open(shot + ".json"))
    cam = meta["camera"]
    pw, ph = meta["preview_image"]
    # The render occupies world x in [-0.5, pw - 0.5], y in [-0.5, ph - 0.5] (pixel centres at
    # integers), seen through the parallel camera recorded beside the picture.
    s = height / (2 * cam["parallel_scale"])
    fx, fy = cam["focal_point"][0], cam["focal_point"][1]
    x0 = width / 2 + (-0.5 - fx) * s
    x1 = width / 2 + (pw - 0.5 - fx) * s
    y0 = height / 2 - (ph - 0.5 - fy) * s  # top edge
    y1 = height / 2 - (-0.5 - fy) * s
    inside = img[int(np.ceil(y0)) + 2:int(y1) - 2, int(np.ceil(x0)) + 2:int(x1) - 2]
    if inside.size == 0:
        fail("the predicted preview rectangle is empty")
    filled = non_background(inside).mean()
    if filled < 0.98:
        fail(f"only {filled:.3f} of the predicted preview rectangle is drawn")
    # Beside the rectangle (left and right margins, below the text lines) is background.
    rows = slice(int(np.ceil(y0)) + 2, int(y1) - 2)
    margins = np.concatenate([img[rows, :max(0, int(x0) - 3)].reshape(-1, 3),
                              img[rows, int(np.ceil(x1)) + 3:].reshape(-1, 3)])
    if margins.size and (np.abs(margins - BACKGROUND).max(axis=1) > 12).mean() > 0.02:
        fail("pixels beside the predicted preview rectangle are drawn")
    # The sphere fills 90 % of the render's height around its centre; gold reflects red more
    # than blue, so its middle is warm.
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    r = 0.2 * (y1 - y0)
    core = img[int(cy - r):int(cy + r), int(cx - r):int(cx + r)]
    if not core[..., 0].mean() > core[..., 2].mean() + 10:
        fail(f"the sphere's middle is not gold: RGB {core.reshape(-1, 3).mean(axis=0)}")
    print(f"preview: {pw}x{ph} render filled {filled:.4f} of its predicted rectangle")


def case_load_error(brdf_view, source_dir, tmp):
    width, height = 640, 400
    shot = os.path.join(tmp, "error.png")
    missing = os.path.join(tmp, "no-such-capture.bpc")
    proc = run_view(brdf_view, [missing, "--size", f"{width}x{height}", "--screenshot", shot],
                    tmp, expect_rc=1)
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    if len(lines) != 1 or "no-such-capture.bpc" not in lines[0]:
        fail(f"expected one line naming the file, got: {proc.stderr!r}")
    img = read_png(shot, width, height)
    # The message is drawn in red in the middle of the window.
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    red = (r > 150) & (g < 120) & (b < 120)
    if red[height // 3: 2 * height // 3].sum() < 200:
        fail("no red error message in the middle of the picture")
    print("load error shown in the window: " + lines[0])


def xdo(*args):
    return subprocess.run(["xdotool"] + list(args), capture_output=True, text=True, timeout=30)


def wait_for(path, seconds=30):
    import time
    end = time.time() + seconds
    while time.time() < end:
        if os.path.exists(path) and os.path.getsize(path) > 0:
            time.sleep(0.3)  # let the writer finish
            return True
        time.sleep(0.1)
    return False


def case_interactive_inner(brdf_view, source_dir, tmp):
    """Runs with DISPLAY set (under xvfb-run): drives the real window with xdotool."""
    import time
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    proc = subprocess.Popen([brdf_view, gold, "--size", "800x600"], cwd=tmp,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        found = xdo("search", "--sync", "--limit", "1", "--name", "brdf-view")
        wid = found.stdout.strip().splitlines()[0] if found.stdout.strip() else ""
        if not wid:
            fail(f"no brdf-view window appeared: {found.stderr}")
        xdo("windowfocus", "--sync", wid)
        time.sleep(0.5)
        xdo("key", "--window", wid, "s")
        first = os.path.join(tmp, "brdf-view-1.png")
        if not wait_for(first):
            fail("the s key wrote no brdf-view-1.png")
        lobe = read_png(first, 800, 600)
        check_not_blank(lobe, 0.01)
        # Slices mode, the pointer over the middle of the heat map, another screenshot.
        xdo("key", "--window", wid, "2")
        time.sleep(1.0)
        xdo("mousemove", "--window", wid, "400", "300")
        time.sleep(0.5)
        xdo("mousemove", "--window", wid, "402", "301")
        time.sleep(0.5)
        xdo("key", "--window", wid, "s")
        second = os.path.join(tmp, "brdf-view-2.png")
        if not wait_for(second):
            fail("the second s press wrote no brdf-view-2.png")
        slices = read_png(second, 800, 600)
        if np.abs(slices - lobe).mean() < 5:
            fail("key 2 did not change the picture (slices mode expected)")
        # The hover lines (pale yellow text under the info lines, top left) say what is under
        # the pointer.
        band = slices[int(0.08 * 600):int(0.18 * 600), :int(0.85 * 800)]
        r, g, b = band[..., 0], band[..., 1], band[..., 2]
        pale_yellow = (r > 200) & (g > 190) & (b > 90) & (b < 190)
        if pale_yellow.sum() < 30:
            fail("no hover read-out under the info lines of the slices view")
        xdo("key", "--window", wid, "q")
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            fail("q did not close the window")
        if proc.returncode != 0:
            fail(f"brdf-view exited {proc.returncode} after q: {proc.stderr.read()}")
        print("interactive: s, 2, hover and q work")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def run_inner_under_xvfb(inner_case, brdf_view, source_dir):
    """Runs this script's `inner_case` under one xvfb-run (an X display that already exists
    when brdf-view starts)."""
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", sys.executable,
                           os.path.abspath(__file__), inner_case, brdf_view, source_dir],
                          env=env, capture_output=True, text=True, timeout=150)
    sys.stdout.write(proc.stdout)
    if "PASS" not in proc.stdout:
        fail(f"{inner_case} failed (exit {proc.returncode}): {proc.stderr}")


def case_interactive(brdf_view, source_dir, tmp):
    run_inner_under_xvfb("interactive_inner", brdf_view, source_dir)


def case_no_display(brdf_view, source_dir, tmp):
    env = {"PATH": tmp, "HOME": tmp}  # no DISPLAY, and no xvfb-run on PATH
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    proc = subprocess.run([brdf_view, gold, "--screenshot", os.path.join(tmp, "x.png")],
                          env=env, capture_output=True, text=True, timeout=60)
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    if proc.returncode != 1 or len(lines) != 1 or "xvfb" not in lines[0]:
        fail(f"expected exit 1 and one line about xvfb, got {proc.returncode}: {proc.stderr!r}")
    proc = subprocess.run([brdf_view, gold], env=env, capture_output=True, text=True, timeout=60)
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    if proc.returncode != 1 or len(lines) != 1 or "DISPLAY" not in lines[0]:
        fail(f"expected exit 1 and one line about DISPLAY, got {proc.returncode}: {proc.stderr!r}")
    if os.path.exists(os.path.join(tmp, "x.png")):
        fail("a picture was written without a display")
    print("no display: " + lines[0])


MILESTONES = ["main", "window", "sources opened", "scene", "first frame"]


def parse_timing(stderr):
    """{milestone: (wall_ms, cpu_ms)} from brdf-view's BRDF_VIEW_TIMING lines."""
    import re
    found = {}
    for line in stderr.splitlines():
        m = re.fullmatch(r"brdf-view: timing: (.+) at (-?\d+) ms wall, (\d+) ms CPU after "
                         r"process start", line.strip())
        if m:
            found[m.group(1)] = (int(m.group(2)), int(m.group(3)))
    return found


def check_milestones(found, names, external_wall_ms, what):
    missing = [n for n in names if n not in found]
    if missing:
        fail(f"{what}: no timing line for {missing}; got {found}")
    # Later milestones never come earlier, in wall or CPU time (10 ms clock ticks for the start).
    for a, b in zip(names, names[1:]):
        if found[b][0] < found[a][0] or found[b][1] < found[a][1]:
            fail(f"{what}: '{b}' {found[b]} reported before '{a}' {found[a]}")
    # The process started after this script started it, and the line was read after the
    # program wrote it: the reported time cannot exceed the time measured here (+1 tick).
    last = found[names[-1]][0]
    if not 0 < last <= external_wall_ms + 10:
        fail(f"{what}: '{names[-1]}' at {last} ms after process start, but only "
             f"{external_wall_ms:.0f} ms passed between starting it and reading the line")
    # ...nor fall far short of it (a wrong clock or reference would be off by far more).
    if last < external_wall_ms - 500:
        fail(f"{what}: '{names[-1]}' at {last} ms, {external_wall_ms:.0f} ms measured outside")


def case_startup_timing_inner(brdf_view, source_dir, tmp):
    """Runs with DISPLAY set (under xvfb-run): the start-up milestones against outside clocks."""
    import time
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    env = dict(os.environ, BRDF_VIEW_TIMING="1")
    # A window on the running display: read stderr until the first frame is reported.
    t0 = time.monotonic()
    proc = subprocess.Popen([brdf_view, gold, "--size", "640x480"], cwd=tmp, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    lines = []
    try:
        for line in proc.stderr:
            lines.append(line)
            if "first frame" in line:
                break
        t1 = time.monotonic()
        found = parse_timing("".join(lines))
        check_milestones(found, MILESTONES, (t1 - t0) * 1000, "window")
        shown = xdo("search", "--onlyvisible", "--limit", "1", "--name", "brdf-view")
        if not shown.stdout.strip():
            fail("first frame reported but no brdf-view window is mapped")
        xdo("key", "--window", shown.stdout.split()[0], "q")
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    finally:
        if proc.returncode is None:
            proc.kill()
            proc.wait()
    if proc.returncode != 0:
        fail(f"brdf-view exited {proc.returncode} after q")
    # CPU so far at the first frame cannot exceed what the kernel counted for the whole run.
    total_cpu_ms = (usage.ru_utime + usage.ru_stime) * 1000
    if found["first frame"][1] > total_cpu_ms + 10:
        fail(f"first frame at {found['first frame'][1]} ms CPU, whole run {total_cpu_ms:.0f} ms")
    print(f"window: {found}, whole run {total_cpu_ms:.0f} ms CPU")
    # A screenshot run reports the same milestones, then the written picture.
    shot = os.path.join(tmp, "timed.png")
    t0 = time.monotonic()
    run = subprocess.run([brdf_view, gold, "--size", "640x480", "--screenshot", shot], cwd=tmp,
                         env=env, capture_output=True, text=True, timeout=120)
    t1 = time.monotonic()
    if run.returncode != 0:
        fail(f"timed screenshot exited {run.returncode}: {run.stderr}")
    found = parse_timing(run.stderr)
    check_milestones(found, MILESTONES + ["screenshot"], (t1 - t0) * 1000, "screenshot")
    check_not_blank(read_png(shot, 640, 480), 0.01)
    # Without the variable the program prints nothing about timing (the same picture again).
    run = subprocess.run([brdf_view, gold, "--size", "640x480", "--screenshot", shot, "--force"],
                         cwd=tmp,
                         capture_output=True, text=True, timeout=120,
                         env={k: v for k, v in os.environ.items() if k != "BRDF_VIEW_TIMING"})
    if run.returncode != 0 or "timing" in run.stderr:
        fail(f"untimed screenshot: exit {run.returncode}, stderr {run.stderr!r}")
    print(f"screenshot: {found}")


def case_startup_timing(brdf_view, source_dir, tmp):
    run_inner_under_xvfb("startup_timing_inner", brdf_view, source_dir)


def case_compare_error(brdf_view, source_dir, tmp):
    """A second source that fails to open (it opens on its own thread): one line naming it,
    exit code 1, and the first source still drawn."""
    width, height = 640, 480
    shot = os.path.join(tmp, "compare.png")
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    missing = os.path.join(tmp, "no-such-fit.json")
    proc = run_view(brdf_view, [gold, "--compare", missing, "--size", f"{width}x{height}",
                                "--screenshot", shot], tmp, expect_rc=1)
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    if len(lines) != 1 or "no-such-fit.json" not in lines[0] or "--compare" not in lines[0]:
        fail(f"expected one line naming the --compare file, got: {proc.stderr!r}")
    check_not_blank(read_png(shot, width, height), 0.01)
    print("compare error: " + lines[0])


def case_small_window(brdf_view, source_dir, tmp):
    # At 320 x 240 the overlay text must stay clear of the legend, which starts at 89 % of the
    # width: no text-coloured pixels (bright, grey) in the columns just left of it, in the rows
    # the overlay occupies; and the overlay must be there at all.
    width, height = 320, 240
    shot = os.path.join(tmp, "small.png")
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    run_view(brdf_view, [gold, "--size", f"{width}x{height}", "--screenshot", shot], tmp)
    img = read_png(shot, width, height)
    text = (img.min(axis=2) > 150) & (img.max(axis=2) - img.min(axis=2) < 40)
    rows = slice(0, height // 4)
    overlay = text[rows, : int(0.3 * width)].sum()
    if overlay < 50:
        fail(f"the overlay text is missing ({overlay} text pixels at the top left)")
    gap = text[rows, int(0.75 * width): int(0.88 * width)].sum()
    if gap > 0:
        fail(f"the overlay text runs into the legend: {gap} text pixels in columns "
             f"{int(0.75 * width)}-{int(0.88 * width)} of the top rows")
    print(f"small window: overlay {overlay} text pixels, none next to the legend")


def case_overwrite(brdf_view, source_dir, tmp):
    """The overwrite rule of every writing command: an existing screenshot is refused before
    any work with one line naming it and --force, and left as it was; --force replaces it; a
    folder in its place is refused even with --force."""
    gold = os.path.join(source_dir, "data-samples", "materials", "gold.json")
    shot = os.path.join(tmp, "again.png")
    args = [gold, "--size", "320x240", "--screenshot", shot]
    run_view(brdf_view, args, tmp)
    with open(shot, "rb") as f:
        before = f.read()
    os.utime(shot, (1_000_000_000, 1_000_000_000))
    proc = run_view(brdf_view, args, tmp, expect_rc=1)
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    if (len(lines) != 1 or shot not in lines[0] or "already exists" not in lines[0]
            or "--force" not in lines[0]):
        fail(f"expected one line naming {shot} and --force, got: {proc.stderr!r}")
    with open(shot, "rb") as f:
        if f.read() != before or os.stat(shot).st_mtime != 1_000_000_000:
            fail("the refused run touched the existing screenshot")
    run_view(brdf_view, args + ["--force"], tmp)
    if os.stat(shot).st_mtime == 1_000_000_000:
        fail("--force did not rewrite the screenshot")
    folder = os.path.join(tmp, "folder.png")
    os.mkdir(folder)
    proc = run_view(brdf_view, [gold, "--screenshot", folder, "--force"], tmp, expect_rc=1)
    if "is a folder, not a file" not in proc.stderr or not os.path.isdir(folder):
        fail(f"a folder in the screenshot's place: {proc.stderr!r}")
    print("overwrite: " + lines[0])


CASES = {
    "overwrite": case_overwrite,
    "lobe_lambert": case_lobe_lambert,
    "small_window": case_small_window,
    "lobe_glossy": case_lobe_glossy,
    "slices": case_slices,
    "preview": case_preview,
    "load_error": case_load_error,
    "no_display": case_no_display,
    "interactive": case_interactive,
    "interactive_inner": case_interactive_inner,
    "startup_timing": case_startup_timing,
    "startup_timing_inner": case_startup_timing_inner,
    "compare_error": case_compare_error,
}

if __name__ == "__main__":
    case, brdf_view, source_dir = sys.argv[1], sys.argv[2], sys.argv[3]
    with tempfile.TemporaryDirectory(prefix=f"brdf-view-{case}-") as tmp:
        CASES[case](brdf_view, source_dir, tmp)
    print("PASS")
