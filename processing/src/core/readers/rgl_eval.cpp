// RglBrdf's evaluation entry points over its tables (rgl_eval.h).
#include "readers/rgl_eval.h"

#include <memory>
#include <string>
#include <utility>

namespace brdf {

RglBrdf::RglBrdf(std::unique_ptr<Tables> tables, std::string name)
    : tables_(std::move(tables)), name_(std::move(name)) {}
RglBrdf::RglBrdf(RglBrdf&&) noexcept = default;
RglBrdf& RglBrdf::operator=(RglBrdf&&) noexcept = default;
RglBrdf::~RglBrdf() = default;

const RglInfo& RglBrdf::info() const { return tables_->info; }

Rgb RglBrdf::EvalCosine(const Vec3& wi, const Vec3& wo) const {
  return tables_->EvalCosine(wi, wo, false);
}

Rgb RglBrdf::Eval(const Vec3& wi, const Vec3& wo) const {
  return tables_->EvalCosine(wi, wo, true);
}

}  // namespace brdf
