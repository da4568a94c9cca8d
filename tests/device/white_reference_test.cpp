// The Spectralon RGB triple in the code is the documented reduction of the real certificate
// file: recomputed here from ../shared/brdf-data/spectralon/Spectralon_Num4.txt.
#include "brdf/device/white_reference.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "brdf/core/models.h"
#include "test_support.h"

namespace brdf::device {
namespace {

struct BandMean {
  double reflectance = 0, uncertainty = 0;
  int rows = 0;
};

// Mean of the certificate rows with lo ≤ λ < hi (nm); rows are "nm reflectance uncertainty".
BandMean MeanOverBand(const std::string& path, double lo, double hi) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  BandMean m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double nm = 0, r = 0, u = 0;
    if (!(fields >> nm >> r >> u)) continue;
    if (nm >= lo && nm < hi) {
      m.reflectance += r;
      m.uncertainty += u;
      ++m.rows;
    }
  }
  if (m.rows > 0) {
    m.reflectance /= m.rows;
    m.uncertainty /= m.rows;
  }
  return m;
}

TEST(SpectralonWhiteReference, IsTheBandMeanOfTheCertificate) {
  const std::string path = brdf::test::DataPath("spectralon/Spectralon_Num4.txt");
  const double bands[3][2] = {{600, 700}, {500, 600}, {400, 500}};  // R, G, B
  const WhiteReference& w = SpectralonWhiteReference();
  for (int c = 0; c < 3; ++c) {
    const BandMean m = MeanOverBand(path, bands[c][0], bands[c][1]);
    EXPECT_EQ(m.rows, 100) << "channel " << c;
    // The table holds the means to 6 decimals.
    EXPECT_NEAR(w.rho[c], m.reflectance, 5e-7) << "channel " << c;
    EXPECT_NEAR(w.rho_uncertainty[c], m.uncertainty, 5e-7) << "channel " << c;
  }
}

TEST(SpectralonWhiteReference, LibraryWhiteReferenceMaterialCarriesTheSameReflectance) {
  const Material m = LoadMaterialFile(std::string(BRDF_SOURCE_DIR) +
                                      "/data-samples/materials/white_reference.json");
  EXPECT_EQ(m.model, Model::kLambert);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(m.Parameter(0)[c], SpectralonWhiteReference().rho[c]);
}

}  // namespace
}  // namespace brdf::device
