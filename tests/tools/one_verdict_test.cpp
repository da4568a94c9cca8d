// One verdict per file (docs/robustness.md, "One verdict per file"): every command that reads a
// file accepts it or refuses it by the one rule of brdf::sources, and `info` says which. The
// expected verdicts come from that rule and from docs/design.md §4 (values no surface has) and
// §9 (under-determined fits), not from the program's output.
#include <nlohmann/json.hpp>

#include <algorithm>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

using Json = nlohmann::json;

std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class OneVerdict : public ToolTest {
 protected:
  // A finished capture of a GGX material on a reduced grid (θout step 5°, φout step 10°).
  Measurement Base() const { return CaptureOf(Ggx03(), {0, 30, 60}, 75, 5, 10); }

  fs::path Write(const std::string& name, const Measurement& m) const {
    const fs::path p = dir_ / name;
    WriteBpc(p.string(), m);
    return p;
  }

  // Index of the sample of slice `s` at (θout, φout).
  static std::size_t At(const Measurement& m, std::size_t s, double theta, double phi) {
    const auto& v = m.slices[s].samples;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i].theta_out_deg == theta && v[i].phi_out_deg == phi) return i;
    ADD_FAILURE() << "no sample at " << theta << ", " << phi;
    return 0;
  }

  ToolRun Info(const fs::path& p, Json* doc) const {
    ToolRun r = RunTool("info " + Quote(p) + " --json", dir_);
    *doc = Json::parse(r.out, nullptr, false);
    return r;
  }
  ToolRun Eval(const fs::path& p) const {
    return RunTool("eval " + Quote(p) + " --in 30,0 --out 30,180", dir_);
  }
  ToolRun Convert(const fs::path& p, const std::string& extra = "") const {
    return RunTool("convert " + Quote(p) + " --quiet --formats json,ktx2 --out " +
                       Quote(dir_ / ("conv-" + p.stem().string())) + " " + extra,
                   dir_);
  }
  ToolRun Preview(const fs::path& p) const {
    return RunTool("preview " + Quote(p) + " --size 16 --spp 1 --jobs 1 --quiet --out " +
                       Quote(dir_ / (p.stem().string() + ".png")),
                   dir_);
  }
  ToolRun Fit(const fs::path& p, const std::string& model, const fs::path& out) const {
    return RunTool("fit " + Quote(p) + " --model " + model + " --starts 1 --jobs 1 --quiet --out " +
                       Quote(out),
                   dir_);
  }
};

// docs/design.md §4: −1e30, 3e38, a negated capture and a capture × 1e30 are values no surface
// has. Every reader refuses them as it refuses a NaN, naming slice and sample; export-csv copies
// them and says what it copied. Before: info "usable: yes", eval −2.8e28, convert wrote 0 or
// 65408, fit "converged".
TEST_F(OneVerdict, ValuesNoSurfaceHasAreRefusedByEveryReaderNamingSliceAndSample) {
  const Measurement base = Base();
  struct Case {
    std::string name;
    Measurement m;
  };
  std::vector<Case> cases;
  {
    Measurement m = base;
    m.slices[1].samples[At(m, 1, 30, 0)].rgb[0] = -1e30f;
    cases.push_back({"neg_one", m});
  }
  {
    Measurement m = base;
    m.slices[1].samples[At(m, 1, 30, 0)].rgb[1] = 3e38f;
    cases.push_back({"huge_one", m});
  }
  {
    Measurement m = base;
    for (Slice& s : m.slices)
      for (Sample& x : s.samples)
        for (float& v : x.rgb) v = -v;
    cases.push_back({"negated", m});
  }
  {
    Measurement m = base;
    for (Slice& s : m.slices)
      for (Sample& x : s.samples)
        for (float& v : x.rgb) v *= 1e30f;
    cases.push_back({"times_1e30", m});
  }
  // Positive control: the same capture as it was is accepted by all.
  const fs::path intact = Write("intact.bpc", base);
  Json doc;
  EXPECT_EQ(Info(intact, &doc).exit_code, 0);
  EXPECT_EQ(doc["usable"], true);
  EXPECT_EQ(Eval(intact).exit_code, 0);
  EXPECT_EQ(Convert(intact).exit_code, 0);

  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path p = Write(c.name + ".bpc", c.m);
    const ToolRun info = Info(p, &doc);
    EXPECT_EQ(info.exit_code, 1) << info.err;
    ASSERT_TRUE(doc.is_object()) << info.out;
    EXPECT_EQ(doc["usable"], false);
    EXPECT_EQ(doc["evaluable"], false);
    const std::string refusals = doc["refusals"].dump();
    EXPECT_NE(refusals.find("slice"), std::string::npos) << refusals;
    EXPECT_NE(refusals.find("sample"), std::string::npos) << refusals;
    const ToolRun text = RunTool("info " + Quote(p), dir_);
    EXPECT_EQ(text.out.find("problems: none"), std::string::npos) << text.out;
    for (const ToolRun& r : {Eval(p), Convert(p), Preview(p), Fit(p, "lambert", dir_ / "f.json")}) {
      EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
      EXPECT_EQ(r.ErrLines().size(), 1u) << r.err;
      EXPECT_NE(r.err.find("slice"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("sample"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(dir_ / "f.json"));
    const ToolRun csv =
        RunTool("export-csv " + Quote(p) + " --out " + Quote(dir_ / (c.name + ".csv")), dir_);
    EXPECT_EQ(csv.exit_code, 0) << csv.err;
    EXPECT_NE(csv.err.find("warning: copied as it is"), std::string::npos) << csv.err;
    EXPECT_NE(csv.err.find("sample"), std::string::npos) << csv.err;
  }
}

// docs/design.md §4: convert warns whenever the RGB9E5 textures clip. 7e4 1/sr at θout ≤ 30°
// (f_r·cosθ ≤ 7e4 < 1e5) is a value a surface may have, above RGB9E5's 65408.
TEST_F(OneVerdict, ConvertWarnsWhenTheTexturesClip) {
  Measurement m = Base();
  for (Sample& x : m.slices[1].samples)
    if (x.theta_out_deg <= 30) x.rgb = {7e4f, 7e4f, 7e4f};
  const ToolRun bright = Convert(Write("bright.bpc", m));
  EXPECT_EQ(bright.exit_code, 0) << bright.err;
  EXPECT_NE(bright.err.find("clip"), std::string::npos) << bright.err;
  EXPECT_NE(bright.err.find("above 65408"), std::string::npos) << bright.err;
  const ToolRun plain = Convert(Write("plain.bpc", Base()));
  EXPECT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.err.find("clip"), std::string::npos) << plain.err;
  // A material's lobe sharper than the 1° texels: its virtual capture holds the model's own
  // values (GGX α = 0.001, f0 = 1: at a mirror direction D = 1/(π α²) ≈ 3.2e5 and
  // f_r = F·G·D/(4 cosθi cosθo) ≳ D/4 ≈ 8e4 > 65408), converted with the warning rather than
  // refused as a measurement would be.
  const fs::path mirror = dir_ / "mirror.json";
  WriteText(mirror, R"({"model": "ggx", "kd": 0, "f0": 1, "alpha": 0.001})");
  const ToolRun sharp = Convert(mirror);
  EXPECT_EQ(sharp.exit_code, 0) << sharp.err;
  EXPECT_NE(sharp.err.find("above 65408"), std::string::npos) << sharp.err;
}

// docs/design.md §9: with fewer usable samples than twice the parameters one channel depends
// on, the fit warns "N usable samples for P parameters" and records representable false;
// --extrapolate auto keeps the defaults p = 1, l = 0.5.
TEST_F(OneVerdict, UnderdeterminedFitsWarnAndAreNotRepresentable) {
  Measurement saturated = Base();
  for (Slice& s : saturated.slices)
    for (Sample& x : s.samples) x.flags |= kFlagSaturated;
  saturated.slices[0].samples[At(saturated, 0, 30, 0)].flags = 0;
  const ToolRun lambert = Fit(Write("sat.bpc", saturated), "lambert", dir_ / "sat.json");
  EXPECT_EQ(lambert.exit_code, 0) << lambert.err;
  // lambert: one parameter, rho (RGB): 3 parameters, 1 per channel.
  EXPECT_NE(lambert.out.find("1 usable sample for 3 parameters"), std::string::npos) << lambert.out;
  EXPECT_EQ(Json::parse(ReadAll(dir_ / "sat.json"))["fit"]["representable"], false);

  Measurement one_per_slice = Base();
  for (std::size_t s = 0; s < one_per_slice.slices.size(); ++s) {
    const Sample keep = one_per_slice.slices[s].samples[At(one_per_slice, s, 30, 0)];
    one_per_slice.slices[s].samples = {keep};
  }
  const fs::path sparse = Write("sparse.bpc", one_per_slice);
  const ToolRun ggx = Fit(sparse, "ggx", dir_ / "sparse.json");
  EXPECT_EQ(ggx.exit_code, 0) << ggx.err;
  // ggx: kd, f0 and alpha, each per channel (the legacy models fit channels apart): 9, 3 each.
  EXPECT_NE(ggx.out.find("3 usable samples for 9 parameters"), std::string::npos) << ggx.out;
  EXPECT_EQ(Json::parse(ReadAll(dir_ / "sparse.json"))["fit"]["representable"], false);

  const ToolRun automatic = Convert(sparse, "--extrapolate auto");
  EXPECT_EQ(automatic.exit_code, 0) << automatic.err;
  EXPECT_NE(automatic.err.find("--extrapolate auto"), std::string::npos) << automatic.err;
  const Json side = Json::parse(ReadAll(dir_ / "conv-sparse" / "sparse.json"));
  EXPECT_EQ(side["extrapolation"]["p"], 1.0) << side.dump();
  EXPECT_EQ(side["extrapolation"]["l"], 0.5) << side.dump();

  // The intact capture's fit is determined: no such warning.
  const ToolRun full = Fit(Write("full.bpc", Base()), "ggx", dir_ / "full.json");
  EXPECT_EQ(full.out.find("usable sample"), std::string::npos) << full.out;
}

// θin 30° alone or 10°, 30°, 50° is not k·Δin from 0°: only the LUT textures need that, so convert
// refuses it and eval, preview and fit accept it; capture warns when it writes such a file, info
// exits 1 and its --json says the same. Before: capture silent, info "usable: no" but exit 0,
// --json "usable": true.
TEST_F(OneVerdict, ThetaInNotKDeltaIsRefusedByConvertAloneAndEveryoneSaysSo) {
  for (const std::string list : {"30", "10,30,50"}) {
    SCOPED_TRACE(list);
    const fs::path p = dir_ / ("t" + std::to_string(list.size()) + ".bpc");
    const ToolRun capture = RunTool(
        "capture --device sim --material gold --sample t --theta-in " + list +
            " --theta-out-step 5 --phi-out-step 10 --noise 0 --sim-pace-ms 0 --quiet --out " +
            Quote(p),
        dir_);
    ASSERT_EQ(capture.exit_code, 0) << capture.err;
    EXPECT_NE(capture.err.find("warning"), std::string::npos) << capture.err;
    EXPECT_NE(capture.err.find("'brdf convert'"), std::string::npos) << capture.err;
    Json doc;
    const ToolRun info = Info(p, &doc);
    EXPECT_EQ(info.exit_code, 1) << info.err;
    EXPECT_EQ(doc["usable"], false) << info.out;
    EXPECT_EQ(doc["evaluable"], true) << info.out;
    EXPECT_EQ(doc["convertible"], false) << info.out;
    EXPECT_NE(doc["refusals"].dump().find("k·Δin"), std::string::npos) << info.out;
    const ToolRun text = RunTool("info " + Quote(p), dir_);
    EXPECT_EQ(text.out.find("problems: none"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("usable: no"), std::string::npos) << text.out;
    EXPECT_EQ(Eval(p).exit_code, 0);
    EXPECT_EQ(Preview(p).exit_code, 0);
    EXPECT_EQ(Fit(p, "lambert", dir_ / (p.stem().string() + ".json")).exit_code, 0);
    const ToolRun convert = Convert(p);
    EXPECT_EQ(convert.exit_code, 1);
    EXPECT_NE(convert.err.find("k·Δin"), std::string::npos) << convert.err;
  }
}

// A material whose "extrapolate" member is invalid is one invalid file for every command.
// Before: info, eval and preview accepted it, convert and fit refused it.
TEST_F(OneVerdict, MaterialWithInvalidExtrapolateIsRefusedEverywhere) {
  const fs::path p = dir_ / "bad.json";
  WriteText(p,
            R"({"model": "lambert", "rho": [0.5, 0.4, 0.3], "extrapolate": {"p": -1, "l": 0.5}})");
  Json doc;
  for (const ToolRun& r :
       {Info(p, &doc), Eval(p), Preview(p), Convert(p), Fit(p, "lambert", dir_ / "bad-fit.json")}) {
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("extrapolate"), std::string::npos) << r.err;
  }
}

// export-csv refuses a value the CSV layout cannot hold (θout < 0, which captures may hold as the
// in-plane convention) naming the capture's slice and sample, not a line of a CSV it never wrote.
TEST_F(OneVerdict, ExportCsvNamesTheCaptureSampleNotALineOfItsOwnCsv) {
  Measurement m = Base();
  const std::size_t n = At(m, 2, 40, 0);
  m.slices[2].samples[n].theta_out_deg = -40.0f;
  const fs::path p = Write("inplane.bpc", m);
  const ToolRun r = RunTool("export-csv " + Quote(p) + " --out " + Quote(dir_ / "x.csv"), dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("inplane.bpc: slice 2, sample " + std::to_string(n)), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("x.csv"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("line"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.csv"));
}

// A transmission (BTDF) table is read mirrored into the reflection hemisphere, with a warning, by
// every reading command: fit as info and eval. Before: fit refused it, pointing at an
// --allow-btdf it does not have.
TEST_F(OneVerdict, BtdfTablesAreReadMirroredByFitAsByEval) {
  const fs::path table =
      test::DataPath("zemax-imaging-sphere/test_13_planesymmetric_btdf_zemax.bsdf");
  const ToolRun eval = RunTool("eval " + Quote(table) + " --in 0,0 --out 10,180", dir_);
  EXPECT_EQ(eval.exit_code, 0) << eval.err;
  EXPECT_NE(eval.err.find("BTDF"), std::string::npos) << eval.err;
  const ToolRun fit = Fit(table, "lambert", dir_ / "btdf.json");
  EXPECT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_NE(fit.err.find("transmission (BTDF) table"), std::string::npos) << fit.err;
}

// `capture --resume` and `repair` read captures too, by the same rule. A slice holding a value
// no surface has: the resume is refused before anything is measured (the file unchanged),
// naming slice and sample and the repair; the repair drops that slice, naming why; the repaired
// file resumed with the same command measures it again, and equals the capture as it was before
// the value was spoiled (the simulated instrument reseeds its noise per measurement: the
// resume guarantee of device/include/brdf/device/capture_session.h). Before: the resume of an
// unfinished capture measured the missing slices into a file every reader refuses, and repair
// answered "nothing to repair".
TEST_F(OneVerdict, ResumeRefusesSlicesEveryReaderRefusesAndRepairDropsThem) {
  const fs::path good = dir_ / "good.bpc";
  const std::string capture =
      "capture --device sim --material gold --sample s --theta-in 0,30,60 --theta-out-step 5 "
      "--phi-out-step 10 --noise 1 --seed 3 --sim-pace-ms 0 --quiet --out ";
  ASSERT_EQ(RunTool(capture + Quote(good), dir_).exit_code, 0);
  const Measurement original = ReadBpc(good.string()).measurement;
  ASSERT_EQ(original.slices.size(), 3u);
  Measurement spoiled = original;
  const std::size_t n = At(spoiled, 1, 30, 0);
  spoiled.slices[1].samples[n].rgb[0] = -1e30f;
  const fs::path bad = Write("bad.bpc", spoiled);
  const std::string bytes_before = ReadText(bad);

  const ToolRun resume = RunTool(capture + Quote(bad) + " --resume", dir_);
  EXPECT_EQ(resume.exit_code, 1) << resume.err;
  EXPECT_NE(resume.err.find("slice 1"), std::string::npos) << resume.err;
  EXPECT_NE(resume.err.find("sample " + std::to_string(n)), std::string::npos) << resume.err;
  EXPECT_NE(resume.err.find("brdf repair"), std::string::npos) << resume.err;
  EXPECT_EQ(ReadText(bad), bytes_before);

  Json doc;
  const ToolRun info = Info(bad, &doc);
  EXPECT_EQ(info.exit_code, 1);
  EXPECT_NE(doc.dump().find("brdf repair"), std::string::npos) << info.out;

  const fs::path fixed = dir_ / "fixed.bpc";
  const ToolRun repair = RunTool("repair " + Quote(bad) + " --out " + Quote(fixed), dir_);
  ASSERT_EQ(repair.exit_code, 0) << repair.err;
  EXPECT_NE(repair.out.find("dropped slice 1 (theta_in 30 deg)"), std::string::npos) << repair.out;
  EXPECT_NE(repair.out.find("values"), std::string::npos) << repair.out;
  EXPECT_NE(repair.out.find("missing theta_in 30 deg"), std::string::npos) << repair.out;

  const ToolRun resumed = RunTool(capture + Quote(fixed) + " --resume", dir_);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(Info(fixed, &doc).exit_code, 0);
  const Measurement again = ReadBpc(fixed.string()).measurement;
  ASSERT_EQ(again.slices.size(), 3u);
  for (const Slice& want : original.slices) {
    const auto got = std::find_if(again.slices.begin(), again.slices.end(), [&](const Slice& s) {
      return s.theta_in_deg == want.theta_in_deg;
    });
    ASSERT_NE(got, again.slices.end()) << want.theta_in_deg;
    ASSERT_EQ(got->samples.size(), want.samples.size());
    for (std::size_t i = 0; i < want.samples.size(); ++i)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(got->samples[i].rgb[c], want.samples[i].rgb[c])
            << "θin " << want.theta_in_deg << " sample " << i;
  }
}

}  // namespace
}  // namespace brdf::tooltest
