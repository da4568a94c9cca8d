// Command-line mistakes give one line on stderr, like every other error, naming the option and
// the value as typed, and exit code 2. The old messages were CLI11's: a second "Run ... --help"
// line, and for --jobs 0 a range printed as two 309-digit numbers.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

class CliErrors : public ToolTest {};

TEST_F(CliErrors, EveryParseErrorIsOneShortLineNamingOptionAndValue) {
  struct Case {
    std::string args;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases = {
      {"convert in --out o --jobs 0", {"brdf: convert: --jobs", "whole number >= 1", "'0'"}},
      {"convert in --out o --jobs abc", {"--jobs", "'abc'"}},
      {"convert in --out o --jobs 2.5", {"--jobs", "'2.5'"}},
      {"atlas in --out o --jobs -1", {"brdf: atlas: --jobs", "'-1'"}},
      {"convert in --out o --exr-compression foo", {"--exr-compression", "foo"}},
      {"eval", {"brdf: eval: ", "file", "brdf eval --help"}},
      // brdf fit: --starts and --jobs at least 1, --max-theta-out an angle in (0, 90].
      {"fit in --out o.json --starts 0", {"brdf: fit: --starts", "whole number >= 1", "'0'"}},
      {"fit in --out o.json --starts x", {"--starts", "'x'"}},
      {"fit in --out o.json --jobs 1.5", {"--jobs", "'1.5'"}},
      {"fit in --out o.json --max-theta-out 0", {"--max-theta-out", "(0, 90] degrees", "'0'"}},
      {"fit in --out o.json --max-theta-out 95", {"--max-theta-out", "'95'"}},
      {"fit in --out o.json --max-theta-out abc", {"--max-theta-out", "'abc'"}},
      {"fit in --out o.json --loss l2", {"--loss", "l2", "ngan"}},
      {"fit in --out o.json --model phong", {"--model", "phong", "blinn-phong"}},
      {"nonsense", {"brdf"}},
      {"eval x.json --in 30,0 --out 30,180 --bogus 1", {"brdf: eval: ", "'--bogus 1'"}},
      {"fit x.json --out y.json --robust=3",
       {"brdf: fit: --robust is a switch and takes no value"}},
      // An option typed without its value, the next option taken for it by CLI11 before.
      {"fit x.json --model --out y.json",
       {"brdf: fit: --model needs a value", "the option '--out'"}},
      {"preview x.json --env --out y.png", {"brdf: preview: --env needs a value", "'--out'"}},
      {"preview x.json --size --help", {"--size needs a value", "'--help'"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const ToolRun r = Run(c.args);
    EXPECT_EQ(r.exit_code, 2);
    const std::vector<std::string> lines = r.ErrLines();
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_LT(lines[0].size(), 200u) << lines[0];
    for (const std::string& e : c.expected)
      EXPECT_NE(lines[0].find(e), std::string::npos) << lines[0] << " lacks " << e;
    EXPECT_EQ(lines[0].find("Value "), std::string::npos) << "CLI11's range wording";
  }
}

TEST_F(CliErrors, ConvertAndAtlasShareOneExrDefaultAndHelpText) {
  const std::string convert = Run("convert --help").out, atlas = Run("atlas --help").out;
  const auto line = [](const std::string& help) {
    const std::size_t at = help.find("--exr-compression");
    const std::size_t second = help.find('\n', help.find('\n', at) + 1);
    return help.substr(at, second - at);  // the option line and its description
  };
  ASSERT_NE(convert.find("--exr-compression"), std::string::npos);
  EXPECT_EQ(line(convert), line(atlas));
  EXPECT_NE(line(convert).find("=none"), std::string::npos) << line(convert);
}

}  // namespace
}  // namespace brdf::tooltest
