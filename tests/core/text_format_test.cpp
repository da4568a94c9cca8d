// The shared number spellings (brdf/core/text_format.h) against the C standard's definition of
// the printf conversions they name, and the round trip ExactNumberText promises.
#include "brdf/core/text_format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "brdf/core/virtual_capture.h"

namespace brdf {
namespace {

TEST(TextFormat, Hex32IsZeroPaddedLowercaseWithPrefix) {
  EXPECT_EQ(Hex32Text(0), "0x00000000");
  EXPECT_EQ(Hex32Text(0x0BADF00Du), "0x0badf00d");
  EXPECT_EQ(Hex32Text(0xFFFFFFFFu), "0xffffffff");
}

TEST(TextFormat, ShortNumberHasSixSignificantDigits) {
  EXPECT_EQ(ShortNumberText(20), "20");
  EXPECT_EQ(ShortNumberText(0.25), "0.25");
  EXPECT_EQ(ShortNumberText(-0.0), "-0");
  EXPECT_EQ(ShortNumberText(1e-5), "1e-05");             // exponent below -4: scientific
  EXPECT_EQ(ShortNumberText(123456789), "1.23457e+08");  // exponent ≥ precision
  EXPECT_EQ(ShortNumberText(12.3456789), "12.3457");
}

TEST(TextFormat, ExactNumberReadsBackBitForBit) {
  EXPECT_EQ(ExactNumberText(0.1), "0.10000000000000001");
  EXPECT_EQ(ExactNumberText(2), "2");
  for (double v : {0.1, 1.0 / 3.0, 12.3456789, 5e-324, std::numeric_limits<double>::max(), -7.25})
    EXPECT_EQ(std::strtod(ExactNumberText(v).c_str(), nullptr), v) << ExactNumberText(v);
}

// The planned θin list of a capture: "%g" where that reads back, else the exact spelling.
TEST(TextFormat, PlannedThetaInListReadsBackEveryAngle) {
  EXPECT_EQ(EncodeThetaInList({0, 20, 40, 60}), "0,20,40,60");
  EXPECT_EQ(EncodeThetaInList({12.5, 0.1}), "12.5,0.1");
  EXPECT_EQ(EncodeThetaInList({12.3456789}), "12.345678899999999");
  Metadata m;
  m.extra[kPlannedThetaInKey] = EncodeThetaInList({0, 12.3456789, 89.999999999});
  const auto planned = PlannedThetaInDeg(m, "x.bpc");
  ASSERT_TRUE(planned.has_value());
  EXPECT_EQ(*planned, (std::vector<double>{0, 12.3456789, 89.999999999}));
}

}  // namespace
}  // namespace brdf
