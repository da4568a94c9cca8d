// One regression test per defect the hostile-input pass (tests/tools/hostile_inputs.py) found,
// run through the built tool as a user runs it. Expected positions are counted by hand in the
// texts written here (line and column of the offending character, 1-based); nothing expected is
// taken from the tool's own output.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tool_test_util.h"

namespace brdf::tooltest {
namespace {

const std::string kGoldMaterial =
    std::string(BRDF_SOURCE_DIR) + "/data-samples/materials/gold.json";

class HostileInputs : public ToolTest {
 protected:
  // The one stderr line of a failed run, checked for what no error line may hold.
  static std::string OneCleanLine(const ToolRun& r) {
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(r.ErrLines().size(), 1u) << r.err;
    for (const char* internal : {"json.exception", "[json", "::", "parse_error", "what()"})
      EXPECT_EQ(r.err.find(internal), std::string::npos) << internal << " in: " << r.err;
    return r.err;
  }
};

// A .json input whose text does not parse was refused by `info`, `eval` and `convert`
// with "JSON text: expected valid JSON ..., got text that does not parse as JSON": no line, no
// column, nothing to look for. NaN is not JSON; the 'N' is on line 3, column 10.
TEST_F(HostileInputs, JsonSyntaxErrorNamesLineAndColumn) {
  const fs::path mat = dir_ / "nan.json";
  WriteText(mat, "{\n  \"model\": \"lambert\",\n  \"rho\": NaN\n}\n");
  for (const std::string& args :
       {"info " + Quote(mat), "eval " + Quote(mat) + " --in 30,0 --out 30,180",
        "convert " + Quote(mat) + " --quiet --out " + Quote(dir_ / "o")}) {
    SCOPED_TRACE(args);
    const std::string err = OneCleanLine(Run(args));
    EXPECT_NE(err.find(mat.string() + ": "), std::string::npos) << err;  // convert adds "FAILED: "
    EXPECT_NE(err.find(": line 3, column 10: expected valid JSON, got 'NaN'"), std::string::npos)
        << err;
  }
}

// A number literal beyond double's range (1e309) is valid JSON text but an infinite
// value; it was reported without a position. The literal starts on line 2, column 10.
TEST_F(HostileInputs, JsonNumberBeyondDoubleNamesItsPosition) {
  const fs::path mat = dir_ / "huge.json";
  WriteText(mat, "{\"model\": \"lambert\",\n \"rho\": [1e309, 0.5, 0.5]}\n");
  const std::string err = OneCleanLine(Run("info " + Quote(mat)));
  EXPECT_NE(err.find(mat.string() + ": line 2, column 10: expected a finite number, got '1e309'"),
            std::string::npos)
      << err;
}

// A DDS texture saved under a .json name (recognised by its magic, as every file is)
// was read with "<stem>.json" beside it as its sidecar, i.e. with itself: the refusal quoted the
// JSON library ("[json.exception.parse_error.101] ... last read: 'D'") and called the file an
// "embedded sidecar", which a DDS cannot have. It is a DDS without a sidecar: its θin list is
// the layout docs/design.md §5 assumes for its slice count (9 slices of the default blind-spot
// fill: 0–80° every 10°), here equal to what convert's own sidecar records.
TEST_F(HostileInputs, DdsUnderAJsonNameIsNotItsOwnSidecar) {
  ASSERT_EQ(Run("convert " + Quote(kGoldMaterial) + " --quiet --formats dds,json --out " +
                Quote(dir_ / "lut"))
                .exit_code,
            0);
  const fs::path wrong = dir_ / "gold.json";
  fs::copy_file(dir_ / "lut" / "gold.dds", wrong);
  const ToolRun info = Run("info --json " + Quote(wrong));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto recorded = nlohmann::json::parse(ReadAll(dir_ / "lut" / "gold.json"));
  const auto described = nlohmann::json::parse(info.out);
  EXPECT_EQ(described["theta_in_deg"], recorded["theta_in_deg"]) << info.out;
  EXPECT_EQ(described["theta_in_deg"],
            nlohmann::json::parse("[0, 10, 20, 30, 40, 50, 60, 70, 80]"));
  EXPECT_EQ(Run("eval " + Quote(wrong) + " --in 30,0 --out 30,180").exit_code, 0);
}

// A sidecar beside a DDS that does not parse was reported as the DDS's "(embedded
// sidecar)" with the parser's text. The error names the sidecar file and where it breaks: the
// text is cut after `{"kind": ` (line 1, column 10, the end of the text).
TEST_F(HostileInputs, BrokenSidecarBesideADdsIsNamed) {
  ASSERT_EQ(
      Run("convert " + Quote(kGoldMaterial) + " --quiet --formats dds --out " + Quote(dir_ / "lut"))
          .exit_code,
      0);
  const fs::path sidecar = dir_ / "lut" / "gold.json";
  WriteText(sidecar, "{\"kind\": ");
  const std::string err = OneCleanLine(Run("info " + Quote(dir_ / "lut" / "gold.dds")));
  EXPECT_NE(err.find(sidecar.string() + ": line 1, column 10: expected valid JSON, got the end "
                                        "of the text"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("embedded"), std::string::npos) << err;
}

// A per-material "<name>.extrapolate.json" that did not parse leaked the parser's
// message too. The stray comma before '}' is at line 1, column 31.
TEST_F(HostileInputs, UnparsableExtrapolationFileNamesLineAndColumn) {
  const fs::path mat = dir_ / "gold.json";
  fs::copy_file(kGoldMaterial, mat);
  const fs::path extra = dir_ / "gold.extrapolate.json";
  WriteText(extra, "{\"extrapolate\": {\"p\": 1, \"l\": ,}}\n");
  const ToolRun r = Run("convert " + Quote(mat) + " --quiet --out " + Quote(dir_ / "o"));
  EXPECT_NE(r.exit_code, 0);
  for (const char* internal : {"json.exception", "[json", "parse_error"})
    EXPECT_EQ(r.err.find(internal), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(extra.string() + ": line 1, column 31: expected valid JSON, got ',}}'"),
            std::string::npos)
      << r.err;
}

// `info` on a third-party table said "usable: yes ('brdf convert' and 'brdf eval'
// accept it)" although convert refuses every table ("not an input": tables are imported
// first). What info claims must hold: eval accepts the table, convert is not claimed.
TEST_F(HostileInputs, InfoOnATableClaimsOnlyWhatTheCommandsDo) {
  const fs::path csv = dir_ / "t.csv";
  WriteText(csv,
            "theta_in,phi_in,theta_out,phi_out,r,g,b\n"
            "0,0,0,0,0.1,0.2,0.3\n0,0,10,0,0.1,0.2,0.3\n0,0,10,90,0.1,0.2,0.3\n"
            "0,0,20,0,0.1,0.2,0.3\n0,0,20,90,0.1,0.2,0.3\n0,0,20,180,0.1,0.2,0.3\n");
  const ToolRun info = Run("info " + Quote(csv));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(info.out.find("'brdf convert'"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("usable: yes ('brdf eval' accepts it)"), std::string::npos) << info.out;
  EXPECT_EQ(Run("eval " + Quote(csv) + " --in 0,0 --out 10,0").exit_code, 0);
  EXPECT_NE(Run("convert " + Quote(csv) + " --quiet --out " + Quote(dir_ / "o")).exit_code, 0);
}

// `atlas` and `fit` given a folder without inputs said "... found in the inputs"
// without naming the folder (convert named it).
TEST_F(HostileInputs, EmptyFolderIsNamedByEveryBatchCommand) {
  const fs::path empty = dir_ / "empty";
  fs::create_directories(empty);
  for (const std::string& args :
       {"atlas " + Quote(empty) + " --quiet --out " + Quote(dir_ / "a"),
        "fit " + Quote(empty) + " --quiet --out " + Quote(dir_ / "f"),
        "convert " + Quote(empty) + " --quiet --out " + Quote(dir_ / "c")}) {
    SCOPED_TRACE(args);
    const std::string err = OneCleanLine(Run(args));
    EXPECT_NE(err.find("found in " + empty.string()), std::string::npos) << err;
  }
}

// ---- captures: the chunk layout of docs/formats/bpc.md, read and rewritten here with zlib's
// crc32, to make files whose every CRC is right but whose content lies ----

struct Chunk {
  std::size_t offset;
  std::string tag;
  std::uint32_t index;
  std::uint64_t payload_size;
};

std::uint32_t U32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}
std::uint64_t U64(const std::string& b, std::size_t at) {
  return U32(b, at) | (static_cast<std::uint64_t>(U32(b, at + 4)) << 32);
}
void PutU32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
void PutU64(std::string& b, std::size_t at, std::uint64_t v) {
  PutU32(b, at, static_cast<std::uint32_t>(v));
  PutU32(b, at + 4, static_cast<std::uint32_t>(v >> 32));
}
std::uint32_t ZlibCrc(const std::string& b, std::size_t at, std::size_t n) {
  return static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(b.data() + at), static_cast<uInt>(n)));
}

std::vector<Chunk> Chunks(const std::string& b) {
  std::vector<Chunk> out;
  for (std::size_t pos = 12; pos + 24 <= b.size();) {
    out.push_back({pos, b.substr(pos, 4), U32(b, pos + 4), U64(b, pos + 8)});
    pos += 24 + out.back().payload_size;
  }
  return out;
}

// `bytes` with the chunk at `c` given index `index` and payload `payload`, CRCs recomputed.
std::string Rewrite(const std::string& bytes, const Chunk& c, std::uint32_t index,
                    const std::string& payload) {
  std::string head = bytes.substr(c.offset, 24);
  PutU32(head, 4, index);
  PutU64(head, 8, payload.size());
  const std::string joined = head + payload;
  PutU32(head, 16, ZlibCrc(joined, 24, payload.size()));
  PutU32(head, 20, ZlibCrc(head, 0, 20));
  return bytes.substr(0, c.offset) + head + payload + bytes.substr(c.offset + 24 + c.payload_size);
}

class HostileCaptures : public HostileInputs {
 protected:
  void SetUp() override {
    HostileInputs::SetUp();
    const ToolRun r =
        Run("capture --device sim --material gold --sample s --theta-in 0,30,60 "
            "--theta-out-step 5 --phi-out-step 10 --noise 0 --quiet --out " +
            Quote(dir_ / "cap.bpc"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    bytes_ = ReadAll(dir_ / "cap.bpc");
    for (const Chunk& c : Chunks(bytes_)) {
      if (c.tag == "SLCE") samples_ += U64(bytes_, c.offset + 24 + 16);
      if (c.tag == "SLCE") slices_.push_back(c);
      if (c.tag == "END ") end_ = c;
    }
    ASSERT_EQ(slices_.size(), 3u);
    ASSERT_EQ(end_.tag, "END ");
  }
  fs::path Write(const std::string& name, const std::string& bytes) const {
    WriteText(dir_ / name, bytes);
    return dir_ / name;
  }
  // Data rows of a CSV the tool wrote: lines that start with a digit (docs/formats/csv.md:
  // '#' comment lines, one header line, then one sample per line).
  static std::size_t CsvRows(const fs::path& csv) {
    const std::string text = ReadAll(csv);
    std::size_t rows = 0;
    for (std::size_t pos = 0; pos < text.size(); pos = text.find('\n', pos) + 1) {
      if (text[pos] >= '0' && text[pos] <= '9') ++rows;
      if (text.find('\n', pos) == std::string::npos) break;
    }
    return rows;
  }
  std::string bytes_;
  std::vector<Chunk> slices_;
  Chunk end_{};
  std::uint64_t samples_ = 0;
};

// `export-csv` read captures with its own strict rule and refused what convert, eval
// and info accept with a warning: bytes after the end chunk (e.g. a capture at the start of a
// larger, zero-filled file) and an end chunk cut short. It now follows the capture rule of
// every command: the same warning, and every sample the file holds exported.
TEST_F(HostileCaptures, ExportCsvAcceptsWhatConvertAcceptsWithAWarning) {
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"trailing.bpc", bytes_ + std::string(4096, '\0')},
        {"cut_end.bpc", bytes_.substr(0, bytes_.size() - 1)}}) {
    SCOPED_TRACE(name);
    const fs::path cap = Write(name, bytes);
    const ToolRun convert = Run("convert " + Quote(cap) + " --quiet --formats json --out " +
                                Quote(dir_ / ("o_" + name)));
    ASSERT_EQ(convert.exit_code, 0) << convert.err;
    const fs::path csv = dir_ / (name + ".csv");
    const ToolRun run = Run("export-csv " + Quote(cap) + " --out " + Quote(csv));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find(cap.string() + ": warning: "), std::string::npos) << run.err;
    EXPECT_EQ(CsvRows(csv), samples_);
  }
}

// An end chunk whose counts lie (CRC-valid, sample_count one short) and two slice
// chunks with one index were refused by info, convert and eval with "run 'brdf repair'", but
// export-csv exported them silently and repair said "an intact, finished capture; nothing to
// repair", so the advice led nowhere. Now export-csv refuses them as info does, and repair
// writes the slices to a capture that info accepts again.
TEST_F(HostileCaptures, InconsistentChunksAreRefusedAlikeAndRepaired) {
  nlohmann::json end = nlohmann::json::parse(bytes_.substr(end_.offset + 24, end_.payload_size));
  ASSERT_EQ(end["sample_count"].get<std::uint64_t>(), samples_);
  end["sample_count"] = samples_ - 1;
  const std::string slice1 = bytes_.substr(slices_[1].offset + 24, slices_[1].payload_size);
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"lying_end.bpc",
                                            Rewrite(bytes_, end_, 0xFFFFFFFF, end.dump())},
        {"dup_index.bpc", Rewrite(bytes_, slices_[1], 0, slice1)}}) {
    SCOPED_TRACE(name);
    const fs::path cap = Write(name, bytes);
    const ToolRun info = Run("info " + Quote(cap));
    EXPECT_EQ(info.exit_code, 1);
    EXPECT_NE(info.out.find("brdf repair"), std::string::npos) << info.out;
    const ToolRun csv = Run("export-csv " + Quote(cap) + " --out " + Quote(dir_ / (name + ".csv")));
    EXPECT_EQ(csv.exit_code, 1) << csv.err;
    EXPECT_NE(csv.err.find(cap.string() + ": byte "), std::string::npos) << csv.err;
    const fs::path fixed = dir_ / ("fixed_" + name);
    const ToolRun repair = Run("repair " + Quote(cap) + " --out " + Quote(fixed));
    EXPECT_EQ(repair.exit_code, 0) << repair.err;
    const ToolRun again = Run("info " + Quote(fixed));
    EXPECT_EQ(again.exit_code, 0) << again.out << again.err;
    EXPECT_EQ(Run("export-csv " + Quote(fixed) + " --out " + Quote(dir_ / ("f_" + name + ".csv")))
                  .exit_code,
              0);
    EXPECT_EQ(CsvRows(dir_ / ("f_" + name + ".csv")), samples_);
  }
}

// `export-csv` went by the file name: a capture saved as "cap.dat" was refused, and a
// KTX2 texture saved as "x.bpc" (which info describes as a texture) was read as a capture with a
// damaged magic. It recognises files by content like every other command.
TEST_F(HostileCaptures, ExportCsvRecognisesCapturesByContent) {
  const fs::path renamed = Write("cap.dat", bytes_);
  const ToolRun ok = Run("export-csv " + Quote(renamed) + " --out " + Quote(dir_ / "dat.csv"));
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(CsvRows(dir_ / "dat.csv"), samples_);
  ASSERT_EQ(Run("convert " + Quote(dir_ / "cap.bpc") + " --quiet --formats ktx2 --out " +
                Quote(dir_ / "lut"))
                .exit_code,
            0);
  const fs::path texture = Write("texture.bpc", ReadAll(dir_ / "lut" / "cap.ktx2"));
  const std::string err =
      OneCleanLine(Run("export-csv " + Quote(texture) + " --out " + Quote(dir_ / "t.csv")));
  EXPECT_NE(err.find(texture.string() + ": a KTX2 texture"), std::string::npos) << err;
}

// `export-csv` of a capture without slices (cut right after its header) blamed the
// output it had not written ("h.csv: line 39: expected at least one data row after the
// header"). It names the capture, the byte where its slices should start and how to continue.
TEST_F(HostileCaptures, ExportCsvOfAnEmptyCaptureNamesTheCapture) {
  const fs::path head = Write("head.bpc", bytes_.substr(0, slices_[0].offset));
  const std::string err =
      OneCleanLine(Run("export-csv " + Quote(head) + " --out " + Quote(dir_ / "h.csv")));
  EXPECT_NE(err.find(head.string() + ": byte " + std::to_string(slices_[0].offset) + ": "),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("h.csv"), std::string::npos) << err;
  EXPECT_NE(err.find("--resume"), std::string::npos) << err;
}

// A damaged .exr environment map was refused with OpenEXR's sentence that repeats
// the file name ("x.exr: EXR content: expected a readable OpenEXR image, got Cannot read image
// file "x.exr". Early end of file: ..."). The line names the file once, and where the file
// breaks: a 1-byte file holds no OpenEXR signature.
TEST_F(HostileInputs, DamagedExrNamesTheFileOnce) {
  ASSERT_EQ(
      Run("convert " + Quote(kGoldMaterial) + " --quiet --formats exr --out " + Quote(dir_ / "lut"))
          .exit_code,
      0);
  const fs::path cut = dir_ / "cut.exr";
  WriteText(cut, ReadAll(dir_ / "lut" / "gold.exr").substr(0, 1));
  const std::string err =
      OneCleanLine(Run("preview " + Quote(kGoldMaterial) + " --env " + Quote(cut) +
                       " --size 8 --spp 1 --quiet --out " + Quote(dir_ / "p.png")));
  const std::size_t first = err.find(cut.string());
  ASSERT_NE(first, std::string::npos) << err;
  EXPECT_EQ(err.find(cut.string(), first + 1), std::string::npos) << err;
  EXPECT_NE(err.find("byte 0: expected the 8-byte OpenEXR signature"), std::string::npos) << err;
  EXPECT_NE(err.find("got a file of 1 byte"), std::string::npos) << err;
}

}  // namespace
}  // namespace brdf::tooltest
