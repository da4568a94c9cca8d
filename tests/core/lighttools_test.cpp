#include "brdf/core/lighttools.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"
#include "brdf/core/models.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) { return brdf::test::NewTempDir("lighttools-" + name); }

Material GgxMaterial() {
  Material mat;
  mat.model = Model::kGgx;
  mat.SetParameter(0, {0.30, 0.12, 0.05});
  mat.SetParameter(1, {0.04, 0.04, 0.04});
  mat.SetParameter(2, {0.25, 0.25, 0.25});
  return mat;
}

// A LightTools table of `mat` written the way a LightTools file describes it: POI is the
// light's azimuth in the sample frame, ScatterRadial/Azimuth the outgoing polar/azimuth angle
// in the same frame. So the value at (radial θ, azimuth φ) is f(l at (θin, POI), v at (θ, φ)).
LightToolsBsdf AnalyticTable(const Material& mat, LightToolsSpectral spectral, bool plane_symmetric,
                             double poi) {
  LightToolsBsdf lt;
  lt.plane_symmetric = plane_symmetric;
  lt.spectral = spectral;
  lt.comments = {"written by lighttools_test from an analytic GGX material"};
  // Plane-symmetric tables cover the half on one side of the plane of incidence.
  const double az_end = plane_symmetric ? poi + 180.0 : 355.0;
  for (double a = plane_symmetric ? poi : 0.0; a <= az_end + 1e-9; a += 5)
    lt.scatter_azimuth_deg.push_back(a);
  for (double r = 0; r <= 88; r += 2) lt.scatter_radial_deg.push_back(r);
  const int channels = spectral == LightToolsSpectral::kMonochrome ? 1 : 3;
  for (double aoi : {0.0, 20.0, 40.0, 60.0}) {
    const Vec3 l = SphericalDirectionDeg(aoi, poi);
    for (int c = 0; c < channels; ++c) {
      LightToolsBlock b;
      b.aoi_deg = aoi;
      b.poi_deg = poi;
      b.channel = c;
      b.wavelength = c == 0 ? 630 : c == 1 ? 525 : 465;
      b.tis = 0.3;
      for (double az : lt.scatter_azimuth_deg) {
        for (double rad : lt.scatter_radial_deg) {
          b.values.push_back(mat.Evaluate(l, SphericalDirectionDeg(rad, az))[c]);
        }
      }
      lt.blocks.push_back(std::move(b));
    }
  }
  return lt;
}

void ExpectSamplesMatch(const Measurement& m, const Material& mat, int channels) {
  ASSERT_EQ(m.slices.size(), 4u);
  for (const Slice& s : m.slices) {
    EXPECT_EQ(s.phi_in_deg, 0.0);
    const Vec3 l = SphericalDirectionDeg(s.theta_in_deg, 0.0);
    for (const Sample& smp : s.samples) {
      const Rgb expected =
          mat.Evaluate(l, SphericalDirectionDeg(smp.theta_out_deg, smp.phi_out_deg));
      for (int c = 0; c < 3; ++c) {
        const double e = expected[channels == 1 ? 0 : c];
        // 9 significant digits in the file, float in the Measurement.
        ASSERT_NEAR(smp.rgb[c], e, 2e-7 * e + 1e-9)
            << "θin " << s.theta_in_deg << " θout " << smp.theta_out_deg << " φout "
            << smp.phi_out_deg << " channel " << c;
      }
    }
  }
}

TEST(LightTools, RgbRoundTripReproducesTheAnalyticMaterial) {
  const Material mat = GgxMaterial();
  const fs::path dir = TempDir("rgb");
  const std::string path = (dir / "ggx_rgb.bsdf").string();
  // POI 90°: LightTools' own convention for isotropic data; the importer rotates it to φin = 0.
  const LightToolsBsdf written = AnalyticTable(mat, LightToolsSpectral::kRgb, false, 90.0);
  WriteLightToolsBsdf(path, written);
  const Measurement m = LoadLightToolsBsdf(path);
  ExpectSamplesMatch(m, mat, 3);
  // 72 azimuths × 44 radial angles above 0, plus the normal once.
  for (const Slice& s : m.slices) EXPECT_EQ(s.samples.size(), 72u * 44u + 1u);
  EXPECT_EQ(m.metadata.operator_notes, "written by lighttools_test from an analytic GGX material");
  fs::remove_all(dir);
}

TEST(LightTools, PlaneSymmetricMonochromeFileGetsItsMirrorHalf) {
  Material mat = GgxMaterial();
  mat.SetParameter(0, {0.3, 0.3, 0.3});
  const LightToolsBsdf written = AnalyticTable(mat, LightToolsSpectral::kMonochrome, true, 0.0);
  const Measurement m = LightToolsToMeasurement(
      ParseLightToolsBsdf(FormatLightToolsBsdf(written), "sym.bsdf"), "sym.bsdf");
  ExpectSamplesMatch(m, mat, 1);
  // Azimuths 0..180 in 5° steps: 0 and 180 once, the 35 in between twice.
  for (const Slice& s : m.slices) EXPECT_EQ(s.samples.size(), (2u + 2u * 35u) * 44u + 1u);
}

TEST(LightTools, XyzBlocksConvertToLinearRec709) {
  // Hand-written XYZ file. D65 white (0.95047, 1, 1.08883) and the sRGB green primary
  // (0.3576, 0.7152, 0.1192) are published; IEC 61966-2-1 maps them to (1,1,1) and (0,1,0).
  const std::string text =
      "# hand-written\nSymmetry Asymmetrical\nSpectralContent XYZ\n"
      "ScatterAzimuth 2 0 180\nScatterRadial 2 0 30\nDataBegin\n"
      "AOI 20\nPOI 0\nSide Front\nScatterType BRDF\nTristimulusValue TrisZ\nTIS 1\n"
      "1.08883 0.1192\n1.08883 0.1192\n"
      "AOI 20 POI 0 Side Front ScatterType BRDF TristimulusValue TrisX TIS 1\n"
      "0.95047 0.3576\n0.95047 0.3576\n"
      "TristimulusValue TrisY AOI 20 TIS 1\n1 0.7152\n1 0.7152\n"
      "DataEnd\n";
  const Measurement m = LightToolsToMeasurement(ParseLightToolsBsdf(text, "xyz.bsdf"), "xyz.bsdf");
  ASSERT_EQ(m.slices.size(), 1u);
  ASSERT_EQ(m.slices[0].samples.size(), 3u);
  for (const Sample& s : m.slices[0].samples) {
    const std::array<float, 3> expected =
        s.theta_out_deg == 0.0f ? std::array<float, 3>{1, 1, 1} : std::array<float, 3>{0, 1, 0};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.rgb[c], expected[c], 1.5e-3);
  }
}

TEST(LightTools, HandWrittenFileLandsInOurFrame) {
  // Light at POI 90° in the sample frame: the file's azimuth 270° is the mirror side, which
  // is φout = 180° in our frame (light at φin = 0).
  const std::string text =
      "Symmetry Asymmetrical\nSpectralContent Monochrome\n"
      "ScatterAzimuth 4 0 90 180 270\nScatterRadial 2 0 45\nDataBegin\n"
      "AOI 45 POI 90 Side Front Wavelength 550 ScatterType BRDF TIS 0.9\n"
      "0.1 0.2\n0.1 0.3\n0.1 0.4\n0.1 5.0\nDataEnd\n";
  const Measurement m = LightToolsToMeasurement(ParseLightToolsBsdf(text, "h.bsdf"), "h.bsdf");
  ASSERT_EQ(m.slices.size(), 1u);
  EXPECT_EQ(m.slices[0].theta_in_deg, 45.0);
  ASSERT_EQ(m.slices[0].samples.size(), 5u);
  bool found_peak = false;
  for (const Sample& s : m.slices[0].samples) {
    if (s.rgb[0] == 5.0f) {
      found_peak = true;
      EXPECT_EQ(s.theta_out_deg, 45.0f);
      EXPECT_EQ(s.phi_out_deg, 180.0f);
    }
    if (s.rgb[0] == 0.3f) {
      EXPECT_EQ(s.phi_out_deg, 0.0f);  // file azimuth 90° is the light's side
    }
  }
  EXPECT_TRUE(found_peak);
}

TEST(LightTools, TransmissionOnlyFileNeedsAllowBtdf) {
  const std::string text =
      "Symmetry Asymmetrical\nSpectralContent Monochrome\nScatterAzimuth 1 0\n"
      "ScatterRadial 2 0 10\nDataBegin\nAOI 10 ScatterType BTDF TIS 0.5\n1 2\nDataEnd\n";
  const LightToolsBsdf lt = ParseLightToolsBsdf(text, "t.bsdf");
  try {
    LightToolsToMeasurement(lt, "t.bsdf");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("t.bsdf: line 6: expected a front-side BRDF block"),
              std::string::npos)
        << e.what();
  }
  const Measurement m = LightToolsToMeasurement(lt, "t.bsdf", LightToolsImportOptions{true});
  ASSERT_EQ(m.slices.size(), 1u);
  EXPECT_EQ(m.slices[0].samples.size(), 2u);
}

TEST(LightTools, MissingChannelBlockIsReportedWithItsLine) {
  const std::string text =
      "Symmetry Asymmetrical\nSpectralContent RGB\nScatterAzimuth 1 0\nScatterRadial 1 0\n"
      "DataBegin\nAOI 10 TristimulusValue R TIS 1\n1\nAOI 10 TristimulusValue B TIS 1\n1\n"
      "DataEnd\n";
  try {
    LightToolsToMeasurement(ParseLightToolsBsdf(text, "rgb.bsdf"), "rgb.bsdf");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()),
              "rgb.bsdf: line 6: expected a G block for AOI 10, POI 0, got none");
  }
}

// Found by the fuzzer: a file whose data section is empty used to be accepted only when
// enough bytes (here, trailing blanks) followed DataBegin to "hold" its 3 × 3 grid, so the
// writer's compact copy of it was refused.
TEST(LightTools, FileWithoutBlocksReadsTheSameWithOrWithoutPadding) {
  const std::string header =
      "SpectralContent Monochrome\nScatterAzimuth 3 0 90 180\nScatterRadial 3 0 30 60\n"
      "DataBegin\nDataEnd\n";
  for (const std::string& text : {header, header + std::string(40, ' ') + "\n"}) {
    const LightToolsBsdf lt = ParseLightToolsBsdf(text, "empty.bsdf");
    EXPECT_TRUE(lt.blocks.empty());
    EXPECT_EQ(lt.scatter_azimuth_deg, (std::vector<double>{0, 90, 180}));
    EXPECT_EQ(lt.scatter_radial_deg, (std::vector<double>{0, 30, 60}));
    const LightToolsBsdf again = ParseLightToolsBsdf(FormatLightToolsBsdf(lt), "rewritten.bsdf");
    EXPECT_TRUE(again.blocks.empty());
    EXPECT_EQ(again.scatter_azimuth_deg, lt.scatter_azimuth_deg);
    try {
      LightToolsToMeasurement(lt, "empty.bsdf");
      FAIL();
    } catch (const FormatError& e) {
      EXPECT_EQ(std::string(e.what()),
                "empty.bsdf: line 1: expected a front-side BRDF block, got no blocks between "
                "DataBegin and DataEnd");
    }
  }
  // A block still has to find its 9 values in the file.
  try {
    ParseLightToolsBsdf(
        "SpectralContent Monochrome\nScatterAzimuth 3 0 90 180\n"
        "ScatterRadial 3 0 30 60\nDataBegin\nAOI 0 TIS 1\n1 2 3\nDataEnd\n",
        "short.bsdf");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("short.bsdf: line 5"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace brdf
