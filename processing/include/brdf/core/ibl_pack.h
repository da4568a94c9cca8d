// The image-based-lighting pack of a material: what an engine needs to light a BRDF with its own
// probes (an irradiance probe or SH, and a GGX-prefiltered radiance map), computed from any
// BrdfSource, so a LUT's pack follows the LUT's own evaluation rule (Lut::SampleAngles through
// LutBrdf or processing::MeasurementAsBrdf: its θin slices, reciprocity, extrapolation,
// whatever they are).
//
// For each view angle μ = cosθv of a table (kRows rows, μ_i = (i + 0.5)/kRows, texel centres:
// a linearly filtered 1D texture of kRows texels returns row i at u = μ_i):
//
//   E(μ)   = ∫_{H²} f_r(l, v) cosθl dω_l              directional albedo, RGB
//   E(μ)   = D(μ) + S(μ)                              broad and sharp parts
//   L_o(v) ≈ D(μ)·P(α_b, R_b) + S(μ)·P(α_eq(μ), R)    the split sum an engine evaluates
//
// with P(α, d) = ∫ L(l) K_α(d·l) dω the GGX-prefiltered radiance, the kernel every engine's
// probe filter applies (the split-sum prefilter with n = v = R, Karis 2013):
//
//   K_α(cosγ) = D_α(θh = γ/2) · max(cosγ, 0) / N_α,    N_α such that ∫ K_α dω = 1,
//
// R = 2(n·v)n − v, α_b (`broad_alpha`) one roughness per material and R_b = normalize(mix(R, n,
// α_b)). At α_b = 1, D_1 is constant and K_1 the normalised clamped cosine, so P(1, n) = Ē(n) =
// (1/π)∫ L(l) max(n·l, 0) dω, the irradiance over π: the broad lobe is then the diffuse-like
// part lit by the engine's irradiance probe or SH (what Lambert-like materials get), and below 1
// it is a clear coat's base lobe or a metal's broad skirt. Under a uniform radiance 1 every P is
// 1, so the split sum gives E(μ) exactly (white furnace).
//
// D_α the GGX distribution of docs/design.md §9 and γ the angle between d and l.
//
// How the numbers are found:
//  - Quadrature: for each view, a product grid over the light hemisphere in the normal frame
//    (so the horizon is an edge of the grid): kThetaSteps nodes in θl ∈ [0°, 90°] and kPhiSteps
//    in φl ∈ [0°, 360°), each axis a midpoint rule mapped through a smooth density that puts
//    30 % of its nodes in a Gaussian of σ ≈ 6° around the mirror direction R = (θv, 180°)
//    (σ/sinθv in φ), where lobes are narrow; weight sinθl·cosθl·dθ·dφ over the density.
//    Integrand f_r from BrdfSource::Eval (for a LutBrdf, Lut::SampleAngles's rule applied to
//    the grid's angles directly, its trigonometry shared between the samples of a row through
//    Lut::SampleTextureFrame: the same values without the vectors' trigonometry). Against NumPy's
//    midpoint rule of `brdf eval` of the same file on a uniform 0.5° × 1° grid
//    (tests/python/ibl_albedo_check.py, a 4-slice and a 6-slice capture) every channel agrees
//    within 0.2 % (test bound 0.5 %; part of the difference is NumPy's own, which moves by
//    0.05 % when its grid is refined 5 ×), and the albedo of analytic GGX materials agrees with
//    a 1500 × 1440 brute-force sum within 0.21 % (test bound 0.3 %,
//    tests/core/ibl_pack_test.cpp). The largest errors are at grazing views (μ < 0.1), where
//    the lobe meets the horizon and a LUT's value jumps at its last slice (docs/design.md §5);
//    elsewhere they are below 0.15 %.
//  - The split, α_eq and α_b: the lobe w(l) = f_r(l, v)·cosθl is lit by the environments
//    P_ℓ(l·a), Legendre polynomials of degree ℓ = 0…kMaxBand centred on the normal (a = n) and
//    on the mirror direction (a = R): rings of every angular frequency around the two
//    directions the engine's probes are looked up at. Its responses t_{a,ℓ} = ∫ w P_ℓ(l·a)dω
//    are compared with the model's, which are closed-form (Funk–Hecke): D·κ_ℓ(α_b)·P_ℓ(a·R_b)
//    + S·κ_ℓ(α)·P_ℓ(a·R), κ_ℓ(α) = 2π∫ K_α(t) P_ℓ(t) dt (κ_ℓ(1) = A_ℓ/π, the clamped cosine's
//    Legendre coefficients). ℓ = 0 is matched exactly (D + S = E). For a given α_b, α_eq per
//    row minimises Σ_{a,ℓ≥1} (2ℓ+1)·(t_{a,ℓ} − model)² (the squared L² distance of the two
//    lobes' zonal parts about a), with S by least squares for each α (clamped to 0 ≤ S ≤ E),
//    over α in [kMinAlpha, α_b] on the luminance; α_b minimises the sum over the rows of that
//    criterion relative to Σ (2ℓ+1) t² (each view counts alike), searched on the κ table's
//    grid in [0.02, 0.75] and 1 (every 6th node, then the 2 either side of the best; grid-only
//    α_eq during the search); then α_eq refined and S and D per channel at it. The relative
//    residual at α_eq is kept per row: a lobe that two GGX kernels do not fit
//    (off-specular, retro-reflective) says so there.
// Rows with E = 0 (a black material, or a view where the source is zero) get S = D = 0 and
// α_eq = 1 (with any α_b).
//
// What an engine reads (one pack fetch per pixel, two probe fetches): the broad part D as a
// quadratic in t = 1 − μ, D_fit(μ) = c0 + c1·t + c2·t², three RGB constants per material fitted by
// least squares, per channel, to the split's D rows (`diffuse`); and per row S_i = E_i − D_fit(μ_i)
// (`specular`, stored with α_eq in one texel), so that D_fit + S = E exactly at every texel
// centre and the white furnace holds whatever the quadratic's error. S_i may then be slightly
// negative where D_fit lies above E (a Lambertian's S is D_i − D_fit(μ_i), rounding-small);
// clamping it would trade the furnace's exactness for a sign. Between texel centres S is
// linear and D_fit quadratic: D_fit + S departs from the linear E by at most |c2|·Δt²/4,
// Δt = 1/kRows (|c2|/16384).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/models.h"

namespace brdf {

struct IblPack {
  static constexpr int kRows = 64;
  static constexpr int kThetaSteps = 64;  // quadrature nodes in θl per view
  static constexpr int kPhiSteps = 72;    // and in φl
  static constexpr int kMaxBand = 48;     // Legendre degrees ℓ = 0…kMaxBand of the fit
  static constexpr double kMinAlpha = 0.005;

  std::vector<double> mu;                  // μ_i = (i + 0.5)/kRows
  std::vector<Rgb> albedo;                 // E(μ), 1 (no unit: reflected over incident)
  std::vector<Rgb> diffuse;                // D(μ_i) of the split (what the quadratic is fitted to)
  std::vector<Rgb> specular;               // S_i = E_i − D_fit(μ_i), weight of P(α_eq, R)
  std::array<Rgb, 3> diffuse_quadratic{};  // c0, c1, c2 of D_fit(μ) = c0 + c1·t + c2·t², t = 1 − μ
  std::vector<double> alpha;               // α_eq(μ)
  std::vector<double> residual;            // relative residual of the fit per row (see above)
  double broad_alpha = 1.0;                // α_b of the broad lobe (1: the clamped cosine), D's
                                           // kernel, read about mix(R, n, α_b)

  // D_fit at `mu` (the quadratic of diffuse_quadratic; `mu` as given, no clamping).
  Rgb DiffuseFit(double mu) const;

  // One row at `mu` as an engine reads it: albedo, specular and alpha as a linearly filtered
  // texture of kRows texels with clamp to edge returns them (linear between μ_i, constant
  // beyond μ_0 and μ_{kRows−1}), diffuse = D_fit at `mu` clamped to [μ_0, μ_{kRows−1}] (the
  // texture coordinate the shader computes), so diffuse + specular = albedo at texel centres.
  struct Row {
    Rgb albedo, diffuse, specular;
    double alpha = 1.0;
  };
  Row At(double mu) const;
};

// The dominant-direction shift of the specular lookup: engines read the prefiltered probe at
// R' = normalize(mix(R, n, s)), s = IblSpecularShift(α_eq(μ), μ) = α_eq·(1 − μ) (0 near the
// normal, where the split sum's n = v = R holds; toward n for rough lobes at oblique views,
// where the horizon clips the lobe and its centre moves off R). Chosen against the true
// environment-lit preview (docs/benchmarks/ibl.md, "Dominant direction").
double IblSpecularShift(double alpha_eq, double mu);
// R' for the unit normal n and unit view v (pointing away from the surface).
Vec3 IblSpecularDirection(const Vec3& n, const Vec3& v, double alpha_eq);

// The broad lobe's lookup direction R_b = normalize(mix(R, n, α_b)) (n at α_b = 1).
Vec3 IblBroadDirection(const Vec3& n, const Vec3& v, double broad_alpha);

// Computes the pack of `source`: 64 × 64 × 72 = 294,912 evaluations of the source and the fit,
// on the calling thread (docs/benchmarks/ibl.md).
IblPack ComputeIblPack(const BrdfSource& source);

// κ_ℓ(α) = 2π∫ K_α(t) P_ℓ(t) dt for ℓ = 0…IblPack::kMaxBand (κ_0 = 1), interpolated in log α
// from a table computed once per process (α clamped to [kMinAlpha, 1]).
std::array<double, IblPack::kMaxBand + 1> GgxPrefilterLegendre(double alpha);

// The pack as the JSON object documented in docs/engines.md ("ibl"): {"mu": [...],
// "albedo_rgb": [[r, g, b], ...], "diffuse_rgb": ..., "specular_rgb": ..., "alpha_eq": [...],
// "diffuse_quadratic_rgb": [c0, c1, c2] (each [r, g, b]), "fit_residual": [...],
// "convention": ...}.
std::string IblPackJson(const IblPack& pack);

}  // namespace brdf
