// The .bpc specification (docs/formats/bpc.md) is precise enough to write a reader from: an
// independent reader written from that page only (tests/python/bpc_reader.py, numpy) must agree
// with the C++ reader on intact, unfinished, cut and damaged files written by the C++ writer.
#include <gtest/gtest.h>

#include <bit>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "brdf/core/bpc.h"
#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "test_support.h"

namespace brdf {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

Measurement MakeMeasurement() {
  Measurement m;
  m.metadata.sample_name = "Grüne Keramik 緑 ✓";
  m.metadata.instrument_model = "MiniDiff V2 (simulated)";
  m.metadata.operator_notes = "tab\there, \"quoted\", back\\slash";
  m.metadata.capture_start = "2026-11-22T10:00:00Z";
  m.metadata.capture_end = "2026-11-22T10:04:00Z";
  m.metadata.extra["seed"] = "7";
  const std::uint32_t specials[] = {0x80000000u, 0x00000001u, 0x7f7fffffu, 0xff800000u,
                                    0x7fc00001u, 0x7f812345u, 0x3f800000u};
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> u(0.0f, 3.0f);
  for (int i = 0; i < 4; ++i) {
    Slice s;
    s.theta_in_deg = 20.0 * i;
    s.has_sigma = i != 1;
    s.complete = i != 2;
    for (int j = 0; j < 60; ++j) {
      Sample p;
      p.theta_in_deg = static_cast<float>(s.theta_in_deg) + 0.01f * static_cast<float>(j % 3);
      p.phi_in_deg = j % 7 == 0 ? -0.0f : 0.0f;
      p.theta_out_deg = static_cast<float>(j % 76);
      p.phi_out_deg = static_cast<float>(j) * 6.0f;
      for (int c = 0; c < 3; ++c) {
        p.rgb[c] = j % 9 == c ? std::bit_cast<float>(specials[(i + j) % 7]) : u(rng);
        p.sigma[c] = s.has_sigma ? 0.01f * u(rng) : 0.0f;
      }
      p.flags = static_cast<std::uint8_t>((i * 60 + j) % 256);
      s.samples.push_back(p);
    }
    m.slices.push_back(std::move(s));
  }
  return m;
}

std::string KindName(BpcProblemKind k) {
  switch (k) {
    case BpcProblemKind::kTruncated:
      return "truncated";
    case BpcProblemKind::kCorrupt:
      return "corrupt";
    case BpcProblemKind::kTrailingData:
      return "trailing_data";
  }
  return "?";
}

// The C++ reader's view of a file in the Python summary's shape.
Json CppSummary(const std::string& path) {
  BpcReadResult r;
  try {
    r = ReadBpc(path);
  } catch (const FormatError& e) {
    return {{"error", e.what()}};
  }
  const Metadata& md = r.measurement.metadata;
  Json j;
  j["metadata"] = {{"sample_name", md.sample_name},
                   {"instrument_model", md.instrument_model},
                   {"instrument_serial", md.instrument_serial},
                   {"firmware_version", md.firmware_version},
                   {"protocol_version", md.protocol_version},
                   {"calibration_reference", md.calibration_reference},
                   {"calibration_time", md.calibration_time},
                   {"capture_start", md.capture_start},
                   {"capture_end", md.capture_end},
                   {"operator_notes", md.operator_notes},
                   {"units", md.units},
                   {"software_version", md.software_version},
                   {"extra", md.extra}};
  j["slice_indices"] = r.slice_indices;
  j["problems"] = Json::array();
  for (const BpcProblem& p : r.problems)
    j["problems"].push_back({{"kind", KindName(p.kind)},
                             {"offset", p.offset},
                             {"size", p.size},
                             {"slice", p.slice_index}});
  j["finished"] = r.finished;
  j["valid_bytes"] = r.valid_bytes;
  j["intact_data_after_damage"] = r.intact_data_after_damage;
  j["slices"] = Json::array();
  for (const Slice& s : r.measurement.slices) {
    Json fields;
    const auto column = [&](const char* name, auto get) {
      Json col = Json::array();
      for (const Sample& p : s.samples) col.push_back(get(p));
      fields[name] = col;
    };
    const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
    column("theta_in_deg", [&](const Sample& p) { return bits(p.theta_in_deg); });
    column("phi_in_deg", [&](const Sample& p) { return bits(p.phi_in_deg); });
    column("theta_out_deg", [&](const Sample& p) { return bits(p.theta_out_deg); });
    column("phi_out_deg", [&](const Sample& p) { return bits(p.phi_out_deg); });
    column("r", [&](const Sample& p) { return bits(p.rgb[0]); });
    column("g", [&](const Sample& p) { return bits(p.rgb[1]); });
    column("b", [&](const Sample& p) { return bits(p.rgb[2]); });
    column("flags", [&](const Sample& p) { return static_cast<unsigned>(p.flags); });
    if (s.has_sigma) {
      column("sigma_r", [&](const Sample& p) { return bits(p.sigma[0]); });
      column("sigma_g", [&](const Sample& p) { return bits(p.sigma[1]); });
      column("sigma_b", [&](const Sample& p) { return bits(p.sigma[2]); });
    }
    j["slices"].push_back({{"theta_in_deg_bits", std::bit_cast<std::uint64_t>(s.theta_in_deg)},
                           {"phi_in_deg_bits", std::bit_cast<std::uint64_t>(s.phi_in_deg)},
                           {"has_sigma", s.has_sigma},
                           {"complete", s.complete},
                           {"samples", s.samples.size()},
                           {"fields", fields}});
  }
  return j;
}

Json RunPythonReader(const std::vector<std::string>& paths) {
  std::string cmd = std::string(BRDF_PYTHON3) + " " + BRDF_SOURCE_DIR "/tests/python/bpc_reader.py";
  for (const auto& p : paths) cmd += " '" + p + "'";
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) return {};
  std::string out;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  const int status = ::pclose(pipe);
  EXPECT_EQ(status, 0) << cmd;
  return Json::parse(out, nullptr, false);
}

TEST(BpcPythonReader, AgreesWithTheCppReaderOnIntactCutAndDamagedFiles) {
  const fs::path dir = brdf::test::ScopedTempDir::MakeTempDir("bpc-python");
  struct Cleanup {
    fs::path dir;
    ~Cleanup() { fs::remove_all(dir); }
  } cleanup{dir};
  const Measurement m = MakeMeasurement();
  const std::string full = EncodeBpc(m);
  std::vector<std::string> files;
  const auto add = [&](const std::string& name, const std::string& bytes) {
    files.push_back((dir / name).string());
    WriteFileAtomically(files.back(), bytes);
  };

  // Written by the appender, finished and unfinished.
  const std::string appended = (dir / "appended.bpc").string();
  {
    Metadata start = m.metadata;
    start.capture_end.clear();
    BpcAppender a = BpcAppender::Create(appended, start);
    for (const Slice& s : m.slices) a.AppendSlice(s);
    files.push_back(appended);
    const std::string unfinished = (dir / "unfinished.bpc").string();
    fs::copy_file(appended, unfinished);
    files.push_back(unfinished);
    a.Finish(m.metadata);
  }
  add("whole.bpc", full);
  std::mt19937 rng(4711);
  std::uniform_int_distribution<std::size_t> offset(0, full.size() - 1);
  for (int i = 0; i < 40; ++i) {
    const std::size_t cut = offset(rng);
    add("cut" + std::to_string(i) + ".bpc", full.substr(0, cut));
  }
  for (int i = 0; i < 40; ++i) {
    std::string bytes = full;
    bytes[offset(rng)] ^= static_cast<char>(1 << (i % 8));
    add("flip" + std::to_string(i) + ".bpc", bytes);
  }
  // Every chunk header field of every chunk: the resynchronisation and slice attribution rules.
  {
    std::uint64_t head_json = 0;
    for (int b = 7; b >= 0; --b)
      head_json = (head_json << 8) | static_cast<unsigned char>(full[20 + b]);
    std::size_t start = 12 + 24 + head_json;
    std::vector<std::size_t> chunk_starts;
    for (const Slice& s : m.slices) {
      chunk_starts.push_back(start);
      start += 24 + 32 + s.samples.size() * (s.has_sigma ? 44 : 32);
    }
    chunk_starts.push_back(start);  // the end chunk
    for (std::size_t c = 0; c < chunk_starts.size(); ++c) {
      for (const std::size_t field : {0, 3, 4, 9, 16, 22}) {
        std::string bytes = full;
        bytes[chunk_starts[c] + field] ^= 0x04;
        add("hdr" + std::to_string(c) + "_" + std::to_string(field) + ".bpc", bytes);
      }
    }
  }
  add("zero_tail.bpc", full.substr(0, full.size() / 2) + std::string(500, '\0'));
  add("trailing.bpc", full + "junk");

  const Json py = RunPythonReader(files);
  ASSERT_TRUE(py.is_array()) << "the Python reader printed no JSON list";
  ASSERT_EQ(py.size(), files.size());
  int with_problems = 0, fatal = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    SCOPED_TRACE(files[i]);
    const Json cpp = CppSummary(files[i]);
    if (cpp.contains("error")) {
      ++fatal;
      EXPECT_TRUE(py[i].contains("error")) << cpp["error"];
      continue;
    }
    ASSERT_FALSE(py[i].contains("error")) << py[i]["error"];
    if (!cpp["problems"].empty()) ++with_problems;
    EXPECT_EQ(py[i]["problems"], cpp["problems"]);
    EXPECT_EQ(py[i]["finished"], cpp["finished"]);
    EXPECT_EQ(py[i]["valid_bytes"], cpp["valid_bytes"]);
    EXPECT_EQ(py[i]["intact_data_after_damage"], cpp["intact_data_after_damage"]);
    EXPECT_EQ(py[i]["slice_indices"], cpp["slice_indices"]);
    EXPECT_EQ(py[i]["metadata"], cpp["metadata"]);
    ASSERT_EQ(py[i]["slices"].size(), cpp["slices"].size());
    for (std::size_t k = 0; k < cpp["slices"].size(); ++k)
      EXPECT_TRUE(py[i]["slices"][k] == cpp["slices"][k]) << "slice " << k << " differs";
  }
  // The sample of files really exercised both readers' damage paths.
  EXPECT_GT(with_problems, 40);
  EXPECT_GT(fatal, 0);
}

}  // namespace
}  // namespace brdf
