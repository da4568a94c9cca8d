#include "brdf/device/white_reference.h"

namespace brdf::device {

const WhiteReference& SpectralonWhiteReference() {
  // Computed once from Spectralon_Num4.txt (grit-lab/grit-lab-spectralon-panel-model @ 78cbf9a9)
  // with the band means described in the header; tests/device/white_reference_test.cpp
  // recomputes them from the file and checks these digits.
  static const WhiteReference kSpectralon{
      "Spectralon panel no. 4, 8°/hemispherical certificate (shared/brdf-data/spectralon/"
      "Spectralon_Num4.txt)",
      {0.989747, 0.989829, 0.989363},
      {0.004904, 0.0053, 0.0053},
      "mean of the certificate's 1 nm rows over 600-700 nm (R), 500-600 nm (G), 400-500 nm (B), "
      "each band half-open [lo, hi)",
  };
  return kSpectralon;
}

}  // namespace brdf::device
