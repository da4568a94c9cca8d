"""Measured materials under three.js's own reflection probes, in a real browser, against the
CPU (ctest: ibl_browser, labels browser, integration).

Materials: every material of the library (`brdf materials --json`, 18 today), every RGL file of
the data path (BRDF_DATA_DIR, default ../shared/brdf-data: rgl/*.bsdf, 18 today, each through
`brdf import`), and the real capture data-samples/captures/gold.bpc converted with `--beyond
auto` (a 9-slice LUT, θin 0–80° every 10°), all by `brdf convert --engine web`. An
equirectangular EXR written here (a sky, a ground and three soft lights) is the environment.
Runtime (aim ≤ 150 s on 2 loaded cores): a 96² sphere, one browser page rendering every
material, the `brdf preview` references two at a time while the browser renders, the
mutations only for the glossy materials of MUTATE, three CPU furnace runs (the capture, gold
and the first RGL file).

The browser (tests/node/render_ibl.mjs: headless Chromium on SwiftShader, three.js from npm)
prefilters that EXR with three's PMREMGenerator and shades a 96² sphere with the shipped
module's probe term; the references are `brdf preview` of the same exported KTX2 with the same
map and camera: the true environment-lit image (the rendering integral, the default) and
`--ibl engine` (the CPU split sum: order-2 SH irradiance and its own GGX-prefiltered pyramid,
independent of three's PMREM). Pixels: the sphere's pixels whose centre lies at least 1.5
pixels inside the silhouette (the tessellated sphere's rim is not the ray-traced one).
Figures per material: relative RMSE = RMS(browser − ref) / RMS(ref) over those pixels and
channels; p95 = 95th percentile over pixels of |browser − ref| / max(|ref|, 5 % of the mean
|ref|) (RGB norms).

Asserted:
  - browser against the CPU split sum: relative RMSE ≤ 2 % and p95 ≤ 6 % for every material
    (the two implementations of the same split sum agree; both bounds leave room for the two
    prefilters' different kernels and resolutions);
  - browser against the truth (the issue's targets): median over the materials of the relative
    RMSE ≤ 3 %, and the MEDIAN OVER THE MATERIALS OF EACH MATERIAL'S OWN 95th-percentile pixel
    ≤ 10 %, the 95th percentile of all materials' pixels pooled ≤ 10 % (the issue's pixel
    bound), and that of the library materials' pixels pooled ≤ 10 %. The 95th percentile of
    the RGL files' pixels pooled, and the materials whose own p95 exceeds 10 %, are printed,
    not asserted (docs/benchmarks/ibl.md names them and why);
  - browser against the truth: no worse than 1.25 × the relative RMSE three's
    MeshStandardMaterial makes on the GGX material (gold) against that material's own truth
    (`brdf preview gold`) in the same scene;
  - white furnace (uniform radiance 1): the browser sphere, and `brdf preview --env furnace
    --ibl engine`, equal the manifest's E(μ) at every pixel's μ = n·v within 0.5 % (for the
    browser beyond the change of E over μ ± 0.002, the uncertainty of a rasterised pixel's μ,
    which matters only where E steps between two rows of the pack; the raw maximum is printed);
  - mutations (rendered for the glossy materials of MUTATE): the pack with every α_eq and the
    broad lobe's broad_alpha 10 % larger (broad_alpha at most 1), and the pack with E dropped (the weights divided by E = D + S), each rendered by the
    same page, must break the bound against the CPU split sum for gold (the test fails if they
    would pass; for rough and diffuse materials a 10 % change of α_eq moves the image by less
    than the bound, so they are not mutated).
  - an atlas (gold, paper_white) from `brdf atlas --engine web`: its paper cell, read at the
    cell's origin and the pack's row 1, renders as the single paper LUT within 0.1 % RMSE;
  - the shipped viewer (index.html?material=gold&env=furnace&ibl=1&lights=0&tonemap=linear
    &background=0) in a 512 x 512 window: title "ready", canvas over the whole window, the
    sphere centred and 0.9 of it across, centre pixel sRGB(E(1));
Reported, not asserted: browser against the truth per material (the split sum's own error,
largest at the rim of glossy materials), next to the CPU split sum against the truth.
Usage: ibl_browser_test.py BRDF_TOOL SOURCE_DIR CHROMIUM DATA_DIR [--keep]  (Debian python3)
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import OpenImageIO as oiio

from check_support import expect, finish, run

SIZE = 96
CAPTURE = "gold_capture"  # data-samples/captures/gold.bpc, --beyond auto
GGX_REFERENCE = "gold"
# The mutations are rendered for glossy materials only (a 10 % change of a rough lobe's α_eq
# moves the image by less than the split-sum bound; docs/benchmarks/ibl.md).
MUTATE = ["gold", "copper", "vch_silk_blue_rgb", CAPTURE]
JOBS = 2  # the CPU references and the RGL imports, two processes at a time
ATLAS_CELL = "paper_white"  # cell 1 of the atlas "pair" (gold, paper_white)
ATLAS_RMSE = 0.001
SPLIT_SUM_RMSE, SPLIT_SUM_P95 = 0.02, 0.06
FURNACE_TOLERANCE = 0.005
STANDARD_RATIO = 1.25
TRUTH_MEDIAN_RMSE, TRUTH_P95 = 0.03, 0.10




def write_environment(path):
    """A sky over a darker ground, three soft lights (Gaussian, σ 10°, 16°, 25°), float EXR."""
    w, h = 512, 256
    j, i = np.mgrid[0:h, 0:w]
    th = (j + 0.5) / h * np.pi
    ph = (i + 0.5) / w * 2 * np.pi
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    up = d[..., 2:3]
    img = np.where(up > 0, np.array([0.35, 0.5, 0.8]) * (0.6 + 0.4 * up),
                   np.array([0.25, 0.2, 0.15]) * (1 + 0.5 * up))
    for theta, phi, sigma, peak, colour in ((50, 30, 10, 6.0, [1, 0.95, 0.85]),
                                            (75, -70, 16, 2.5, [0.8, 0.9, 1.0]),
                                            (100, 160, 25, 1.5, [1, 0.6, 0.4])):
        a = np.radians([theta, phi])
        c = np.array([np.sin(a[0]) * np.cos(a[1]), np.sin(a[0]) * np.sin(a[1]), np.cos(a[0])])
        g = np.arccos(np.clip(d @ c, -1, 1))
        img = img + peak * np.exp(-0.5 * (g / np.radians(sigma)) ** 2)[..., None] * np.array(colour)
    out = oiio.ImageOutput.create(path)
    spec = oiio.ImageSpec(w, h, 3, "float")
    spec.attribute("compression", "none")
    out.open(path, spec)
    out.write_image(img.astype(np.float32))
    out.close()


def read_exr(path):
    buf = oiio.ImageBuf(path)
    return buf.get_pixels(oiio.FLOAT).reshape(SIZE, SIZE, -1)[..., :3].astype(np.float64)


def read_browser(path):
    """RGBA32F rows top first, mirrored left-right back into the preview's frame."""
    return np.fromfile(path, dtype="<f4").reshape(SIZE, SIZE, 4)[:, ::-1, :3].astype(np.float64)


# The preview's orthographic camera on +x (docs/preview.md): pixel centres, the unit sphere's
# diameter over 0.9 of the frame; the normal of each pixel's hit and mu = n.v with v = +x.
Y, X = np.mgrid[0:SIZE, 0:SIZE]
SX = ((X + 0.5) / SIZE * 2 - 1) / 0.9
SY = (1 - (Y + 0.5) / SIZE * 2) / 0.9
R = np.hypot(SX, SY)
MASK = R < 1 - 1.5 * 2 / (0.9 * SIZE)
MU = np.sqrt(np.clip(1 - R ** 2, 0, 1))


def pixel_errors(a, ref):
    d, t = (a - ref)[MASK], ref[MASK]
    norm = np.linalg.norm(t, axis=1)
    return np.linalg.norm(d, axis=1) / np.maximum(norm, 0.05 * norm.mean())


def metrics(a, ref):
    d, t = (a - ref)[MASK], ref[MASK]
    rel_rmse = float(np.sqrt((d ** 2).mean()) / np.sqrt((t ** 2).mean()))
    return rel_rmse, float(np.percentile(pixel_errors(a, ref), 95))


def albedo_at(manifest, mu):
    """E(mu) as the pack's linear texture returns it (clamped beyond the first and last row)."""
    table_mu = np.asarray(manifest["ibl"]["mu"])
    e = np.asarray(manifest["ibl"]["albedo_rgb"])
    return np.stack([np.interp(mu, table_mu, e[:, c]) for c in range(3)], -1)


# How far a pixel's mu can lie from the analytic MU of its centre in the browser (the
# tessellated sphere's rasterised normals, sub-pixel precision): 0.002 (0.05 px at mid radius).
MU_UNCERTAINTY = 0.002


def furnace_error(image, manifest, mu_uncertainty=0.0):
    """Max over pixels of |image - E(mu)| / E(mu), less the change of E over +-mu_uncertainty
    (where E steps between rows, e.g. at a LUT's last measured angle, a pixel's mu matters)."""
    want = albedo_at(manifest, MU)
    slope = np.maximum(np.abs(albedo_at(manifest, MU + mu_uncertainty) - want),
                       np.abs(albedo_at(manifest, MU - mu_uncertainty) - want))[MASK]
    want = want[MASK]
    got = image[MASK]
    excess = np.maximum(np.abs(got - want) - slope, 0.0)
    return float((excess / np.maximum(want, 1e-3)).max())


def check_viewer(png, manifest):
    """The shipped index.html in a 512 x 512 window (furnace, ibl=1, lights=0, tonemap=linear,
    background=0): the canvas covers the window (no page-background #111 pixel), the sphere is
    centred and 0.9 of the window across (its middle row and column), and its centre pixel is
    sRGB(E(1)) of the manifest within 2/255."""
    img = oiio.ImageBuf(png).get_pixels(oiio.UINT8)[..., :3].astype(int)
    h, w = img.shape[:2]
    expect((h, w) == (512, 512), f"viewer screenshot {w}x{h}")
    lit = img.max(-1) > 0
    page = (img == 17).all(-1)
    expect(not page.any(), f"viewer: {int(page.sum())} pixels show the page, not the canvas")
    row, col = lit[h // 2], lit[:, w // 2]
    across = (np.flatnonzero(row)[[0, -1]] if row.any() else np.array([0, -1]))
    down = (np.flatnonzero(col)[[0, -1]] if col.any() else np.array([0, -1]))
    centre_x, centre_y = across.mean(), down.mean()
    diameter = across[1] - across[0] + 1
    expect(abs(centre_x - (w - 1) / 2) <= 1.5 and abs(centre_y - (h - 1) / 2) <= 1.5,
           f"viewer: sphere centred at ({centre_x}, {centre_y})")
    expect(abs(diameter - 0.9 * h) <= 4, f"viewer: sphere {diameter} px across, expected {0.9 * h:.0f}")
    e = albedo_at(manifest, np.array(1.0))
    srgb = np.where(e <= 0.0031308, 12.92 * e, 1.055 * np.power(np.clip(e, 0, 1), 1 / 2.4) - 0.055) * 255
    got = img[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1].reshape(-1, 3).mean(0)
    expect(np.abs(got - srgb).max() <= 2.0, f"viewer: centre pixel {got} vs sRGB(E(1)) {srgb}")
    print(f"viewer: title ready, canvas covers the 512x512 window, sphere {diameter} px across centred at "
          f"({centre_x:.1f}, {centre_y:.1f}), centre {np.round(got, 1)} vs sRGB(E(1)) {np.round(srgb, 1)}")


def run_all(commands, jobs=JOBS):
    """Runs the commands `jobs` at a time (each must succeed, as run())."""
    with ThreadPoolExecutor(jobs) as pool:
        list(pool.map(run, commands))


def main():
    tool, source, chromium, data_dir = sys.argv[1:5]
    keep = "--keep" in sys.argv
    data_dir = os.environ.get("BRDF_DATA_DIR", data_dir)
    work = tempfile.mkdtemp(prefix="brdf_ibl_browser_")
    started = time.time()
    env = os.path.join(work, "env.exr")
    write_environment(env)
    out = os.path.join(work, "out")
    # Every material of the library (`brdf materials`) and every RGL file of the data folder.
    library = [m["name"] for m in json.loads(run([tool, "materials", "--json"]))]
    rgl = sorted(glob.glob(os.path.join(data_dir, "rgl", "*.bsdf")))
    if not rgl:
        print(f"FAILED: {os.path.join(data_dir, 'rgl')}: no .bsdf files (set BRDF_DATA_DIR to the brdf-data folder)")
        return 1
    rgl_names = [os.path.basename(p)[:-len(".bsdf")] for p in rgl]
    # RGL files become noise-free virtual captures at the instrument's geometry (brdf import).
    captures = [os.path.join(work, n + ".bpc") for n in rgl_names]
    run_all([[tool, "import", p, "--out", c] for p, c in zip(rgl, captures)])
    run([tool, "convert", *library, *captures, "--out", out, "--engine", "web", "--quiet", "--jobs", str(JOBS),
         "--formats", "ktx2"])
    capture = os.path.join(work, CAPTURE + ".bpc")
    shutil.copyfile(os.path.join(source, "data-samples", "captures", "gold.bpc"), capture)
    run([tool, "convert", capture, "--beyond", "auto", "--out", out, "--engine", "web", "--quiet",
         "--formats", "ktx2"])
    # An atlas of two library materials: its second cell (paper) must render as paper does.
    run([tool, "atlas", "gold", ATLAS_CELL, "--out", os.path.join(out, "pair"), "--engine", "web",
         "--quiet"])
    names = library + rgl_names + [CAPTURE]
    kind = {n: "library" for n in library} | {n: "RGL" for n in rgl_names} | {CAPTURE: "capture"}
    manifests = {n: json.load(open(os.path.join(out, "web", n + ".manifest.json"))) for n in names}
    slices = len(manifests[CAPTURE]["theta_in_deg"])
    expect(slices != 4, f"{CAPTURE}: --beyond auto gave {slices} slices; the test wants a non-4-slice LUT")
    prep_s = time.time() - started

    # The browser: every material and the furnace in one page; the mutations for MUTATE;
    # MeshStandardMaterial on gold.
    gold = json.load(open(os.path.join(source, "data-samples", "materials", "gold.json")))
    standard = list(gold["f0"]) + [1.0, float(np.sqrt(gold["alpha"]))]
    renders = os.path.join(work, "browser")
    os.makedirs(renders)
    # The browser runs while the CPU references are computed (same map, camera and KTX2).
    t0 = time.time()
    node = subprocess.Popen(
        ["node", os.path.join(source, "tests", "node", "render_ibl.mjs"), "--web",
         os.path.join(out, "web"), "--materials", ",".join(names + ["pair:" + ATLAS_CELL]), "--env", env, "--out", renders,
         "--size", str(SIZE), "--chromium", chromium, "--mutate", ",".join(MUTATE), "--timeout-s", "300",
         "--standard", ",".join(f"{v:.9g}" for v in standard), "--viewer", GGX_REFERENCE],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    refs = os.path.join(work, "refs")
    os.makedirs(refs)
    preview = [tool, "preview", "--env", env, "--size", str(SIZE), "--no-background", "--quiet",
               "--jobs", "1"]
    commands = []
    for n in names:
        ktx2 = os.path.join(out, n + ".ktx2")
        commands.append(preview + [ktx2, "--out", os.path.join(refs, n + ".truth.exr")])
        commands.append(preview + [ktx2, "--ibl", "engine", "--out", os.path.join(refs, n + ".engine.exr")])
    commands.append(preview + [GGX_REFERENCE, "--out", os.path.join(refs, "ggx.truth.exr")])
    # `--ibl engine` under the white furnace: one material of each kind (0.3 s each).
    furnace_cpu = [CAPTURE, GGX_REFERENCE, rgl_names[0]]
    for n in furnace_cpu:
        commands.append([tool, "preview", os.path.join(out, n + ".ktx2"), "--env", "furnace", "--ibl",
                         "engine", "--size", str(SIZE), "--no-background", "--quiet", "--jobs", "1",
                         "--out", os.path.join(refs, n + ".furnace.exr")])
    run_all(commands)
    cpu_s = time.time() - t0
    log, err = node.communicate(timeout=400)
    browser_s = time.time() - t0
    if node.returncode != 0:
        print(f"FAILED: render_ibl.mjs exited with {node.returncode}\n{log}\n{err[-4000:]}")
        return 1
    print("browser:", log.strip().splitlines()[-1][:400])

    rows = []
    pooled = {"library": [], "RGL": [], "capture": []}  # every material's pixel errors against the truth
    mutation_caught = {"alpha110": [], "noE": []}
    for n in names:
        truth = read_exr(os.path.join(refs, n + ".truth.exr"))
        engine = read_exr(os.path.join(refs, n + ".engine.exr"))
        ibl = read_browser(os.path.join(renders, n + ".ibl.f32"))
        vs_engine = metrics(ibl, engine)
        vs_truth = metrics(ibl, truth)
        cpu_truth = metrics(engine, truth)
        # Mean brightness of the browser's sphere over the truth's, less 1.
        bias = float(ibl[MASK].sum() / truth[MASK].sum() - 1)
        furnace_image = read_browser(os.path.join(renders, n + ".furnace.f32"))
        furnace = furnace_error(furnace_image, manifests[n], MU_UNCERTAINTY)
        furnace_raw = furnace_error(furnace_image, manifests[n])
        rows.append((n, vs_engine, vs_truth, cpu_truth, furnace, furnace_raw, bias))
        pooled[kind[n]].append(pixel_errors(ibl, truth))
        expect(vs_engine[0] <= SPLIT_SUM_RMSE and vs_engine[1] <= SPLIT_SUM_P95,
               f"{n}: browser vs CPU split sum: relative RMSE {vs_engine[0]:.4f} (bound "
               f"{SPLIT_SUM_RMSE}), p95 {vs_engine[1]:.4f} (bound {SPLIT_SUM_P95})")
        expect(furnace <= FURNACE_TOLERANCE, f"{n}: white furnace: max relative error {furnace:.5f} against E(mu)")
        for m in mutation_caught if n in MUTATE else ():
            mm = metrics(read_browser(os.path.join(renders, f"{n}.{m}.f32")), engine)
            if mm[0] > SPLIT_SUM_RMSE or mm[1] > SPLIT_SUM_P95:
                mutation_caught[m].append((n, mm))
    print(f"{'material':32s} {'browser vs CPU split sum':>26s} {'browser vs truth':>20s} "
          f"{'CPU split sum vs truth':>24s} {'bias':>7s} {'furnace (raw)':>16s}")
    for n, ve, vt, ct, fu, fr, bias in rows:
        print(f"{n:32s} {ve[0]:12.4f} {ve[1]:12.4f}  {vt[0]:9.4f} {vt[1]:9.4f}  {ct[0]:11.4f} {ct[1]:11.4f}  "
              f"{bias:+7.3f}  {fu:8.5f} ({fr:.5f})")
    median_rmse = float(np.median([r[2][0] for r in rows]))
    median_p95 = float(np.median([r[2][1] for r in rows]))
    pooled_all = float(np.percentile(np.concatenate(sum(pooled.values(), [])), 95))
    pooled_kind = {k: float(np.percentile(np.concatenate(v), 95)) for k, v in pooled.items()}
    over = [(r[0], r[2][1]) for r in rows if r[2][1] > TRUTH_P95]
    print(f"browser vs truth over {len(rows)} materials ({len(library)} library, {len(rgl_names)} RGL, "
          f"the capture): median relative RMSE {median_rmse:.4f} (bound {TRUTH_MEDIAN_RMSE}, asserted); "
          f"median of the per-material 95th-percentile pixel {median_p95:.4f} (bound {TRUTH_P95}, "
          f"asserted); 95th percentile of all materials' pixels pooled {pooled_all:.4f} (bound {TRUTH_P95}, "
          f"asserted), of the library's "
          f"{pooled_kind['library']:.4f} (asserted), of the RGL files' {pooled_kind['RGL']:.4f} (not "
          f"asserted); browser vs CPU split sum: median "
          f"relative RMSE {np.median([r[1][0] for r in rows]):.4f}")
    print(f"materials whose own 95th-percentile pixel exceeds {TRUTH_P95}: {len(over)} of {len(rows)}: "
          + ", ".join(f"{n} {v:.3f}" for n, v in sorted(over, key=lambda x: -x[1])))
    expect(median_rmse <= TRUTH_MEDIAN_RMSE, f"browser vs truth: median relative RMSE {median_rmse:.4f}")
    expect(median_p95 <= TRUTH_P95, f"browser vs truth: median 95th-percentile pixel {median_p95:.4f}")
    expect(pooled_all <= TRUTH_P95,
           f"browser vs truth: 95th percentile of all materials' pixels pooled {pooled_all:.4f}")
    expect(pooled_kind["library"] <= TRUTH_P95,
           f"browser vs truth: 95th percentile of the library materials' pixels pooled {pooled_kind['library']:.4f}")

    standard_err = metrics(read_browser(os.path.join(renders, "standard.f32")),
                           read_exr(os.path.join(refs, "ggx.truth.exr")))
    ours = dict((r[0], r[2]) for r in rows)[GGX_REFERENCE]
    print(f"{GGX_REFERENCE}: measured LUT vs its truth {ours[0]:.4f} (p95 {ours[1]:.4f}); three's "
          f"MeshStandardMaterial vs the GGX material's truth {standard_err[0]:.4f} (p95 "
          f"{standard_err[1]:.4f}); ratio {ours[0] / standard_err[0]:.3f} (bound {STANDARD_RATIO})")
    expect(ours[0] <= STANDARD_RATIO * standard_err[0],
           f"{GGX_REFERENCE}: relative RMSE {ours[0]:.4f} > {STANDARD_RATIO} x MeshStandardMaterial's {standard_err[0]:.4f}")

    for n in furnace_cpu:
        cpu_furnace = furnace_error(read_exr(os.path.join(refs, n + ".furnace.exr")), manifests[n])
        label = f"{n} ({slices} slices)" if n == CAPTURE else n
        print(f"{label}: --ibl engine under the white furnace: max relative error {cpu_furnace:.5f}")
        expect(cpu_furnace <= FURNACE_TOLERANCE, f"{n}: --ibl engine furnace: max relative error {cpu_furnace:.5f}")

    check_viewer(os.path.join(renders, "viewer.png"), manifests[GGX_REFERENCE])

    single = read_browser(os.path.join(renders, ATLAS_CELL + ".ibl.f32"))
    cell = read_browser(os.path.join(renders, f"pair.{ATLAS_CELL}.ibl.f32"))
    atlas_err = metrics(cell, single)
    print(f"atlas pair, cell {ATLAS_CELL} (pack row 1): relative RMSE {atlas_err[0]:.6f} against "
          f"the single LUT's render (bound {ATLAS_RMSE})")
    expect(atlas_err[0] <= ATLAS_RMSE, f"atlas cell {ATLAS_CELL}: relative RMSE {atlas_err[0]:.6f} against its own LUT")

    for m, caught in mutation_caught.items():
        print(f"mutation {m}: fails the split-sum bound for {len(caught)} of the {len(MUTATE)} mutated: "
              + ", ".join(f"{n} {v[0]:.4f}/{v[1]:.4f}" for n, v in caught))
        expect(any(n == GGX_REFERENCE for n, _ in caught), f"mutation {m} would pass the test for {GGX_REFERENCE}")
    print(f"times: imports and conversions {prep_s:.1f} s, CPU references {cpu_s:.1f} s and the browser "
          f"{browser_s:.1f} s (concurrently), "
          f"total {time.time() - started:.1f} s")
    return finish(work, keep)


if __name__ == "__main__":
    sys.exit(main())
