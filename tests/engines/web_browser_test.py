"""The web hand-off in a real browser, end to end (ctest label: browser).

A GGX material is captured noise-free and converted by `brdf convert --engine web,unity`; the
exported web folder is served to headless Chromium (WebGL 2 on SwiftShader), which loads the
KTX2 with three.js's KTX2Loader and renders a sphere with the shipped ShaderMaterial
(tests/node/render_web.mjs). tests/python/web_render_check.py then compares, independently of
the code under test:
  - the float image with a numpy reference from the analytic material (RMS and max error),
  - the manifest's probe texels with the KTX2 file and with what the GPU fetched,
  - the shipped GLSL and the shipped Unity HLSL (glslangValidator -D → SPIR-V → spirv-cross →
    GLSL ES, executed by the same WebGL context) with `brdf eval` of the LUT for 300 pairs.
Usage: web_browser_test.py BRDF_TOOL SOURCE_DIR [CHROMIUM]   (Debian /usr/bin/python3; fails when a tool
is missing: install it with tools/install-deps.sh and tools/install-npm-deps.sh)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

MATERIAL = {"model": "ggx", "kd": [0.10, 0.20, 0.35], "f0": [0.04, 0.04, 0.04], "alpha": 0.35}

HARNESS = """// glslang stand-in for Unity's Core RP texture struct (Texture.hlsl)
struct UnityTexture3D { Texture3D tex; SamplerState samplerstate; };
#include "MeasuredBrdf.hlsl"
Texture3D lut : register(t0);
SamplerState lut_sampler : register(s0);
Texture2D<float4> pairs : register(t1);
float4 main(float4 pos : SV_Position) : SV_Target {
  int x = int(pos.x);
  float3 n = pairs.Load(int3(x, 0, 0)).xyz;
  float3 l = pairs.Load(int3(x, 1, 0)).xyz;
  float3 v = pairs.Load(int3(x, 2, 0)).xyz;
  UnityTexture3D t;
  t.tex = lut;
  t.samplerstate = lut_sampler;
  float3 f;
  MeasuredBrdf_float(t, n, l, v, f);
  return float4(f, 1.0);
}
"""


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        print(f"FAILED ({r.returncode}): {' '.join(cmd)}\n{r.stdout}\n{r.stderr[-4000:]}")
        sys.exit(1)
    return r.stdout


def main():
    tool, source = sys.argv[1], sys.argv[2]
    chromium = sys.argv[3] if len(sys.argv) > 3 else "chromium"
    for exe in ("node", "chromium", "glslangValidator", "spirv-cross"):
        if shutil.which(exe) is None:
            print(f"FAILED: {exe} not found; run tools/install-deps.sh")
            return 1
    check = os.path.join(source, "tests/python/web_render_check.py")
    work = tempfile.mkdtemp(prefix="brdf_web_browser_")
    mat = os.path.join(work, "ggx_blue.json")
    with open(mat, "w") as f:
        json.dump(MATERIAL, f)
    out = os.path.join(work, "out")
    run([tool, "convert", mat, "--out", out, "--engine", "web,unity", "--quiet",
         "--formats", "ktx2,json"])
    web = os.path.join(out, "web")
    angles, nlv = os.path.join(work, "angles.txt"), os.path.join(work, "nlv.txt")
    run([sys.executable, check, "gen-pairs", "300", "11", angles, nlv])
    with open(os.path.join(work, "eval.txt"), "w") as f:
        f.write(run([tool, "eval", os.path.join(out, "ggx_blue.ktx2"), "--pairs", angles]))
    harness = os.path.join(out, "unity", "harness.hlsl")
    with open(harness, "w") as f:
        f.write(HARNESS)
    spv = os.path.join(work, "harness.spv")
    run(["glslangValidator", "-D", "-V", "-e", "main", "-S", "frag", harness, "-o", spv])
    es = os.path.join(work, "harness_es.glsl")
    run(["spirv-cross", spv, "--es", "--version", "300", "--output", es])
    result = os.path.join(work, "result")
    os.makedirs(result)
    run(["node", os.path.join(source, "tests/node/render_web.mjs"), "--web", web,
         "--material", "ggx_blue", "--out", result, "--size", "256", "--pairs", nlv,
         "--hlsl-glsl", es, "--chromium", chromium])
    r = subprocess.run([sys.executable, check, "check", "--material", mat, "--result", result,
                        "--ktx2", os.path.join(web, "ggx_blue.ktx2"), "--manifest",
                        os.path.join(web, "ggx_blue.manifest.json"), "--eval",
                        os.path.join(work, "eval.txt"), "--hlsl"], capture_output=True, text=True)
    print(r.stdout + r.stderr, end="")
    # An atlas: the second material's cell (a Lambertian) through the viewer's ?cell= path.
    lam = os.path.join(work, "lambert_orange.json")
    with open(lam, "w") as f:
        json.dump({"model": "lambert", "rho": [0.8, 0.5, 0.2]}, f)
    run([tool, "atlas", mat, lam, "--out", os.path.join(work, "atlas", "set"), "--engine", "web",
         "--quiet"])
    atlas_web = os.path.join(work, "atlas", "web")
    atlas_result = os.path.join(work, "atlas_result")
    os.makedirs(atlas_result)
    run(["node", os.path.join(source, "tests/node/render_web.mjs"), "--web", atlas_web,
         "--material", "set", "--cell", "lambert_orange", "--out", atlas_result, "--size", "128",
         "--chromium", chromium])
    a = subprocess.run([sys.executable, check, "check", "--material", lam, "--result",
                        atlas_result, "--ktx2", os.path.join(atlas_web, "set.ktx2"), "--manifest",
                        os.path.join(atlas_web, "set.manifest.json")], capture_output=True, text=True)
    print("atlas cell lambert_orange: " + (a.stdout + a.stderr).strip().replace("\n", "\natlas: "))
    if a.returncode != 0:
        r = a
    if r.returncode == 0:
        shutil.rmtree(work, ignore_errors=True)
    else:
        print(f"kept {work} for inspection")
    return r.returncode


if __name__ == "__main__":
    sys.exit(main())
