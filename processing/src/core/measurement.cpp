#include "brdf/core/measurement.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <limits>

namespace brdf {

std::size_t Measurement::SampleCount() const {
  std::size_t n = 0;
  for (const auto& s : slices) n += s.samples.size();
  return n;
}

std::vector<double> Measurement::ThetaInDeg() const {
  std::vector<double> out;
  out.reserve(slices.size());
  for (const auto& s : slices) out.push_back(s.theta_in_deg);
  return out;
}

SliceStats ComputeSliceStats(const Slice& slice) {
  SliceStats st;
  st.theta_in_deg = slice.theta_in_deg;
  st.samples = slice.samples.size();
  st.complete = slice.complete;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double tmin = kInf, tmax = -kInf, pmin = kInf, pmax = -kInf;
  std::array<double, 3> lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf}, sum{};
  std::size_t valid = 0;
  for (const Sample& s : slice.samples) {
    tmin = std::min<double>(tmin, s.theta_out_deg);
    tmax = std::max<double>(tmax, s.theta_out_deg);
    pmin = std::min<double>(pmin, s.phi_out_deg);
    pmax = std::max<double>(pmax, s.phi_out_deg);
    for (int b = 0; b < 4; ++b)
      if (s.flags & (1u << b)) ++st.flag_counts[b];
    if (s.flags & kFlagInvalid) continue;
    ++valid;
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min<double>(lo[c], s.rgb[c]);
      hi[c] = std::max<double>(hi[c], s.rgb[c]);
      sum[c] += s.rgb[c];
    }
  }
  if (!slice.samples.empty()) {
    st.theta_out_min_deg = tmin;
    st.theta_out_max_deg = tmax;
    st.phi_out_min_deg = pmin;
    st.phi_out_max_deg = pmax;
  }
  if (valid > 0) {
    st.min = lo;
    st.max = hi;
    for (int c = 0; c < 3; ++c) st.mean[c] = sum[c] / static_cast<double>(valid);
  }
  return st;
}

std::string UtcNowIso8601() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buf;
}

const char* SoftwareVersion() { return BRDF_VERSION_STRING; }

}  // namespace brdf
