// The GLSL snippet that ships with every LUT compiles with a real compiler, glslangValidator
// (Debian glslang-tools), as GLSL ES 3.00 and as GLSL 4.50, inside a minimal fragment shader.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "brdf/exporter/metadata.h"
#include "test_support.h"

namespace brdf::exporter {
namespace {

int Compile(const std::string& version_line, const std::string& snippet,
            const brdf::test::ScopedTempDir& dir, const std::string& name) {
  const std::string path = (dir / (name + ".frag")).string();
  std::ofstream(path)
      << version_line << "\n"
      << "precision highp float;\n"
      << snippet << "uniform sampler3D lut;\n"
      << "out vec4 color;\n"
      << "void main() { color = vec4(MeasuredBrdf(lut, vec3(0.0, 0.0, 1.0), normalize(vec3(0.3, "
         "0.0, 1.0)), normalize(vec3(-0.3, 0.1, 1.0))), 1.0); }\n";
  const int status = std::system(("glslangValidator " + path + " > " + path + ".log 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(GlslSnippet, CompilesAsGlslEs300AndGlsl450) {
  const brdf::test::ScopedTempDir dir("glsl");
  const std::string snippet = ShaderSnippetGlsl({0, 20, 40, 60});
  for (const auto& [version, name] :
       {std::pair<std::string, std::string>{"#version 300 es", "es300"},
        std::pair<std::string, std::string>{"#version 450", "gl450"}}) {
    const int code = Compile(version, snippet, dir, name);
    std::ifstream log((dir / (name + ".frag.log")).string());
    const std::string text((std::istreambuf_iterator<char>(log)), {});
    EXPECT_EQ(code, 0) << version << ":\n" << text;
  }
}

}  // namespace
}  // namespace brdf::exporter
