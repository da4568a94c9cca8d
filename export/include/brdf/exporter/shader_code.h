// The shader lookup of an exported LUT or atlas in every language the engine hand-off ships:
// GLSL (one text for GLSL ES 3.00 and GLSL 4.50), HLSL (Unity includes, Unreal .ush) and the
// Godot 4 shading language. All three are generated from ONE template (shader_code.cpp), so
// they cannot disagree; only the type names, the atan2 spelling, constants and the texture
// fetch differ.
//
// What the generated code computes (docs/design.md §4, §5; paper §5.1, Figure 8), given a unit
// normal n, a unit light direction l and a unit view direction v, all pointing away from the
// surface and expressed in any one frame (world, view or tangent space):
//   1. The tangent frame of the light: z = n, x = the projection of l onto the tangent plane,
//      normalised (so φin = 0), y = z × x. When l is (nearly) parallel to n any tangent does,
//      because the material is isotropic and slice θin = 0 is symmetric about n.
//   2. θin = atan2(|l − n(n·l)|, n·l) and v in that frame, v_local = (v·x, v·y, v·n).
//   3. ω_d = S(θin)·v_local, S = [[−cosθin, 0, −sinθin], [0, −1, 0], [−sinθin, 0, cosθin]]
//      (the specular frame: the mirror direction of l maps to the pole θd = 0).
//   4. θd = atan2(|ω_d.xy|, ω_d.z) (accurate near the pole, where acos(z) loses half its
//      digits: at θd = 0.5° a half-precision z = cos θd is 1 − 3.8e-5, below half's 4.9e-4
//      step), φd = atan2(ω_d.y, ω_d.x) wrapped to [0°, 360°) (0 at the pole itself, where
//      atan2(0, 0) is undefined in GLSL).
//   5. Centre-exact texture coordinates (docs/design.md §5):
//        u = (x0 + φd/1° + 0.5)/W, v = (y0 + θd/1° + 0.5)/H, w = ((θin − θin,0)/Δin + 0.5)/K,
//      with (x0, y0) the texel origin of the material's cell (0, 0 for a single LUT) and W × H
//      the texture size (361 × 181 for a single LUT); u and v are clamped to the cell's outer
//      texel centres so an atlas never filters into a neighbour. The published form
//      (u = φd/2π, v = θd/π, w = θin/θin,max) is half a texel off; it is quoted in a comment.
//   6. One trilinear fetch at mip level 0 (the sampler must be linear, clamp-to-edge on all
//      three axes, no mipmaps, no sRGB decode).
// The result is f_r in 1/sr, linear RGB, NOT multiplied by cosθin: outgoing radiance from a
// directional light of irradiance-at-normal-incidence E is f_r · E · max(n·l, 0).
// Above the last measured θin (60° for the reference instrument) the clamp-to-edge w axis
// selects the last slice, read at the ω_d of the actual θin (the lobe keeps following the
// mirror direction; `brdf eval` of a LUT does the same); below the first slice, the first. Light
// below the horizon (n·l ≤ 0) returns the value for θin = 90° clamped the same way; the caller's
// max(n·l, 0) makes it contribute nothing.
//
// Entry points in the generated code (same names and argument order in every language):
//   MeasuredBrdfCoords(sin_in, cos_in, v_local, cell_texels) → uvw     (pure arithmetic)
//   MeasuredBrdfTangent([lut,] cell_texels, l_ts, v_ts) → f_r          (tangent space, z = n)
//   MeasuredBrdfCell([lut,] cell_texels, n, l, v) → f_r                (any space)
//   MeasuredBrdf([lut,] n, l, v) → f_r                                 (cell (0, 0))
// [lut,] is `highp sampler3D lut` in GLSL, `Texture3D lut, SamplerState lut_sampler` in HLSL and
// absent in Godot, whose code reads the uniform `measured_brdf_lut` the .gdshader declares.
//
// Image-based lighting (docs/engines.md, "ibl": the split sum of the material's IBL pack,
// brdf/core/ibl_pack.h), the same in every language; the engine supplies its two probe values:
//   MeasuredBrdfIblPack([pack,] pack_v, mu, diffuse0, diffuse1, diffuse2, out diffuse,
//                       out specular) → α_eq
//       the material's row of the RGBA16F pack texture (IblPack::kRows texels (S, α_eq)) at
//       μ = n·v, one linear fetch; pack_v the row's v; diffuse = c0 + c1·t + c2·t², t = 1 − μ
//       (μ clamped to the texel centres), from the material's constants diffuse0…2
//   MeasuredBrdfIblDirection(n, v, α_eq) → normalize(mix(R, n, α_eq·(1 − n·v))), R = 2(n·v)n − v
//       (IblSpecularDirection, brdf/core/ibl_pack.h)
//   MeasuredBrdfIblRadiance(diffuse, specular, irradiance_over_pi, prefiltered) → radiance
//       = diffuse·irradiance_over_pi + specular·prefiltered (the probe filtered with GGX α_eq)
// [pack,] is `highp sampler2D pack` in GLSL, `Texture2D pack, SamplerState pack_sampler` in
// HLSL, and the uniform `measured_brdf_ibl_pack` in Godot.
#pragma once

#include <string>
#include <vector>

namespace brdf::exporter {

enum class ShaderLanguage {
  kGlsl,   // body valid as GLSL ES 3.00 and GLSL 4.50 (no #version line)
  kHlsl,   // Shader Model 4+ HLSL (Unity, Unreal, glslang's HLSL front end)
  kGodot,  // Godot 4 shading language (functions only; the .gdshader adds the uniform)
};

// The constants the lookup needs.
struct ShaderLutLayout {
  double theta_in0_deg = 0;  // θin of slice 0
  double delta_in_deg = 20;  // Δin (any positive value for a single slice)
  int slices = 4;            // K
  int texture_width = 361;   // W: 361 for a LUT, Cm·361 for an atlas
  int texture_height = 181;  // H: 181 for a LUT, Rm·181 for an atlas
};

// The layout of a single LUT with this θin list. Throws InvalidArgument for an empty list.
ShaderLutLayout LutShaderLayout(const std::vector<double>& theta_in_deg);

// The generated functions above in one language, with a comment header that restates the
// contract. Throws InvalidArgument for a layout with slices < 1, delta ≤ 0 or sizes < 1.
std::string MeasuredBrdfShaderCode(ShaderLanguage language, const ShaderLutLayout& layout);

enum class GlslVersion { kEs300, k450 };
// A complete GLSL file: "#version 300 es" or "#version 450", then the kGlsl body. The body
// starts with `precision highp float; precision highp sampler3D;` (required by GLSL ES for
// sampler3D, accepted and ignored by desktop GLSL). To paste it into a shader that has its own
// #version line, drop the first line.
std::string MeasuredBrdfGlslFile(GlslVersion version, const ShaderLutLayout& layout);

// The decoder of the compact form (compact_lut.h, docs/formats/compact.md) as a complete GLSL ES
// 3.00 file: the same template with its fetch replaced by MeasuredBrdfCompactFetch(uvw), which
// reads the uniforms it declares (no sampler parameter: MeasuredBrdf(n, l, v),
// MeasuredBrdfTangent(cell, l, v), ... take no `lut`):
//   measured_brdf_compact_grid   sampler2D RGB16F, width the largest column count, one texel row
//                                per kept row, slices stacked (slice k from row row0_k)
//   measured_brdf_compact_rows   sampler2D RGBA32F, 181 × K: (row map m(θd = x°), row0_k,
//                                rows_k − 1, cols_k − 1)
//   measured_brdf_compact_cols   sampler2D R32F, 361 × K: column map m(φd = x°), mirrored
//                                lists folded
//   measured_brdf_compact_scale, measured_brdf_compact_epsilon   S and ε of the file
// All read with texelFetch (no filtering, any sampler state), exactly as CompactLut::SampleAngles.
std::string CompactBrdfGlslFile(const ShaderLutLayout& layout);

}  // namespace brdf::exporter
