"""The web hand-off in a real browser, end to end (ctest label: browser).

A GGX material is captured noise-free and converted by `brdf convert --engine all`; the
exported web folder is served to headless Chromium (WebGL 2 on SwiftShader), which loads the
KTX2 with three.js's KTX2Loader and renders a sphere with the shipped ShaderMaterial
(tests/node/render_web.mjs). tests/python/web_render_check.py then compares, independently of
the code under test:
  - the float image with a numpy reference from the analytic material (RMS and max error),
  - the manifest's probe texels with the KTX2 file and with what the GPU fetched,
  - every shipped shader with `brdf eval` of the LUT (the default blind-spot fill: θin 0–80°
    every 10°), for 300 random direction pairs, 100 more in the filled region (light at θin
    65–85°, view at θout 76–88°: neither measured by the instrument), and for
    the exact directions where angle math meets a pole or the horizon (views exactly along the
    normal, at the horizon, in the mirror direction; lights exactly along the normal): the
    three.js module's GLSL (MeasuredBrdfCell, MeasuredBrdfTangent), the sidecar's
    texel_convention.glsl, and, executed by the same WebGL context as GLSL ES, the Unity HLSL
    and the Unreal .ush (glslangValidator -D → SPIR-V → spirv-cross), the GLSL 4.50 file
    (glslangValidator -V → SPIR-V → spirv-cross) and the Godot shader (its GLSL ES dialect
    with Godot's additions replaced).
Usage: web_browser_test.py BRDF_TOOL SOURCE_DIR [CHROMIUM]   (Debian /usr/bin/python3; fails when a tool
is missing: install it with tools/install-deps.sh and tools/install-npm-deps.sh)
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

from check_support import run

MATERIAL = {"model": "ggx", "kd": [0.10, 0.20, 0.35], "f0": [0.04, 0.04, 0.04], "alpha": 0.35}

# The HLSL harnesses: a function Evaluate(Lut, LutSampler, N, L, V) calling the shipped code as
# the engine does, and this main() evaluating it for each column of the pairs texture.
HLSL_PAIRS_MAIN = """
Texture3D lut : register(t0);
SamplerState lut_sampler : register(s0);
Texture2D<float4> pairs : register(t1);
float4 main(float4 pos : SV_Position) : SV_Target {
  int x = int(pos.x);
  float3 n = pairs.Load(int3(x, 0, 0)).xyz;
  float3 l = pairs.Load(int3(x, 1, 0)).xyz;
  float3 v = pairs.Load(int3(x, 2, 0)).xyz;
  return float4(Evaluate(lut, lut_sampler, n, l, v), 1.0);
}
"""

# Unity: the Shader Graph entry point, with a glslang stand-in for Core RP's texture struct
# (Texture.hlsl).
UNITY_HARNESS = """struct UnityTexture3D { Texture3D tex; SamplerState samplerstate; };
#include "@INCLUDE@"
float3 Evaluate(Texture3D Lut, SamplerState LutSampler, float3 N, float3 L, float3 V) {
  UnityTexture3D t;
  t.tex = Lut;
  t.samplerstate = LutSampler;
  float3 f;
  MeasuredBrdf_float(t, N, L, V, f);
  return f;
}
""" + HLSL_PAIRS_MAIN

# Unreal wraps a Custom node's code in a function of its inputs (MaterialTemplate.ush
# CustomExpressionN; a TextureObject input "Lut" arrives as Lut and LutSampler). @CODE@ is the
# code line the .ush tells the artist to type.
UNREAL_HARNESS = """#include "@USH@"
float3 Evaluate(Texture3D Lut, SamplerState LutSampler, float3 N, float3 L, float3 V) {
  @CODE@
}
""" + HLSL_PAIRS_MAIN

# Appended to the shipped GLSL 4.50 file for glslangValidator -V (Vulkan GLSL needs bindings).
GL450_MAIN = """
layout(binding = 0) uniform sampler3D lut;
layout(binding = 1) uniform sampler2D pairs;
layout(location = 0) out vec4 color;
void main() {
  int x = int(gl_FragCoord.x);
  vec3 n = texelFetch(pairs, ivec2(x, 0), 0).xyz;
  vec3 l = texelFetch(pairs, ivec2(x, 1), 0).xyz;
  vec3 v = texelFetch(pairs, ivec2(x, 2), 0).xyz;
  color = vec4(MeasuredBrdf(lut, n, l, v), 1.0);
}
"""

# Godot's shading language is GLSL ES 3.0 plus a header, uniform hints and built-ins
# (tests/engines/shader_compile_test.cpp does the same translation to compile it): the built-ins
# become globals that main() fills from the pairs texture, with a white light of unit energy,
# and DIFFUSE_LIGHT, what light() accumulates, is the output.
GODOT_BUILTINS = """precision highp float;
vec3 ALBEDO; float METALLIC; float SPECULAR; float ROUGHNESS;
vec3 NORMAL; vec3 LIGHT; vec3 VIEW; vec3 LIGHT_COLOR; float ATTENUATION;
vec3 DIFFUSE_LIGHT; vec3 SPECULAR_LIGHT; vec3 EMISSION; mat4 INV_VIEW_MATRIX;
"""
GODOT_MAIN = """
uniform highp sampler2D pairs;
layout(location = 0) out highp vec4 fragColor;
void main() {
  int x = int(gl_FragCoord.x);
  NORMAL = texelFetch(pairs, ivec2(x, 0), 0).xyz;
  LIGHT = texelFetch(pairs, ivec2(x, 1), 0).xyz;
  VIEW = texelFetch(pairs, ivec2(x, 2), 0).xyz;
  LIGHT_COLOR = vec3(1.0);
  ATTENUATION = 1.0;
  DIFFUSE_LIGHT = vec3(0.0);
  godot_fragment();
  godot_light();
  fragColor = vec4(DIFFUSE_LIGHT, 1.0);
}
"""



def es_harnesses(out, work):
    """GLSL ES 3.00 sources, each with a main() that evaluates one shipped shader for the pairs
    texture: the Unity HLSL, the Unreal .ush (glslangValidator -D → SPIR-V → spirv-cross), the
    GLSL 4.50 file (glslangValidator -V → SPIR-V → spirv-cross) and the Godot shader
    (translated). Returns {name: path}."""
    def cross(name, src_path, hlsl):
        spv = os.path.join(work, name + ".spv")
        run(["glslangValidator"] + (["-D"] if hlsl else []) +
            ["-V", "-e", "main", "-S", "frag", src_path, "-o", spv])
        es = os.path.join(work, name + "_es.glsl")
        run(["spirv-cross", spv, "--es", "--version", "300", "--output", es])
        return es

    def only(folder, suffix):
        found = sorted(f for f in os.listdir(folder) if f.endswith(suffix))
        if len(found) != 1:
            print(f"FAILED: expected one *{suffix} in {folder}, found {found}")
            sys.exit(1)
        return found[0]

    result = {}
    unity = os.path.join(out, "unity")
    include = only(unity, ".hlsl")
    with open(os.path.join(unity, "harness.hlsl"), "w") as f:
        f.write(UNITY_HARNESS.replace("@INCLUDE@", include))
    result["hlsl"] = cross("unity", os.path.join(unity, "harness.hlsl"), True)

    unreal = os.path.join(out, "unreal")
    ush = only(unreal, ".ush")
    with open(os.path.join(unreal, ush)) as f:
        code = re.search(r"// Code:\s+(return [^\n]+;)", f.read())
    if code is None:
        print(f"FAILED: {ush} names no Custom node code line ('// Code: return ...;')")
        sys.exit(1)
    with open(os.path.join(unreal, "harness.hlsl"), "w") as f:
        f.write(UNREAL_HARNESS.replace("@USH@", ush).replace("@CODE@", code.group(1)))
    result["unreal"] = cross("unreal", os.path.join(unreal, "harness.hlsl"), True)

    web = os.path.join(out, "web")
    with open(os.path.join(web, only(web, ".450.glsl"))) as f:
        gl450 = f.read()
    gl450_path = os.path.join(work, "gl450.frag")
    with open(gl450_path, "w") as f:
        f.write(gl450 + GL450_MAIN)
    result["gl450"] = cross("gl450", gl450_path, False)

    godot = os.path.join(out, "godot")
    with open(os.path.join(godot, only(godot, ".gdshader"))) as f:
        src = f.read()
    for pattern, repl, count in ((r"shader_type spatial;", "", 1),
                                 (r"render_mode [^;]+;", "", 1),
                                 (r"uniform (sampler3D|sampler2D|samplerCube) (\w+) : [^;]+;",
                                  r"uniform highp \1 \2;", 3),
                                 (r"uniform float (\w+) = [^;]+;", r"uniform float \1;", 3),
                                 (r"uniform vec3 (\w+) = [^;]+;", r"uniform vec3 \1;", 3),
                                 (r"void fragment\(\)", "void godot_fragment()", 1),
                                 (r"void light\(\)", "void godot_light()", 1)):
        src, n = re.subn(pattern, repl, src)
        if n != count:
            print(f"FAILED: the Godot shader has {n} matches of {pattern!r}, expected {count}")
            sys.exit(1)
    godot_path = os.path.join(work, "godot_es.glsl")
    with open(godot_path, "w") as f:
        f.write(GODOT_BUILTINS + src + GODOT_MAIN)
    result["godot"] = godot_path
    return result


def bc6h_hand_off(tool, source, chromium, work, mat, angles, nlv, exact_angles, exact_nlv, check):
    """The BC6H hand-off (`--engine all --compress bc6h`): the web module creates the 3D texture
    at 364 × 184 × K (WebGL's multiple-of-4 rule for BPTC) from the KTX2's blocks, and every
    shipped shader of the BC6H form addresses it with 364 and 184 in place of 361 and 181. The
    same pairs (plus pairs at the φd = 0° seam and in the last θd rows, 170–179.6°) through the
    module's GLSL (MeasuredBrdfCell and MeasuredBrdfTangent), the Unity HLSL, the Unreal .ush,
    the GLSL 4.50 file and the Godot shader of the BC6H folders, against `brdf eval` of the same
    BC6H KTX2 (which reads the blocks as a GPU decodes them), to the tolerance of the RGB9E5
    path; the probe texels against the numpy BC6H decoder."""
    out = os.path.join(work, "bc6h_out")
    run([tool, "convert", mat, "--out", out, "--engine", "all", "--compress", "bc6h", "--quiet",
         "--formats", "ktx2,json"])
    ktx2 = os.path.join(out, "ggx_blue.ktx2")
    seam_angles, seam_nlv = os.path.join(work, "seam_angles.txt"), os.path.join(work, "seam_nlv.txt")
    run([sys.executable, check, "gen-seam", seam_angles, seam_nlv])
    b_angles, b_nlv = os.path.join(work, "bc6h_angles.txt"), os.path.join(work, "bc6h_nlv.txt")
    for dst, parts in ((b_angles, (angles, seam_angles)), (b_nlv, (nlv, seam_nlv))):
        with open(dst, "w") as f:
            for part in parts:
                f.write(open(part).read())
    for a, e in ((b_angles, "bc6h_eval.txt"), (exact_angles, "bc6h_exact_eval.txt")):
        with open(os.path.join(work, e), "w") as f:
            f.write(run([tool, "eval", ktx2, "--pairs", a]))
    for folder, suffix in (("unity", ".hlsl"), ("unreal", ".ush"), ("godot", ".gdshader"),
                           ("web", ".js")):
        names = [f for f in os.listdir(os.path.join(out, folder)) if f.endswith(suffix)]
        if names != [n for n in names if n.endswith("_bc6h" + suffix)] or not names:
            print(f"FAILED: the BC6H {folder} folder ships {names}, expected *_bc6h{suffix}")
            sys.exit(1)
    b_work = os.path.join(work, "bc6h_work")
    os.makedirs(b_work)
    harnesses = es_harnesses(out, b_work)
    result = os.path.join(work, "bc6h_result")
    os.makedirs(result)
    run(["node", os.path.join(source, "tests/node/render_web.mjs"), "--web",
         os.path.join(out, "web"), "--material", "ggx_blue", "--out", result, "--size", "64",
         "--pairs", b_nlv, "--exact", exact_nlv,
         "--es-harness", ",".join(f"{k}={v}" for k, v in harnesses.items()),
         "--chromium", chromium])
    size = json.load(open(os.path.join(result, "image.json")))["texture"]["size"]
    if size[:2] != [364, 184]:
        print(f"FAILED: the web module created the BC6H texture at {size}, expected 364 x 184")
        sys.exit(1)
    # (The sidecar's texel_convention.glsl addresses the file's 361 × 181: it is for APIs that
    # create the texture at its true size, not for WebGL.)
    langs = ["glsl", "tangent"] + list(harnesses)
    return subprocess.run([sys.executable, check, "check", "--result", result, "--ktx2",
                           os.path.join(out, "web", "ggx_blue.ktx2"), "--manifest",
                           os.path.join(out, "web", "ggx_blue.manifest.json"), "--langs",
                           ",".join(langs), "--eval", os.path.join(work, "bc6h_eval.txt"),
                           "--angles", b_angles,
                           "--exact-eval", os.path.join(work, "bc6h_exact_eval.txt"),
                           "--exact-angles", exact_angles,
                           "--sidecar", os.path.join(out, "ggx_blue.json")],
                          capture_output=True, text=True)


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
    run([tool, "convert", mat, "--out", out, "--engine", "all", "--quiet",
         "--formats", "ktx2,json"])
    web = os.path.join(out, "web")
    ktx2 = os.path.join(out, "ggx_blue.ktx2")
    with open(os.path.join(out, "ggx_blue.json")) as f:
        beyond = json.load(f).get("beyond") or {}
    if beyond.get("extrapolated_theta_in") != [70.0, 80.0]:
        print(f"FAILED: the LUT carries no filled slices at θin 70 and 80° ({beyond})")
        return 1
    angles, nlv = os.path.join(work, "angles.txt"), os.path.join(work, "nlv.txt")
    run([sys.executable, check, "gen-pairs", "300", "11", angles, nlv])
    exact_angles = os.path.join(work, "exact_angles.txt")
    exact_nlv = os.path.join(work, "exact_nlv.txt")
    run([sys.executable, check, "gen-exact", exact_angles, exact_nlv])
    for a, e in ((angles, "eval.txt"), (exact_angles, "exact_eval.txt")):
        with open(os.path.join(work, e), "w") as f:
            f.write(run([tool, "eval", ktx2, "--pairs", a]))
    harnesses = es_harnesses(out, work)
    result = os.path.join(work, "result")
    os.makedirs(result)
    run(["node", os.path.join(source, "tests/node/render_web.mjs"), "--web", web,
         "--material", "ggx_blue", "--out", result, "--size", "256", "--pairs", nlv,
         "--exact", exact_nlv, "--sidecar", os.path.join(out, "ggx_blue.json"),
         "--es-harness", ",".join(f"{k}={v}" for k, v in harnesses.items()),
         "--chromium", chromium])
    langs = ["glsl", "tangent", "sidecar"] + list(harnesses)
    r = subprocess.run([sys.executable, check, "check", "--material", mat, "--result", result,
                        "--ktx2", os.path.join(web, "ggx_blue.ktx2"), "--manifest",
                        os.path.join(web, "ggx_blue.manifest.json"), "--langs", ",".join(langs),
                        "--eval", os.path.join(work, "eval.txt"), "--angles", angles,
                        "--exact-eval", os.path.join(work, "exact_eval.txt"),
                        "--exact-angles", exact_angles], capture_output=True, text=True)
    print(r.stdout + r.stderr, end="")
    # A real capture's LUT (data-samples/captures/gold.bpc, measured noise and the extrapolated
    # band): its slices are not exactly symmetric, so a lookup at the wrong azimuth or θin
    # shows. The exact directions through every shader against `brdf eval` of its KTX2.
    cap = os.path.join(work, "capture")
    run([tool, "convert", os.path.join(source, "data-samples/captures/gold.bpc"), "--out", cap,
         "--engine", "web", "--quiet", "--formats", "ktx2,json"])
    with open(os.path.join(work, "gold_exact_eval.txt"), "w") as f:
        f.write(run([tool, "eval", os.path.join(cap, "gold.ktx2"), "--pairs", exact_angles]))
    cap_result = os.path.join(work, "capture_result")
    os.makedirs(cap_result)
    run(["node", os.path.join(source, "tests/node/render_web.mjs"), "--web",
         os.path.join(cap, "web"), "--material", "gold", "--out", cap_result, "--size", "64",
         "--exact", exact_nlv, "--sidecar", os.path.join(cap, "gold.json"),
         "--es-harness", ",".join(f"{k}={v}" for k, v in harnesses.items()),
         "--chromium", chromium])
    c = subprocess.run([sys.executable, check, "check", "--result", cap_result, "--ktx2",
                        os.path.join(cap, "web", "gold.ktx2"), "--manifest",
                        os.path.join(cap, "web", "gold.manifest.json"), "--langs",
                        ",".join(langs), "--exact-eval",
                        os.path.join(work, "gold_exact_eval.txt"), "--exact-angles",
                        exact_angles], capture_output=True, text=True)
    print("capture gold.bpc: " + (c.stdout + c.stderr).strip().replace("\n", "\ncapture: "))
    if c.returncode != 0:
        r = c
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
    b = bc6h_hand_off(tool, source, chromium, work, mat, angles, nlv, exact_angles, exact_nlv, check)
    print("BC6H hand-off: " + (b.stdout + b.stderr).strip().replace("\n", "\nBC6H: "))
    if b.returncode != 0:
        r = b
    if r.returncode == 0:
        shutil.rmtree(work, ignore_errors=True)
    else:
        print(f"kept {work} for inspection")
    return r.returncode


if __name__ == "__main__":
    sys.exit(main())
