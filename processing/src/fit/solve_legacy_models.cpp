// RunFit for the legacy models, whose channels are independent problems (kernel_fit.h). Built
// with -O3 (processing/CMakeLists.txt): the kernels only pay off fully inlined.
#include "fit_kernels.h"
#include "kernel_fit.h"

#include "brdf/core/error.h"

namespace brdf::processing::detail {

Search RunLegacyModelFit(const FitData& data, const FitOptions& options) {
  switch (options.model) {
    case Model::kLambert:
      return RunFit<kernels::LambertKernel>(data, options);
    case Model::kLafortune:
      return RunFit<kernels::LafortuneKernel>(data, options);
    case Model::kBlinnPhong:
      return RunFit<kernels::BlinnPhongKernel>(data, options);
    case Model::kGgx:
      return RunFit<kernels::GgxKernel>(data, options);
    case Model::kWard:
      return RunFit<kernels::WardKernel>(data, options);
    default:
      break;
  }
  throw InvalidArgument("fit: " + std::string(ModelName(options.model)) +
                        " is not a model with independent channels");
}

}  // namespace brdf::processing::detail
