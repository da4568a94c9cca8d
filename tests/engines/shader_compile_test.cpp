// Every shader the engine hand-off ships, compiled by a real compiler: Khronos'
// glslangValidator (Debian glslang-tools) as GLSL ES 3.00 and GLSL 4.50, and through its HLSL
// front end (-D) with minimal stand-ins for the Unity and Unreal macros, as the engines would
// compile them. The Godot shader is translated to GLSL ES (its language is a GLSL ES 3.0
// dialect) by replacing only what Godot adds: shader_type, uniform hints and built-ins.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <tuple>

#include <nlohmann/json.hpp>

#include "brdf/engines/engine_export.h"
#include "brdf/exporter/lut_export.h"
#include "brdf/exporter/shader_code.h"
#include "brdf/exporter/sidecar.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;
using exporter::ShaderLutLayout;

class ShaderCompile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "brdf_shader_compile_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string Write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  static std::string Read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // Runs glslangValidator with `args`; returns its exit code, output in `log`.
  int Glslang(const std::string& args, std::string* log) {
    const std::string cmd = std::string(BRDF_GLSLANG) + " " + args + " 2>&1";
    std::FILE* pipe = ::popen(cmd.c_str(), "r");
    if (pipe == nullptr) return -1;
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) log->append(buf, n);
    const int status = ::pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  void ExpectCompiles(const std::string& args, const std::string& what) {
    std::string log;
    EXPECT_EQ(Glslang(args, &log), 0) << what << ":\n" << log;
  }
  // A LUT converted with every engine, as `brdf convert --engine all` writes it.
  // bc6h: the BC6H form (--compress bc6h), whose shaders address 364 x 184 slices.
  fs::path ExportAll(const std::vector<double>& theta_in_deg, bool bc6h = false) {
    Lut lut;
    lut.Resize(theta_in_deg.size());
    lut.theta_in_deg = theta_in_deg;
    for (std::size_t i = 0; i < lut.texels.size(); ++i) lut.texels[i] = 0.01f * (i % 97);
    exporter::TextureMetadata meta;
    meta.name = "m";
    meta.source = "test";
    const fs::path out = dir_ / ("out" + std::to_string(theta_in_deg.size()) + (bc6h ? "b" : ""));
    fs::create_directories(out);
    exporter::LutExportOptions options;
    if (bc6h) options.compression = exporter::LutCompression::kBc6h;
    engines::ExportLutWithEngines(out.string(), lut, meta, options, engines::ParseEngines("all"));
    return out;
  }
  // The file name of the .hlsl include in the export's unity folder ("" when there is none).
  static std::string UnityInclude(const fs::path& out) {
    std::string include;
    for (const auto& e : fs::directory_iterator(out / "unity"))
      if (e.path().extension() == ".hlsl") include = e.path().filename().string();
    return include;
  }
  fs::path dir_;
};

const std::vector<ShaderLutLayout> kLayouts = {
    {0, 20, 4, 361, 181},   // the reference instrument
    {10, 15, 3, 361, 181},  // another θin list
    {0, 1, 1, 361, 181},    // a single slice
    {0, 20, 4, 1083, 362},  // an atlas of 3 × 2 cells
    {0, 20, 4, 364, 184},   // BC6H: slices padded to whole blocks
    {0, 10, 9, 364, 184},   // BC6H of the default 9-slice fill
};

TEST_F(ShaderCompile, GlslFilesCompileAsGlslEs300And450) {
  for (const ShaderLutLayout& l : kLayouts) {
    const std::string tag = std::to_string(l.slices) + "_" + std::to_string(l.texture_width);
    ExpectCompiles("-S frag " + Write("es_" + tag + ".frag", exporter::MeasuredBrdfGlslFile(
                                                                 exporter::GlslVersion::kEs300, l)),
                   "GLSL ES 3.00 " + tag);
    ExpectCompiles("-S frag " + Write("gl_" + tag + ".frag", exporter::MeasuredBrdfGlslFile(
                                                                 exporter::GlslVersion::k450, l)),
                   "GLSL 4.50 " + tag);
  }
}

TEST_F(ShaderCompile, Glsl450LinksToSpirvWithAMain) {
  const std::string body = exporter::MeasuredBrdfGlslFile(exporter::GlslVersion::k450, kLayouts[0]);
  const std::string main_text =
      "layout(binding = 0) uniform sampler3D brdf_lut;\n"
      "layout(location = 0) in vec3 n_in;\nlayout(location = 1) in vec3 l_in;\n"
      "layout(location = 2) in vec3 v_in;\nlayout(location = 0) out vec4 color;\n"
      "void main() { color = vec4(MeasuredBrdf(brdf_lut, normalize(n_in), normalize(l_in), "
      "normalize(v_in)) + MeasuredBrdfTangent(brdf_lut, vec2(0.0), l_in, v_in), 1.0); }\n";
  ExpectCompiles(
      "-V -S frag -o " + (dir_ / "a.spv").string() + " " + Write("a.frag", body + main_text),
      "GLSL 4.50 to SPIR-V");
}

// docs/design.md §5: the sidecar's "glsl" snippet compiles as it ships (ES 3.00 needs a
// precision for sampler3D, which the earlier snippet lacked) and equals the shipped files' body.
TEST_F(ShaderCompile, SidecarSnippetIsTheShippedGlslAndCompiles) {
  exporter::PackedVolume v{361, 181, 4, std::vector<std::uint32_t>(361 * 181 * 4, 0)};
  exporter::TextureMetadata meta;
  meta.name = "m";
  const auto j = nlohmann::json::parse(exporter::SidecarJson(v, {0, 20, 40, 60}, meta));
  const std::string snippet = j["texel_convention"]["glsl"];
  const std::string file =
      exporter::MeasuredBrdfGlslFile(exporter::GlslVersion::kEs300, kLayouts[0]);
  EXPECT_EQ("#version 300 es\n" + snippet, file);
  ExpectCompiles("-S frag " + Write("sidecar_es.frag", "#version 300 es\n" + snippet),
                 "sidecar snippet as GLSL ES 3.00");
  ExpectCompiles("-S frag " + Write("sidecar_gl.frag", "#version 450\n" + snippet),
                 "sidecar snippet as GLSL 4.50");
}

TEST_F(ShaderCompile, ShippedWebGlslFilesCompile) {
  const fs::path out = ExportAll({0, 20, 40, 60});
  ExpectCompiles("-S frag " + (out / "web/MeasuredBrdf.es300.glsl").string(), "web es300 file");
  ExpectCompiles("-S frag " + (out / "web/MeasuredBrdf.450.glsl").string(), "web 450 file");
  ExpectCompiles("-S frag " + (out / "web/MeasuredBrdf.compact.es300.glsl").string(),
                 "web compact decoder (GLSL ES 3.00)");
  const fs::path bc6h = ExportAll({0, 20, 40, 60}, true);
  ExpectCompiles("-S frag " + (bc6h / "web/MeasuredBrdf_bc6h.es300.glsl").string(),
                 "BC6H web es300 file");
  ExpectCompiles("-S frag " + (bc6h / "web/MeasuredBrdf_bc6h.450.glsl").string(),
                 "BC6H web 450 file");
  const std::string bc6h_js = Read(bc6h / "web/measured_brdf_bc6h.js");
  // The module's lookup addresses the padded texture WebGL creates.
  EXPECT_NE(bc6h_js.find("MEASURED_BRDF_TEXELS_U = 364.0;"), std::string::npos);
  EXPECT_NE(bc6h_js.find("MEASURED_BRDF_TEXELS_V = 184.0;"), std::string::npos);
  EXPECT_NE(bc6h_js.find("export const TEXTURE_SIZE = [364, 184, 4];"), std::string::npos);
  // The ES module embeds the same GLSL body.
  const std::string js = Read(out / "web/measured_brdf.js");
  const std::string body =
      exporter::MeasuredBrdfShaderCode(exporter::ShaderLanguage::kGlsl, kLayouts[0]);
  EXPECT_NE(js.find("export const MEASURED_BRDF_GLSL = `" + body + "`;"), std::string::npos);
}

// Stand-ins for what Unity's Core RP (Texture.hlsl) and the built-in pipeline's
// UnityPBSLighting.cginc provide to the include.
constexpr const char* kUnityStandIns = R"(
struct UnityTexture3D { Texture3D tex; SamplerState samplerstate; };
#define UNITY_DECLARE_TEX3D(name) Texture3D name; SamplerState sampler##name
struct UnityLight { half3 color; half3 dir; };
struct UnityIndirect { half3 diffuse; half3 specular; };
struct UnityGI { UnityLight light; UnityIndirect indirect; };
struct UnityGIInput { UnityLight light; float3 worldPos; half3 worldViewDir; half atten; };
struct SurfaceOutput { half3 Albedo; half3 Normal; half3 Emission; half Specular; half Gloss; half Alpha; };
UnityGI UnityGlobalIllumination(UnityGIInput data, half occlusion, half3 normal) {
  UnityGI gi; gi.light = data.light; gi.indirect.diffuse = 0; gi.indirect.specular = 0; return gi;
}
)";

// Stand-ins for the probe functions URP (Lighting.hlsl) and HDRP (Core's AmbientProbe.hlsl,
// ShaderVariablesFunctions.hlsl) give the image-based-lighting functions, with their signatures.
constexpr const char* kUrpStandIns = R"(
#define UNIVERSAL_LIGHTING_INCLUDED
struct UnityTexture2D { Texture2D tex; SamplerState samplerstate; };
half3 SampleSH(half3 normalWS) { return normalWS * 0.5 + 0.5; }
half3 GlossyEnvironmentReflection(half3 reflectVector, half perceptualRoughness, half occlusion) {
  return reflectVector * perceptualRoughness * occlusion;
}
)";
constexpr const char* kHdrpStandIns = R"(
#define __AMBIENTPROBE_HLSL__
struct UnityTexture2D { Texture2D tex; SamplerState samplerstate; };
float3 EvaluateAmbientProbe(float3 normalWS) { return normalWS * 0.5 + 0.5; }
float PerceptualRoughnessToMipmapLevel(float perceptualRoughness) { return perceptualRoughness * 6.0; }
TextureCube _SkyTexture; SamplerState s_trilinear_clamp_sampler;
float4 SampleSkyTexture(float3 texCoord, float lod, int sliceIndex) {
  return _SkyTexture.SampleLevel(s_trilinear_clamp_sampler, texCoord, lod + sliceIndex);
}
)";

TEST_F(ShaderCompile, UnityIblFunctionsCompileForUrpAndHdrp) {
  for (const std::vector<double>& thetas :
       {std::vector<double>{0, 20, 40, 60}, {0, 10, 20, 30, 40, 50, 60, 70, 80}}) {
    for (const bool bc6h : {false, true}) {  // RGB9E5 and the BC6H form (364 x 184)
      SCOPED_TRACE(bc6h ? "BC6H" : "RGB9E5");
      const fs::path out = ExportAll(thetas, bc6h);
      const std::string include = UnityInclude(out);
      ASSERT_FALSE(include.empty());
      for (const auto& [pipeline, stand_ins, function] :
           {std::tuple{"urp", kUrpStandIns, "MeasuredBrdfIbl_float"},
            std::tuple{"hdrp", kHdrpStandIns, "MeasuredBrdfIbl_float"}}) {
        const std::string harness = std::string(kUnityStandIns) + stand_ins + "#include \"" +
                                    include + "\"\n" + R"(
Texture2D g_pack; SamplerState g_pack_sampler;
float4 main(float3 n : TEXCOORD0, float3 v : TEXCOORD1) : SV_Target {
  UnityTexture2D t; t.tex = g_pack; t.samplerstate = g_pack_sampler;
  float3 o; )" + function + R"((t, 0.5, float3(0.3, 0.2, 0.1), float3(0.01, 0.02, 0.03),
                                  float3(-0.01, 0.0, 0.01), 0.4, n, v, o);
  return float4(o, 1.0);
}
)";
        const std::string file = (out / "unity" / (std::string(pipeline) + ".hlsl")).string();
        std::ofstream(file) << harness;
        ExpectCompiles("-D -V -e main -S frag -o " + (dir_ / "ibl.spv").string() + " " + file,
                       std::string("Unity ") + pipeline + " IBL in " + include);
      }
    }
  }
}

TEST_F(ShaderCompile, UnityIncludeCompilesForShaderGraphAndBuiltInPipeline) {
  for (const std::vector<double>& thetas : {std::vector<double>{0, 20, 40, 60}, {10, 25, 40}}) {
    for (const bool bc6h : {false, true}) {  // RGB9E5 and the BC6H form (364 x 184)
      SCOPED_TRACE(bc6h ? "BC6H" : "RGB9E5");
      const fs::path out = ExportAll(thetas, bc6h);
      const std::string include = UnityInclude(out);
      ASSERT_FALSE(include.empty());
      const std::string harness = std::string(kUnityStandIns) +
                                  "#define MEASURED_BRDF_BUILTIN_LIGHTING\n#include \"" + include +
                                  "\"\n" + R"(
Texture3D g_lut; SamplerState g_lut_sampler;
float4 main(float3 n : TEXCOORD0, float3 l : TEXCOORD1, float3 v : TEXCOORD2) : SV_Target {
  UnityTexture3D t; t.tex = g_lut; t.samplerstate = g_lut_sampler;
  float3 a; MeasuredBrdf_float(t, n, l, v, a);
  half3 b; MeasuredBrdf_half(t, (half3)n, (half3)l, (half3)v, b);
  float3 c; MeasuredBrdfRadiance_float(t, n, l, v, float3(1, 1, 1), c);
  half3 d; MeasuredBrdfRadiance_half(t, (half3)n, (half3)l, (half3)v, half3(1, 1, 1), d);
  SurfaceOutput s; s.Albedo = 1; s.Normal = (half3)n; s.Emission = 0; s.Specular = 0; s.Gloss = 0; s.Alpha = 1;
  UnityGIInput gin; gin.light.color = 1; gin.light.dir = (half3)l; gin.worldPos = 0; gin.worldViewDir = (half3)v; gin.atten = 1;
  UnityGI gi; gi.light.color = 0; gi.light.dir = 0; gi.indirect.diffuse = 0; gi.indirect.specular = 0;
  LightingMeasuredBrdf_GI(s, gin, gi);
  half4 e = LightingMeasuredBrdf(s, (half3)v, gi);
  return float4(a + b + c + d + e.rgb, 1.0);
}
)";
      const std::string file = (out / "unity" / "harness.hlsl").string();
      std::ofstream(file) << harness;
      ExpectCompiles("-D -V -e main -S frag -o " + (dir_ / "u.spv").string() + " " + file,
                     "Unity include " + include);
    }
  }
}

TEST_F(ShaderCompile, UnrealUshCompilesInACustomNodeAsTheCommentSays) {
  for (const bool bc6h : {false, true}) {  // RGB9E5 and the BC6H form (364 x 184)
    SCOPED_TRACE(bc6h ? "BC6H" : "RGB9E5");
    const fs::path out = ExportAll({0, 20, 40, 60}, bc6h);
    const std::string ush =
        Read(out / (bc6h ? "unreal/MeasuredBrdf_bc6h.ush" : "unreal/MeasuredBrdf.ush"));
    // The Custom node's code line, as the include tells the artist to type it.
    std::smatch m;
    ASSERT_TRUE(std::regex_search(ush, m, std::regex(R"(// Code:\s+(return [^\n]+;))"))) << ush;
    // Unreal passes a TextureObject input "Lut" as Texture3D Lut and SamplerState LutSampler and
    // wraps the code in a function (MaterialTemplate.ush: CustomExpressionN).
    const std::string harness = "#include \"" +
                                std::string(bc6h ? "MeasuredBrdf_bc6h.ush" : "MeasuredBrdf.ush") +
                                "\"\n"
                                "float3 CustomExpression0(Texture3D Lut, SamplerState LutSampler, "
                                "float3 N, float3 L, float3 "
                                "V) {\n  " +
                                m[1].str() + "\n}\n" + R"(
Texture3D Material_Texture3D_0; SamplerState Material_Texture3D_0Sampler;
float4 main(float3 n : TEXCOORD0, float3 l : TEXCOORD1, float3 v : TEXCOORD2) : SV_Target {
  return float4(CustomExpression0(Material_Texture3D_0, Material_Texture3D_0Sampler, n, l, v), 1.0);
}
)";
    const std::string file = (out / "unreal" / "harness.hlsl").string();
    std::ofstream(file) << harness;
    ExpectCompiles("-D -V -e main -S frag -o " + (dir_ / "ue.spv").string() + " " + file,
                   "Unreal Custom node");
  }
}

TEST_F(ShaderCompile, UnrealIblCustomNodeCompilesAsTheCommentSays) {
  for (const bool bc6h : {false, true}) {  // RGB9E5 and the BC6H form (364 x 184)
    SCOPED_TRACE(bc6h ? "BC6H" : "RGB9E5");
    const fs::path out = ExportAll({0, 10, 20, 30, 40, 50, 60, 70, 80}, bc6h);
    std::string ush;
    for (const auto& e : fs::directory_iterator(out / "unreal"))
      if (e.path().extension() == ".ush") ush = e.path().filename().string();
    ASSERT_FALSE(ush.empty());
    const std::string text = Read(out / "unreal" / ush);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        text, m, std::regex(R"(// Code:\s+(return MeasuredBrdfIblUnreal[^\n]+;))")))
        << text;
    // Stand-ins for what Unreal's base pass gives a material (ReflectionEnvironmentShared.ush,
    // the View uniform buffer), and the Custom node's Additional Define.
    const std::string harness =
        std::string(R"(
struct FViewStandIn { float4 SkyLightColor; };
static const FViewStandIn View = { float4(1, 1, 1, 1) };
TextureCube SkyCube; SamplerState SkyCubeSampler;
float3 GetSkySHDiffuse(float3 Normal) { return Normal * 0.5 + 0.5; }
float3 GetSkyLightReflection(float3 ReflectionVector, float Roughness, out float OutSkyAverageBrightness) {
  OutSkyAverageBrightness = 1.0;
  return SkyCube.SampleLevel(SkyCubeSampler, ReflectionVector, Roughness * 6.0).rgb;
}
#define MEASURED_BRDF_UNREAL_SKY 1
#include ")") +
        ush + "\"\n" +
        "float3 CustomExpression1(Texture2D IblPack, SamplerState IblPackSampler, float IblRow, "
        "float3 IblDiffuse0, float3 IblDiffuse1, float3 IblDiffuse2, float IblBroadAlpha, float3 "
        "N, "
        "float3 V) {\n  " +
        m[1].str() + "\n}\n" + R"(
Texture2D Material_Texture2D_0; SamplerState Material_Texture2D_0Sampler;
float4 main(float3 n : TEXCOORD0, float3 v : TEXCOORD1) : SV_Target {
  return float4(CustomExpression1(Material_Texture2D_0, Material_Texture2D_0Sampler, 0.5,
                                  float3(0.3, 0.2, 0.1), float3(0.01, 0.02, 0.03),
                                  float3(-0.01, 0.0, 0.01), 0.4, n, v), 1.0);
}
)";
    const std::string file = (out / "unreal" / "ibl_harness.hlsl").string();
    std::ofstream(file) << harness;
    ExpectCompiles("-D -V -e main -S frag -o " + (dir_ / "ue_ibl.spv").string() + " " + file,
                   "Unreal IBL Custom node");
  }
}

// Godot's shading language is GLSL ES 3.0 plus a header, uniform hints and built-ins; strip
// exactly those and the rest must be valid GLSL ES 3.00.
TEST_F(ShaderCompile, GodotShaderIsValidOnceGodotsAdditionsAreReplaced) {
  for (const bool bc6h : {false, true}) {  // RGB9E5 and the BC6H form (364 x 184)
    SCOPED_TRACE(bc6h ? "BC6H" : "RGB9E5");
    const fs::path out = ExportAll({0, 20, 40, 60}, bc6h);
    std::string src =
        Read(out / (bc6h ? "godot/measured_brdf_bc6h.gdshader" : "godot/measured_brdf.gdshader"));
    ASSERT_NE(src.find("shader_type spatial;"), std::string::npos);
    ASSERT_NE(src.find("void light()"), std::string::npos);
    src = std::regex_replace(src, std::regex(R"(shader_type spatial;)"), "");
    src = std::regex_replace(src, std::regex(R"(render_mode [^;]+;)"), "");
    src = std::regex_replace(
        src, std::regex(R"(uniform (sampler3D|sampler2D|samplerCube) (\w+) : [^;]+;)"),
        "uniform highp $1 $2;");
    // GLSL ES has no uniform initialisers; Godot's are defaults the material starts from.
    src = std::regex_replace(src, std::regex(R"(uniform (float|vec3) (\w+) = [^;]+;)"),
                             "uniform $1 $2;");
    src = std::regex_replace(src, std::regex(R"(void fragment\(\))"), "void godot_fragment()");
    src = std::regex_replace(src, std::regex(R"(void light\(\))"), "void godot_light()");
    const std::string builtins =
        "#version 300 es\nprecision highp float;\n"
        "vec3 ALBEDO; float METALLIC; float SPECULAR; float ROUGHNESS;\n"
        "vec3 NORMAL; vec3 LIGHT; vec3 VIEW; vec3 LIGHT_COLOR; float ATTENUATION;\n"
        "vec3 DIFFUSE_LIGHT; vec3 SPECULAR_LIGHT; vec3 EMISSION; mat4 INV_VIEW_MATRIX;\n";
    const std::string tail =
        "out vec4 color;\nvoid main() { godot_fragment(); godot_light(); color = "
        "vec4(DIFFUSE_LIGHT "
        "+ "
        "EMISSION, 1.0); }\n";
    ExpectCompiles("-S frag " + Write("godot.frag", builtins + src + tail),
                   "Godot shader as GLSL ES");
  }
}

}  // namespace
}  // namespace brdf
