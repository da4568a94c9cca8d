// The measurement point cloud: what an instrument captured, before any resampling.
//
// A Measurement is a list of slices, one per incidence angle θin, each holding the samples
// captured with that light direction. Angles are stored in degrees exactly as the instrument
// reports them (float32, so a .bpc round trip is bit-exact); values are f_r in 1/sr, linear
// RGB, never multiplied by cosθ. Isotropic captures use φin = 0 (light in the +x half of the
// xz-plane, docs/design.md §4).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace brdf {

// Per-sample quality flags (bit mask). Values are part of the .bpc format: never renumber.
enum SampleFlag : std::uint8_t {
  kFlagSaturated = 1u << 0,        // the raw detector signal clipped at ADC full scale
  kFlagBelowNoiseFloor = 1u << 1,  // signal under the instrument's noise floor
  kFlagInterpolated = 1u << 2,     // value filled in by software, not measured
  kFlagInvalid = 1u << 3,          // no usable value (blind spot, hardware fault)
};
inline constexpr std::uint8_t kKnownSampleFlags = 0x0f;

struct Sample {
  float theta_in_deg = 0, phi_in_deg = 0, theta_out_deg = 0, phi_out_deg = 0;
  std::array<float, 3> rgb{};    // f_r, 1/sr
  std::array<float, 3> sigma{};  // one-standard-deviation uncertainty of rgb, 1/sr (0 if unknown)
  std::uint8_t flags = 0;
};

struct Slice {
  double theta_in_deg = 0;
  double phi_in_deg = 0;
  bool has_sigma = false;  // whether Sample::sigma carries information
  bool complete = true;    // false for a slice whose capture was interrupted
  std::vector<Sample> samples;
};

struct Metadata {
  std::string sample_name;
  std::string instrument_model;
  std::string instrument_serial;
  std::string firmware_version;
  std::string protocol_version;
  std::string calibration_reference;  // e.g. "Spectralon SRS-99 (shared/brdf-data/spectralon)"
  std::string calibration_time;       // ISO 8601 UTC
  std::string capture_start;          // ISO 8601 UTC
  std::string capture_end;            // ISO 8601 UTC; empty while a capture is in progress
  std::string operator_notes;
  std::string units = "1/sr";
  std::string software_version;
  std::map<std::string, std::string> extra;  // anything else worth keeping (source file, seed)
};

struct Measurement {
  Metadata metadata;
  std::vector<Slice> slices;  // ascending θin for instrument captures

  std::size_t SampleCount() const;
  std::vector<double> ThetaInDeg() const;
};

// Summary statistics used by `brdf info`.
struct SliceStats {
  double theta_in_deg = 0;
  std::size_t samples = 0;
  bool complete = true;
  double theta_out_min_deg = 0, theta_out_max_deg = 0;
  double phi_out_min_deg = 0, phi_out_max_deg = 0;
  std::array<double, 3> min{}, max{}, mean{};  // over samples without kFlagInvalid
  std::array<std::size_t, 4> flag_counts{};  // saturated, below noise floor, interpolated, invalid
};
SliceStats ComputeSliceStats(const Slice& slice);

// The metadata as the JSON object the .bpc header stores (docs/formats/bpc.md), as text.
std::string MetadataToJsonText(const Metadata& metadata);

// ISO 8601 UTC timestamp of now, to the second ("2026-11-22T10:04:05Z").
std::string UtcNowIso8601();

// The toolchain's version string, recorded in every file it writes.
const char* SoftwareVersion();

}  // namespace brdf
