// MERL `.binary` reading, evaluation, writing and identification: see brdf/core/merl.h.
#include "brdf/core/merl.h"

#include <bit>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/core/sha256.h"

namespace brdf {
namespace {

constexpr std::array<const char*, 3> kPlaneNames = {"red", "green", "blue"};
constexpr std::array<int, 3> kDims = {kMerlThetaHalfBins, kMerlThetaDiffBins, kMerlPhiDiffBins};
constexpr std::array<const char*, 3> kDimNames = {"theta_half", "theta_diff", "phi_diff"};

// floor(x) clamped to [0, n−1]; NaN maps to 0.
inline int BinIndex(double x, int n) {
  return x >= 0.0 ? (x < n ? static_cast<int>(x) : n - 1) : 0;
}

std::string DescribeBin(std::size_t plane_index) {
  const std::size_t phi_d = plane_index % kMerlPhiDiffBins;
  const std::size_t theta_d = (plane_index / kMerlPhiDiffBins) % kMerlThetaDiffBins;
  const std::size_t theta_h = plane_index / (kMerlPhiDiffBins * kMerlThetaDiffBins);
  return "bin theta_half " + std::to_string(theta_h) + ", theta_diff " + std::to_string(theta_d) +
         ", phi_diff " + std::to_string(phi_d);
}

}  // namespace

MerlBin MerlBinOf(const Vec3& wi, const Vec3& wo) {
  const Vec3 h = Normalize(wi + wo);
  const double theta_h = std::acos(h.z < 1.0 ? h.z : 1.0);
  const double phi_h = std::atan2(h.y, h.x);
  // The "difference" vector: ωi expressed in the frame where h is the pole, i.e. ωi rotated
  // by −φh about the normal, then by −θh about the binormal (Rusinkiewicz 1998).
  const double cp = std::cos(phi_h), sp = std::sin(phi_h);
  const double ct = std::cos(theta_h), st = std::sin(theta_h);
  const double x1 = cp * wi.x + sp * wi.y, y1 = cp * wi.y - sp * wi.x, z1 = wi.z;
  const double dx = ct * x1 - st * z1, dy = y1, dz = st * x1 + ct * z1;
  const double theta_d = std::acos(dz > 1.0 ? 1.0 : (dz < -1.0 ? -1.0 : dz));
  double phi_d = std::atan2(dy, dx);
  if (phi_d < 0.0) phi_d += kPi;  // reciprocity: φd and φd + π are the same bin
  MerlBin bin;
  bin.theta_half = theta_h > 0.0 ? BinIndex(std::sqrt(theta_h / (kPi / 2)) * kMerlThetaHalfBins,
                                            kMerlThetaHalfBins)
                                 : 0;
  bin.theta_diff = BinIndex(theta_d / (kPi / 2) * kMerlThetaDiffBins, kMerlThetaDiffBins);
  bin.phi_diff = BinIndex(phi_d / kPi * kMerlPhiDiffBins, kMerlPhiDiffBins);
  return bin;
}

void MerlBinCenter(const MerlBin& bin, Vec3& wi, Vec3& wo) {
  const double t = (bin.theta_half + 0.5) / kMerlThetaHalfBins;
  const double theta_h = (kPi / 2) * t * t;
  const double theta_d = (bin.theta_diff + 0.5) * (kPi / 2) / kMerlThetaDiffBins;
  const double phi_d = (bin.phi_diff + 0.5) * kPi / kMerlPhiDiffBins;
  const Vec3 d = SphericalDirection(theta_d, phi_d);
  // Undo the rotation of MerlBinOf with φh = 0: rotate by +θh about the binormal.
  const double ct = std::cos(theta_h), st = std::sin(theta_h);
  wi = {ct * d.x + st * d.z, d.y, -st * d.x + ct * d.z};
  const Vec3 h{st, 0.0, ct};
  wo = h * (2.0 * Dot(wi, h)) - wi;
}

MerlBrdf MerlBrdf::FromBytes(std::span<const std::uint8_t> bytes, std::string file) {
  if (bytes.size() < 12)
    throw FormatError(file, BytePosition(0),
                      "a 12-byte header of three int32 (90, 90, 180), then 3 x 1458000 float64",
                      std::to_string(bytes.size()) + " bytes in the file");
  ByteReader r(bytes.data(), bytes.size(), file);
  for (int k = 0; k < 3; ++k) {
    const std::uint64_t at = r.offset();
    const std::int32_t dim = r.I32("the header");
    if (dim != kDims[k])
      throw FormatError(file, BytePosition(at),
                        "header dimension " + std::to_string(k) + " (" + kDimNames[k] +
                            " bins) = " + std::to_string(kDims[k]),
                        std::to_string(dim),
                        "a MERL .binary file starts with the int32 values 90, 90, 180");
  }
  if (bytes.size() != kMerlFileBytes)
    throw FormatError(
        file, "file size",
        std::to_string(kMerlFileBytes) + " bytes (12-byte header + 3 x 1458000 float64 values)",
        std::to_string(bytes.size()) + " bytes",
        bytes.size() < kMerlFileBytes ? "the file is truncated" : "trailing data after the table");
  MerlBrdf out;
  out.name_ = std::filesystem::path(file).filename().string();
  out.values_.resize(3 * kMerlBinsPerChannel);
  for (std::size_t c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < kMerlBinsPerChannel; ++i) {
      const std::uint64_t at = r.offset();
      const double raw = r.F64("a value");
      if (!std::isfinite(raw))
        throw FormatError(
            file, BytePosition(at) + " (" + kPlaneNames[c] + " plane, " + DescribeBin(i) + ")",
            "a finite value (negative marks 'not measured')",
            std::isnan(raw) ? "NaN" : (raw > 0 ? "+inf" : "-inf"));
      if (raw < 0.0) ++out.info_.unmeasured_bins[c];
      out.values_[c * kMerlBinsPerChannel + i] = raw < 0.0 ? -1.0 : raw * kMerlScale[c];
    }
  }
  return out;
}

MerlBrdf MerlBrdf::Load(const std::string& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path, kMerlFileBytes);
  return FromBytes(bytes, path);
}

Rgb MerlBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return {0.0, 0.0, 0.0};
  if (!std::isfinite(wi.x + wi.y + wi.z + wo.x + wo.y + wo.z)) return {0.0, 0.0, 0.0};
  const std::size_t i = MerlBinOf(wi, wo).Index();
  Rgb f;
  for (std::size_t c = 0; c < 3; ++c) {
    const double v = values_[c * kMerlBinsPerChannel + i];
    f[c] = v > 0.0 ? v : 0.0;
  }
  return f;
}

bool MerlBrdf::IsMeasured(const Vec3& wi, const Vec3& wo) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return false;
  if (!std::isfinite(wi.x + wi.y + wi.z + wo.x + wo.y + wo.z)) return false;
  const std::size_t i = MerlBinOf(wi, wo).Index();
  for (std::size_t c = 0; c < 3; ++c)
    if (values_[c * kMerlBinsPerChannel + i] < 0.0) return false;
  return true;
}

std::string EncodeMerlBinary(const BrdfSource& source) {
  std::string out;
  out.reserve(kMerlFileBytes);
  for (const int d : kDims) AppendU32(out, static_cast<std::uint32_t>(d));
  std::vector<double> planes(3 * kMerlBinsPerChannel, -1.0);
  MerlBin bin;
  for (bin.theta_half = 0; bin.theta_half < kMerlThetaHalfBins; ++bin.theta_half) {
    for (bin.theta_diff = 0; bin.theta_diff < kMerlThetaDiffBins; ++bin.theta_diff) {
      for (bin.phi_diff = 0; bin.phi_diff < kMerlPhiDiffBins; ++bin.phi_diff) {
        Vec3 wi, wo;
        MerlBinCenter(bin, wi, wo);
        if (!(wi.z > 0.0) || !(wo.z > 0.0)) continue;
        const Rgb f = source.Eval(wi, wo);
        for (std::size_t c = 0; c < 3; ++c)
          if (std::isfinite(f[c]))
            planes[c * kMerlBinsPerChannel + bin.Index()] = f[c] / kMerlScale[c];
      }
    }
  }
  for (const double v : planes) AppendU64(out, std::bit_cast<std::uint64_t>(v));
  return out;
}

void WriteMerlBinary(const std::string& path, const BrdfSource& source) {
  WriteFileAtomically(path, EncodeMerlBinary(source));
}

std::vector<MerlDigest> ReadMerlDigestTable(const std::string& path) {
  std::string table = path;
  if (table.empty()) {
    const char* env = std::getenv("BRDF_MERL_SHA256_TABLE");
    if (env == nullptr || *env == '\0')
      throw InvalidArgument(
          "no MERL SHA-256 table given: pass its path or set BRDF_MERL_SHA256_TABLE "
          "(../shared/brdf-data/reference/merl_binary_sha256.tsv)");
    table = env;
  }
  return ParseMerlDigestTable(ReadFileText(table, 1u << 20), table);
}

std::vector<MerlDigest> ParseMerlDigestTable(std::string_view text, const std::string& table) {
  std::vector<MerlDigest> out;
  std::size_t start = 0;
  for (std::uint64_t line_no = 1; start < text.size(); ++line_no) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line(text.substr(start, end - start));
    start = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::size_t t1 = line.find('\t');
    const std::size_t t2 = t1 == std::string::npos ? t1 : line.find('\t', t1 + 1);
    auto fail = [&](const std::string& expected) {
      throw FormatError(table, LinePosition(line_no), expected,
                        "\"" + line.substr(0, 100) + (line.size() > 100 ? "...\"" : "\""));
    };
    if (t2 == std::string::npos || line.find('\t', t2 + 1) != std::string::npos)
      fail("material<TAB>size_bytes<TAB>sha256 (three tab-separated fields)");
    MerlDigest d;
    d.material = line.substr(0, t1);
    const std::string size = line.substr(t1 + 1, t2 - t1 - 1);
    d.sha256 = line.substr(t2 + 1);
    if (d.material.empty()) fail("a material name in the first field");
    if (size.empty() || size.size() > 19 ||
        size.find_first_not_of("0123456789") != std::string::npos)
      fail("a decimal byte count in the second field");
    d.size_bytes = std::stoull(size);
    for (char& ch : d.sha256)
      if (ch >= 'A' && ch <= 'F') ch = static_cast<char>(ch - 'A' + 'a');
    if (d.sha256.size() != 64 ||
        d.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
      fail("64 hexadecimal digits of SHA-256 in the third field");
    out.push_back(std::move(d));
  }
  return out;
}

std::optional<std::string> IdentifyMerlFile(const std::string& merl_path,
                                            const std::string& table_path) {
  const std::vector<MerlDigest> table = ReadMerlDigestTable(table_path);
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(merl_path, ec);
  if (ec) throw IoError(merl_path + ": cannot read size: " + ec.message());
  bool candidate = false;
  for (const MerlDigest& d : table) candidate |= d.size_bytes == size;
  if (!candidate) return std::nullopt;  // no published file has this size: skip hashing
  const std::string sha = Sha256HexOfFile(merl_path);
  for (const MerlDigest& d : table)
    if (d.size_bytes == size && d.sha256 == sha) return d.material;
  return std::nullopt;
}

}  // namespace brdf
