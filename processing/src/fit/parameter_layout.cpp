// Value layouts of the fitted models (parameter_layout.h).
#include "parameter_layout.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace brdf::processing::detail {

std::vector<Block> BlocksOf(Model model) {
  const ModelInfo& info = DescribeModel(model);
  std::vector<Block> blocks;
  if (models::ChannelsIndependent(model)) {
    for (int c = 0; c < 3; ++c) {
      Block b;
      b.channel = c;
      for (const ParameterInfo& p : info.parameters) b.value_index.push_back(p.offset + c);
      blocks.push_back(b);
    }
  } else {
    Block b;
    for (int i = 0; i < info.value_count; ++i) b.value_index.push_back(i);
    blocks.push_back(b);
  }
  return blocks;
}

const ParameterInfo& ParameterOfValue(const ModelInfo& info, int value_index) {
  for (const ParameterInfo& p : info.parameters)
    if (value_index >= p.offset && value_index < p.offset + p.Count()) return p;
  return info.parameters.front();
}

Material ClampIntoRange(Material m) {
  const ModelInfo& info = DescribeModel(m.model);
  for (const ParameterInfo& p : info.parameters)
    for (int c = 0; c < p.Count(); ++c) {
      double& v = m.values[static_cast<std::size_t>(p.offset + c)];
      v = std::clamp(std::isfinite(v) ? v : p.start, p.min, p.max);
    }
  return m;
}

bool SameStart(const Material& a, const Material& b) {
  for (std::size_t i = 0; i < a.values.size(); ++i)
    if (std::fabs(a.values[i] - b.values[i]) > 1e-9 * std::max(1.0, std::fabs(a.values[i])))
      return false;
  return true;
}

}  // namespace brdf::processing::detail
