// What the viewer shows of one BRDF source: its LUT (docs/design.md §5, the asset an engine
// samples) and, when the source was a measurement, which outgoing directions were actually
// measured.
//
// Every picture in brdf-view (lobes, slice heat maps) is drawn from the LUT and sampled the way
// a GPU samples it (brdf::Lut::SampleAngles: trilinear in the specular frame, so a θin between
// two measured slices shows the lobe the LUT interpolates, with its peak following the mirror
// direction). Sources are opened by brdf::sources::OpenForView (brdf/sources/open.h, called by
// tools/brdf-view), which reads and resamples each once; this header only turns what it
// returns into a ViewSource. No VTK here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "brdf/core/brdf_source.h"
#include "brdf/core/lut.h"
#include "brdf/core/measurement.h"
#include "brdf/processing/extrapolation.h"
#include "brdf/processing/resample.h"

namespace brdf::viewer {

// Where a value at an outgoing direction came from.
enum class Coverage : std::uint8_t {
  kMeasured,      // interpolated from measured samples (θout ≤ θb, a valid sample nearby)
  kExtrapolated,  // θb < θout: the docs/design.md §6 grazing extrapolation
  kUnmeasured,    // θout ≤ θb but no valid sample nearby (blind spot, samples flagged invalid)
};
const char* CoverageName(Coverage coverage);  // "measured", "extrapolated", "unmeasured"

// Per-slice map of measured outgoing directions on a 1° grid in the measurement frame:
// cell (t, p) covers θout ∈ [t − ½°, t + ½°), φout ∈ [p − ½°, p + ½°), t = 0…90, p = 0…359.
struct CoverageMap {
  static constexpr int kThetaCells = 91;
  static constexpr int kPhiCells = 360;
  double theta_in_deg = 0;
  std::vector<std::uint8_t> measured;  // kThetaCells × kPhiCells, 1 = a valid sample nearby
  // A slice the blind-spot fill added (brdf/processing/beyond.h: inserted between measured
  // slices or extrapolated past the last one): no direction of it was measured, and the
  // viewer draws it as it draws the §6 band (translucent). `measured` is all 0 then.
  bool filled = false;

  bool MeasuredAt(double theta_out_deg, double phi_out_deg) const;
};

struct ViewSource {
  std::string name;  // shown in the window ("gold", "ibiza.bpc")
  Lut lut;
  // Last measured polar angle θb (degrees); beyond it the LUT holds the §6 extrapolation.
  // 90 when unknown (an exported LUT without a sidecar).
  double theta_b_deg = 90;
  // One map per LUT slice (same order) when the source was a measurement; empty otherwise,
  // in which case every direction up to θb counts as measured.
  std::vector<CoverageMap> coverage;
  std::vector<std::string> warnings;  // from opening the source, shown in the window

  // Coverage of the outgoing direction (θout, φout) in degrees for light at (θin, 0). Between
  // two slices a direction is unmeasured when it is unmeasured in either neighbour (the LUT
  // blends both); a filled slice (CoverageMap::filled) counts as extrapolated wherever its
  // weight is not zero.
  Coverage CoverageAt(double theta_in_deg, double theta_out_deg, double phi_out_deg) const;
  // The channel maximum over every texel of the LUT with θout ≤ 90° (a fixed scale for the
  // legend while θin moves). Channel index 0–2 = R, G, B; 3 = luminance.
  double MaxValue(int channel) const;
};

// A measurement (capture, imported table, noise-free capture of a material) and the LUT that
// processing::BuildLut made of it, with its report: coverage from the measurement's valid
// samples (a sample covers the 1° cells within its lattice step, or within 1° for scattered
// data). LUT slices the measurement does not have are the blind-spot fill's (CoverageMap::
// filled). Throws InvalidArgument when `report` does not describe `lut`'s measured slices.
ViewSource ViewSourceFromResampled(const Measurement& measurement, Lut lut,
                                   const processing::ResampleReport& report, std::string name);

// ViewSourceFromResampled of BuildLut(measurement, params) with the commands' blind-spot fill
// (processing::kDefaultBeyondMethod, kDefaultBeyondSubdivisions: what `brdf convert` does by
// default): resamples it here. Throws what BuildLut throws (InvalidArgument for a measurement
// it cannot resample).
ViewSource ViewSourceFromMeasurement(const Measurement& measurement,
                                     const processing::ExtrapolationParams& params,
                                     std::string name);

// An exported LUT as stored (no coverage information). `theta_b_deg` from its sidecar if known.
ViewSource ViewSourceFromLut(Lut lut, std::string name, double theta_b_deg = 90);

// Any evaluable BRDF (an analytic material, a fit): the virtual capture on the reference
// instrument's geometry (brdf::CaptureNoiseFree: θin 0/20/40/60°, θout 0–75°, φout 0–359° at 1°,
// docs/design.md §1) resampled with the default §6 parameters and blind-spot fill, i.e. exactly
// the LUT `brdf convert` would make from that capture.
ViewSource ViewSourceFromBrdf(const BrdfSource& source, std::string name);

}  // namespace brdf::viewer
