// Interpolation of one measurement slice over the outgoing direction, used by BuildLut (every
// evaluation of a capture goes through the LUT it builds, measurement_brdf.h).
// The methods are described in resample.h and docs/resampling.md.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/core/measurement.h"
#include "brdf/core/models.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/processing/resample.h"

namespace brdf::processing::detail {

// One valid sample after normalisation: θ ∈ [0°, 90°], φ ∈ [0°, 360°) relative to φin.
struct Point {
  double theta_deg = 0, phi_deg = 0;
  Rgb value{};
};

struct CleanSlice {
  std::vector<Point> points;
  std::size_t invalid = 0;
  double max_theta_deg = 0;
};

// Drops kFlagInvalid samples, normalises angles and validates the rest. `slice_index` only
// names the slice in messages. Throws InvalidArgument.
CleanSlice CleanSliceSamples(const Slice& slice, std::size_t slice_index,
                             bool check_measured_values = true);

// Why a sample not flagged invalid cannot be used ("θout outside [−90°, 90°]", "red value not a
// finite number", a value no surface has: docs/design.md §4), or nullptr. The one rule of
// CleanSliceSamples and FindLutInputProblems. `negative_allowance` is the slice's
// (NegativeAllowance; a sample's own 5σ widens it); nullopt leaves the values no surface has
// unchecked (ResampleOptions::check_measured_values).
const char* SampleDefect(const Sample& sample, std::optional<double> negative_allowance);

// How far below zero a value of `slice` may lie and still be noise around zero (1/sr):
// kNegativeFractionOfPeak of the slice's largest plausible value, at least kNegativeFloorPerSr.
double NegativeAllowance(const Slice& slice);

// Validates the slice's own θin (finite, [0°, 90°)). Throws InvalidArgument.
void CheckSliceThetaIn(const Slice& slice, std::size_t slice_index);

// Moving least squares on the unit sphere: k nearest samples by chord distance (uniform 3D
// cell grid), Wendland C2 weights with radius = distance of the k-th neighbour, linear fit in
// the tangent plane of the query, result limited to the neighbours' value range.
class ScatteredInterpolator {
 public:
  ScatteredInterpolator(const std::vector<Point>& points, int neighbours);
  Rgb At(const Vec3& q) const;

 private:
  int k_ = 0;
  double cell_ = 1.0;
  double origin_[3] = {0, 0, 0};
  int dims_[3] = {1, 1, 1};
  std::vector<std::uint32_t> cell_start_;  // CSR over cells, size cells + 1
  std::vector<Vec3> pos_;                  // samples ordered by cell
  std::vector<Rgb> val_;
};

// Values on the lattice θ = j·Δθ (j = 0…Nθ−1, row 0 the pole, every column of row 0 holding
// the same averaged value), φ = φ0 + i·Δφ (i = 0…Nφ−1, Δφ = 360°/Nφ).
struct RegularGrid {
  int n_theta = 0, n_phi = 0;
  double d_theta = 1, d_phi = 1, phi0 = 0;
  double inv_d_theta = 1, inv_d_phi = 1;
  std::vector<double> values;  // (j·Nφ + i)·3 + c

  // Bilinear in (θ, φ); φ wraps across the seam; θ beyond the last row clamps to it.
  Rgb At(double theta_deg, double phi_deg) const {
    double tj = theta_deg * inv_d_theta;
    int j0;
    double ft;
    if (tj >= n_theta - 1) {
      j0 = n_theta - 2;
      ft = 1.0;
    } else {
      if (tj < 0) tj = 0;
      j0 = static_cast<int>(tj);
      ft = tj - j0;
    }
    double u = (phi_deg - phi0) * inv_d_phi;
    if (u < 0.0) u += n_phi;  // φ ∈ [0°, 360°) and φ0 within one step of 0°: one wrap is enough
    if (!(u >= 0.0 && u < n_phi)) u -= std::floor(u / n_phi) * n_phi;
    int i0 = static_cast<int>(u);
    if (i0 >= n_phi) i0 = 0;  // u rounded up to exactly Nφ
    const double fu = u - i0;
    const int i1 = i0 + 1 == n_phi ? 0 : i0 + 1;
    const double* r0 = &values[static_cast<std::size_t>(j0) * n_phi * 3];
    const double* r1 = r0 + static_cast<std::size_t>(n_phi) * 3;
    Rgb out;
    for (int c = 0; c < 3; ++c) {
      const double a = r0[i0 * 3 + c] + (r0[i1 * 3 + c] - r0[i0 * 3 + c]) * fu;
      const double b = r1[i0 * 3 + c] + (r1[i1 * 3 + c] - r1[i0 * 3 + c]) * fu;
      out[c] = a + (b - a) * ft;
    }
    return out;
  }
};

// Lattice detection. Returns nullopt if the points are not on a lattice as above or more than
// half of its nodes are empty. Empty nodes are listed in `holes` (node index j·Nφ + i) and
// hold 0 until filled.
std::optional<RegularGrid> DetectRegularGrid(const std::vector<Point>& points,
                                             std::vector<std::size_t>& holes);

// The interpolant of one slice plus its horizon ring at θb.
class SliceInterpolator {
 public:
  SliceInterpolator(const Slice& slice, std::size_t slice_index, const ResampleOptions& options);

  // f at the direction (θ, φ) (degrees, φ relative to φin = 0) whose unit vector is `dir`.
  Rgb At(double theta_deg, double phi_deg, const Vec3& dir) const {
    return grid_ ? grid_->At(theta_deg, phi_deg) : scattered_->At(dir);
  }

  // Precomputes what Horizon needs; call once θb of the whole measurement is known.
  void PrepareHorizon(double theta_b_deg);
  // f at (θb, φ): exact on the regular grid; from a 0.1° ring table for the scattered method.
  Rgb Horizon(double phi_deg) const {
    return grid_ ? grid_->At(theta_b_deg_, phi_deg) : RingAt(phi_deg);
  }
  // Mean of f(θb, φ) over the full circle of φ: the value for the nadir, where all φ meet.
  const Rgb& HorizonMean() const { return horizon_mean_; }

  const SliceResampleReport& report() const { return report_; }

 private:
  Rgb RingAt(double phi_deg) const;

  std::optional<RegularGrid> grid_;
  std::unique_ptr<ScatteredInterpolator> scattered_;
  double theta_b_deg_ = 0;
  std::vector<Rgb> ring_;  // scattered only: f(θb, n·360°/ring_.size())
  Rgb horizon_mean_{};
  SliceResampleReport report_;
};

}  // namespace brdf::processing::detail
