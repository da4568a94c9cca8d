// The white reference a capture is calibrated against.
//
// A scatterometer measures relative signal; f_r comes from comparing the sample's signal with
// that of a Lambertian panel of known reflectance ρ_w measured at the same incidence angle:
//   f_r = (C_s − dark)/t_s ÷ ((C_w − dark)/t_w) · ρ_w/π
// The panel's certificate gives ρ_w as a spectrum; the toolchain works in linear Rec.709 RGB,
// so the spectrum is reduced to one reflectance per channel. The reduced numbers live here,
// in the repository, with how they were computed, because the certificate file itself lives
// outside the repository (../shared/brdf-data/spectralon/).
#pragma once

#include <array>
#include <string_view>

namespace brdf::device {

struct WhiteReference {
  std::string_view name;        // for metadata: what panel, which certificate
  std::array<double, 3> rho{};  // directional-hemispherical reflectance, linear RGB, 0 … 1
  std::array<double, 3> rho_uncertainty{};  // the certificate's stated uncertainty, same bands
  std::string_view provenance;              // how `rho` was computed from the certificate
};

// The Spectralon panel of ../shared/brdf-data/spectralon/Spectralon_Num4.txt (8°/hemispherical
// calibration, 350–2500 nm at 1 nm, columns: wavelength_nm reflectance uncertainty).
// Reduction: the plain mean of the 100 rows of each band, 600 ≤ λ < 700 nm (R),
// 500 ≤ λ < 600 nm (G), 400 ≤ λ < 500 nm (B). A band mean is used instead of a CIE-weighted
// Rec.709 projection because the panel is flat to 0.15 % over 400–700 nm (0.9888 … 0.9903),
// so any weighting gives the same triple within a third of the certificate's ±0.5 %.
const WhiteReference& SpectralonWhiteReference();

}  // namespace brdf::device
