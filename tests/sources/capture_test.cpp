// The damaged-capture rule in-process (brdf/sources/capture.h): what LoadCaptureForLut accepts,
// warns about and refuses, and which remedy a refusal carries. The damage is made by hand in the
// file's bytes at chunk offsets read from the file itself (docs/formats/bpc.md: a 12-byte
// preamble, then chunks with a 24-byte header holding the payload size at +8).
#include "brdf/sources/capture.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "tools/tool_test_util.h"

namespace brdf::sources {
namespace {

namespace fs = std::filesystem;
using tooltest::BpcChunks;
using tooltest::ChunkSpan;
using tooltest::ReadAll;
using tooltest::WriteText;

class CaptureRule : public tooltest::ToolTest {
 protected:
  // A finished four-slice capture (θin 0, 20, 40, 60°) and its chunks.
  fs::path WriteReference() {
    const fs::path p = dir_ / "ref.bpc";
    WriteBpc(p.string(), tooltest::CaptureOf(tooltest::Lambertian(), {0, 20, 40, 60}, 60, 10, 20));
    return p;
  }
};

TEST_F(CaptureRule, AnIntactCaptureLoadsAsWritten) {
  const fs::path ref = WriteReference();
  std::vector<std::string> warnings;
  const Measurement m = LoadCaptureForLut(ref.string(), &warnings);
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(m.slices.size(), 4u);
  // Lambertian ρ/π for the red channel, stored as float.
  EXPECT_EQ(m.slices[3].samples[5].rgb[0], static_cast<float>(0.5 / tooltest::kPi));
}

TEST_F(CaptureRule, AMissingEndChunkIsAWarningWhenEveryPlannedSliceIsThere) {
  const fs::path ref = WriteReference();
  const std::vector<ChunkSpan> chunks = BpcChunks(ref);
  ASSERT_GE(chunks.size(), 6u);  // header, four slices, end
  std::string b = ReadAll(ref);
  b.resize(chunks.back().offset);  // the end chunk gone
  const fs::path cut = dir_ / "unfinished.bpc";
  WriteText(cut, b);
  std::vector<std::string> warnings;
  const Measurement m = LoadCaptureForLut(cut.string(), &warnings);
  EXPECT_EQ(m.slices.size(), 4u);
  ASSERT_FALSE(warnings.empty());
  EXPECT_EQ(warnings[0].rfind(cut.string() + ": warning: ", 0), 0u) << warnings[0];
}

TEST_F(CaptureRule, ACutInsideTheLastSliceIsRefusedWithTheResumeRemedy) {
  const fs::path ref = WriteReference();
  const std::vector<ChunkSpan> chunks = BpcChunks(ref);
  const ChunkSpan& last_slice = chunks[chunks.size() - 2];
  std::string b = ReadAll(ref);
  b.resize(last_slice.offset + last_slice.size / 2);
  const fs::path cut = dir_ / "cut.bpc";
  WriteText(cut, b);
  try {
    LoadCaptureForLut(cut.string(), nullptr);
    ADD_FAILURE() << "a capture cut inside a slice was accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), cut.string());
    EXPECT_EQ(e.remedy().kind, RemedyKind::kResumeCapture) << e.what();
    // The intact prefix ends where the cut slice begins.
    EXPECT_EQ(e.remedy().valid_bytes, last_slice.offset) << e.what();
    EXPECT_EQ(e.remedy().theta_in_deg, (std::vector<double>{60})) << e.what();
  }
}

TEST_F(CaptureRule, DamageFollowedByIntactSlicesIsRefusedWithTheRepairRemedy) {
  const fs::path ref = WriteReference();
  const std::vector<ChunkSpan> chunks = BpcChunks(ref);
  std::string b = ReadAll(ref);
  const ChunkSpan& second_slice = chunks[2];
  b[second_slice.offset + 24 + 10] ^= 0x01;  // a payload byte: its CRC-32 no longer matches
  const fs::path flipped = dir_ / "flipped.bpc";
  WriteText(flipped, b);
  try {
    LoadCaptureForLut(flipped.string(), nullptr);
    ADD_FAILURE() << "a corrupt slice was accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.remedy().kind, RemedyKind::kRepairCapture) << e.what();
    EXPECT_NE(std::string(e.what()).find("byte " + std::to_string(second_slice.offset)),
              std::string::npos)
        << e.what();
  }
}

TEST_F(CaptureRule, RepairRefusesAnExistingOutputWithTheOverwriteRemedy) {
  const fs::path ref = WriteReference();
  const std::vector<ChunkSpan> chunks = BpcChunks(ref);
  std::string b = ReadAll(ref);
  b.resize(chunks.back().offset + 3);
  const fs::path cut = dir_ / "cut.bpc";
  WriteText(cut, b);
  WriteText(dir_ / "taken.bpc", "mine");
  try {
    RepairCapture(cut.string(), (dir_ / "taken.bpc").string());
    ADD_FAILURE() << "an existing output was replaced";
  } catch (const Error& e) {
    EXPECT_EQ(e.remedy().kind, RemedyKind::kForceOverwrite) << e.what();
    EXPECT_EQ(e.remedy().file, (dir_ / "taken.bpc").string());
  }
  EXPECT_EQ(ReadAll(dir_ / "taken.bpc"), "mine");
  const RepairReport r = RepairCapture(cut.string(), (dir_ / "taken.bpc").string(), true);
  EXPECT_EQ(r.kept_theta_in_deg, (std::vector<double>{0, 20, 40, 60}));
  EXPECT_NE(ReadAll(dir_ / "taken.bpc"), "mine");
}

}  // namespace
}  // namespace brdf::sources
