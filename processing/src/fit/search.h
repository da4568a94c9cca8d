// What a model's multi-start returns (private to brdf_fit): the best refinement and the
// totals over all of them. kernel_fit.h computes it.
#pragma once

#include <ceres/types.h>

#include <optional>
#include <string>
#include <vector>

#include "brdf/core/models.h"
#include "brdf/fit/fit.h"
#include "fit_data.h"

namespace brdf::processing::detail {

struct Refinement {
  Material material;
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
  ceres::TerminationType termination = ceres::FAILURE;
  std::string message;
};

// One block's outcome. Each block is its own Ceres problem: the blocks share no residual (the
// legacy models' channels are independent; an engine model is a single block).
struct BlockOutcome {
  std::vector<double> x;
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
  ceres::TerminationType termination = ceres::FAILURE;
  std::string message;
};

inline int Rank(ceres::TerminationType t) {  // worse outcomes rank higher
  switch (t) {
    case ceres::CONVERGENCE:
      return 0;
    case ceres::NO_CONVERGENCE:
      return 1;
    default:
      return 2;
  }
}

struct Search {
  std::optional<Refinement> best;
  int iterations = 0, starts = 0;
  double robust_scale = 0;  // the Cauchy scale used, 0 without a robust loss
};

// RunFit for the legacy models (solve_legacy_models.cpp) and the engine models
// (solve_engine_models.cpp), by options.model; two files so that the build compiles them in
// parallel.
Search RunLegacyModelFit(const FitData& data, const FitOptions& options);
Search RunEngineModelFit(const FitData& data, const FitOptions& options);

}  // namespace brdf::processing::detail
