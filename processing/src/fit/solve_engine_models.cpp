// RunFit for the engine models, whose channels are coupled (kernel_fit.h); under the ngan loss
// through their linear forms (LinearCost). Built with -O3 (processing/CMakeLists.txt): the
// kernels only pay off fully inlined.
#include "fit_kernels.h"
#include "kernel_fit.h"

#include "brdf/core/error.h"

namespace brdf::processing::detail {

Search RunEngineModelFit(const FitData& data, const FitOptions& options) {
  switch (options.model) {
    case Model::kUnrealDefaultLit:
      return RunFit<kernels::UnrealKernel>(data, options);
    case Model::kUnityHdrpLit:
      return RunFit<kernels::HdrpKernel>(data, options);
    case Model::kUnityHdrpLitSpecular:
      return RunFit<kernels::HdrpSpecularKernel>(data, options);
    case Model::kUnityUrpLit:
      return RunFit<kernels::UrpKernel>(data, options);
    case Model::kUnityUrpLitSpecular:
      return RunFit<kernels::UrpSpecularKernel>(data, options);
    default:
      break;
  }
  throw InvalidArgument("fit: " + std::string(ModelName(options.model)) +
                        " is not an engine model");
}

}  // namespace brdf::processing::detail
