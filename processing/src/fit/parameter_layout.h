// How a model's values map to the unknowns the fitter solves for (private to brdf_fit).
#pragma once

#include <vector>

#include "brdf/core/models.h"

namespace brdf::processing::detail {

// The fitted unknowns: one block per independent problem.
struct Block {
  std::vector<int> value_index;  // into Material::values
  int channel = -1;
};
std::vector<Block> BlocksOf(Model model);

// The parameter that value `value_index` of a material belongs to.
const ParameterInfo& ParameterOfValue(const ModelInfo& info, int value_index);

// `m` with every value clamped into its parameter's range (non-finite values to the start).
Material ClampIntoRange(Material m);

// Whether two starts of one model are the same point (within 1e-9 relative per value).
bool SameStart(const Material& a, const Material& b);

}  // namespace brdf::processing::detail
