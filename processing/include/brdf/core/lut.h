// The exported asset in memory: K slices of the specular-frame LUT of docs/design.md §5.
//
// Slice k holds f(θin,k, ω_out) sampled at texel centres (φd = i·1°, i = 0…360; θd = j·1°,
// j = 0…180) of the specular frame S(θin,k); column 360 repeats column 0. Values are f_r in
// 1/sr, linear RGB. Storage is float RGB, index ((k·181 + j)·361 + i)·3 + c.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace brdf {

struct Lut {
  static constexpr int kWidth = 361;   // Nφ
  static constexpr int kHeight = 181;  // Nθ
  static constexpr double kTexelDeg = 1.0;
  // A light polar angle within this of the measured θin range counts as inside it (no
  // exchange, no warning): float32 angles, and a shader's, agree with the measured ones to
  // about 1e-5°.
  static constexpr double kThetaInToleranceDeg = 1e-3;

  std::vector<double> theta_in_deg;  // K values, k·Δin
  std::vector<float> texels;         // K × 181 × 361 × 3

  int slices() const { return static_cast<int>(theta_in_deg.size()); }
  // Δin in degrees (theta_in_deg[1] - theta_in_deg[0]; 0 for a single slice).
  double DeltaInDeg() const;

  void Resize(std::size_t k) {
    theta_in_deg.resize(k);
    texels.assign(k * kHeight * kWidth * 3, 0.0f);
  }
  std::size_t Index(int k, int j, int i) const {
    return ((static_cast<std::size_t>(k) * kHeight + j) * kWidth + i) * 3;
  }
  float* Texel(int k, int j, int i) { return &texels[Index(k, j, i)]; }
  const float* Texel(int k, int j, int i) const { return &texels[Index(k, j, i)]; }

  // Samples the LUT exactly as a GPU samples the 3D texture: normalised coordinates
  // u = (φd/1° + 0.5)/361, v = (θd/1° + 0.5)/181, w = (θin/Δin + 0.5)/K, trilinear filtering,
  // clamp-to-edge addressing.
  std::array<float, 3> SampleTrilinear(double u, double v, double w) const;
  // The BRDF the LUT stands for, from angles (degrees): light at (θin, 0), ω_out given by
  // (θout, φout). This is the one evaluation rule of docs/design.md §5 that `brdf eval`, the
  // preview, the viewer and the shipped shaders all apply:
  //  1. Reciprocity beyond the measured θin range: when ExchangesLightAndView(θin, θout), the
  //     query is answered as the one with light and view exchanged, f(θout → θin) with the
  //     relative azimuth −φout (f(ωi, ωo) = f(ωo, ωi)). For a light beyond the last slice and
  //     a view inside the measured θin range this reads a measured value instead of a clamped
  //     one.
  //  2. The texture lookup: ω_d = S(θin)·ω_out, then SampleTrilinear at the centre-exact
  //     coordinates above. θin between two slices interpolates linearly between them at the
  //     same specular-frame coordinates (θd, φd); θin outside [θin,0, θin,K−1] takes the
  //     nearest slice (clamp-to-edge). A θin list that is not k·Δin (an evaluation-only LUT,
  //     see processing::ResampleOptions) is interpolated the same way between its neighbours.
  std::array<float, 3> SampleAngles(double theta_in_deg, double theta_out_deg,
                                    double phi_out_deg) const;
  // Step 1 of SampleAngles: true when θin lies outside [θin,0, θin,K−1] and θout lies nearer to
  // that range than θin does (inside it, or outside by less). For a k·Δin LUT that is
  // θin > θin,K−1 and θout < θin.
  bool ExchangesLightAndView(double theta_in_deg, double theta_out_deg) const;
  // Step 2 alone: the texture lookup at (θin, θout, φout), no exchange.
  std::array<float, 3> SampleTexture(double theta_in_deg, double theta_out_deg,
                                     double phi_out_deg) const;
  // SampleTexture with the caller's trigonometry, for loops that share it between samples
  // (the IBL pack's grid): the light's cos θin and sin θin, its SliceCoordinate, and ω_out =
  // (x, y, z) as SphericalDirectionDeg(θout, φout) gives it. The same arithmetic as
  // SampleTexture from there on, so equal inputs give the same bits.
  std::array<float, 3> SampleTextureFrame(double cos_in, double sin_in, double slice, double x,
                                          double y, double z) const;
  // The normalised coordinates (u, v, w) SampleTexture and SampleTextureFrame pass to
  // SampleTrilinear: they depend on the θin list alone, not on the texels, so a loop that reads
  // the same places of many LUTs (the blind-spot fill of a batch) computes them once.
  std::array<double, 3> TextureCoordinates(double theta_in_deg, double theta_out_deg,
                                           double phi_out_deg) const;
  std::array<double, 3> TextureCoordinatesFrame(double cos_in, double sin_in, double slice,
                                                double x, double y, double z) const;
  // The fractional slice coordinate of `theta_in_deg` (k + t), before clamping: θin/Δin for a
  // k·Δin list, piecewise linear between entries otherwise.
  double SliceCoordinate(double theta_in_deg) const;
};

}  // namespace brdf
