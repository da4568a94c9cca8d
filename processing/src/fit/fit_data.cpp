#include "fit_data.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>

#include "brdf/core/error.h"
#include "brdf/core/geometry.h"

namespace brdf::processing {

namespace {

// Cell edges in θ (radians) of a sorted list of row angles (degrees): midpoints between rows,
// the first row's lower edge at 0 when it is the pole, the outer edges half a step out.
std::vector<std::pair<double, double>> RowEdges(const std::vector<double>& rows_deg) {
  std::vector<std::pair<double, double>> edges(rows_deg.size());
  for (std::size_t i = 0; i < rows_deg.size(); ++i) {
    const double prev = i > 0
                            ? rows_deg[i - 1]
                            : rows_deg[i] - (rows_deg.size() > 1 ? rows_deg[1] - rows_deg[0] : 1.0);
    const double next =
        i + 1 < rows_deg.size()
            ? rows_deg[i + 1]
            : rows_deg[i] + (rows_deg.size() > 1 ? rows_deg[i] - rows_deg[i - 1] : 1.0);
    const double lo = std::max(0.0, 0.5 * (prev + rows_deg[i]));
    const double hi = std::min(90.0, 0.5 * (rows_deg[i] + next));
    edges[i] = {DegToRad(lo), DegToRad(hi)};
  }
  return edges;
}

// SphericalDirectionDeg of the float angles of samples, each distinct angle's sine and cosine
// computed once: a capture repeats the same 76 θ and 360 φ values in every slice, and four
// sincos per sample were most of the data preparation. Bit-identical to SphericalDirectionDeg.
class DirectionCache {
 public:
  Vec3 Of(float theta_deg, float phi_deg) {
    const auto& [st, ct] = SinCos(theta_deg);
    const auto& [sp, cp] = SinCos(phi_deg);
    return {st * cp, st * sp, ct};
  }

 private:
  // The last angle looked up first: θin and φin are the same for a whole slice, θout for a row.
  const std::pair<double, double>& SinCos(float deg) {
    for (const Entry* e : last_)
      if (e != nullptr && e->first == deg) return e->second;
    auto it = cache_.find(deg);
    if (it == cache_.end()) {
      const double rad = DegToRad(deg);
      it = cache_.emplace(deg, std::make_pair(std::sin(rad), std::cos(rad))).first;
    }
    last_[next_] = &*it;
    next_ = (next_ + 1) % last_.size();
    return it->second;
  }
  using Entry = std::pair<const float, std::pair<double, double>>;
  std::unordered_map<float, std::pair<double, double>> cache_;  // references stay valid
  std::array<const Entry*, 3> last_{};
  std::size_t next_ = 0;
};

double Median(std::vector<double>& v) {
  if (v.empty()) return 0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

FitData PrepareFitData(const Measurement& measurement, const FitOptions& options) {
  if (options.max_theta_out_deg &&
      !(*options.max_theta_out_deg > 0 && *options.max_theta_out_deg <= 90))
    throw InvalidArgument("fit: the largest θout must be in (0°, 90°], got " +
                          NumberText(*options.max_theta_out_deg));
  FitData data;
  data.samples.reserve(measurement.SampleCount());
  DirectionCache directions;
  for (std::size_t si = 0; si < measurement.slices.size(); ++si) {
    const Slice& slice = measurement.slices[si];
    data.theta_in_deg.push_back(slice.theta_in_deg);
    // Rows of this slice (θout rounded to 1e-3°) and their sample counts, for the weights.
    std::map<long, std::size_t> rows;
    std::vector<const Sample*> kept;
    std::vector<long> kept_row;  // each kept sample's key into rows
    kept.reserve(slice.samples.size());
    kept_row.reserve(slice.samples.size());
    long last_key = 0;
    std::size_t* last_count = nullptr;  // rows[last_key]: samples come row by row
    for (const Sample& s : slice.samples) {
      bool finite = std::isfinite(s.theta_in_deg) && std::isfinite(s.phi_in_deg) &&
                    std::isfinite(s.theta_out_deg) && std::isfinite(s.phi_out_deg);
      for (float v : s.rgb) finite = finite && std::isfinite(v);
      if ((s.flags & kFlagInvalid) != 0 || !finite) {
        ++data.excluded_invalid;
        continue;
      }
      if ((s.flags & kFlagSaturated) != 0) {
        ++data.excluded_saturated;
        continue;
      }
      if (s.theta_in_deg < 0 || s.theta_in_deg >= 90 || s.theta_out_deg < 0 ||
          s.theta_out_deg >= 90 ||
          (options.max_theta_out_deg && s.theta_out_deg > *options.max_theta_out_deg + 1e-9)) {
        ++data.excluded_theta_out;
        continue;
      }
      const long key = std::lround(s.theta_out_deg * 1000.0);
      if (last_count == nullptr || key != last_key) last_count = &rows[key], last_key = key;
      ++*last_count;
      kept.push_back(&s);
      kept_row.push_back(key);
    }
    std::vector<double> row_deg;
    for (const auto& [key, count] : rows) row_deg.push_back(static_cast<double>(key) / 1000.0);
    const auto edges = RowEdges(row_deg);
    std::map<long, double> cell;  // solid angle per sample of each row
    long cell_key = 0;
    double cell_area = -1;  // cell[cell_key] once looked up (-1: none yet)
    std::size_t r = 0;
    for (const auto& [key, count] : rows) {
      const double area = 2.0 * kPi * (std::cos(edges[r].first) - std::cos(edges[r].second));
      cell[key] = area / static_cast<double>(count);
      ++r;
    }
    for (std::size_t ki = 0; ki < kept.size(); ++ki) {
      const Sample* s = kept[ki];
      FitSample x;
      const Vec3 l = directions.Of(s->theta_in_deg, s->phi_in_deg);
      const Vec3 v = directions.Of(s->theta_out_deg, s->phi_out_deg);
      x.g = ShadingGeometry::Of(l, v);
      if (!x.g.AboveHorizon()) {
        ++data.excluded_theta_out;
        continue;
      }
      for (int c = 0; c < 3; ++c) x.m[c] = s->rgb[c];
      x.cos_in = l.z;
      if (cell_area < 0 || cell_key != kept_row[ki])
        cell_key = kept_row[ki], cell_area = cell[cell_key];
      x.sqrt_w = cell_area;  // squared below, after normalising
      x.theta_h_deg = RadToDeg(std::acos(std::clamp(x.g.n_dot_h, -1.0, 1.0)));
      x.slice = static_cast<int>(si);
      data.samples.push_back(x);
    }
  }
  if (data.samples.empty())
    throw FormatError(measurement.metadata.sample_name, "samples",
                      "at least one valid, unsaturated sample above the horizon",
                      "none (" + std::to_string(data.excluded_invalid) + " invalid, " +
                          std::to_string(data.excluded_saturated) + " saturated, " +
                          std::to_string(data.excluded_theta_out) + " outside the θout range)");
  double total = 0;
  for (const FitSample& x : data.samples) total += x.sqrt_w;
  for (FitSample& x : data.samples) x.sqrt_w = std::sqrt(x.sqrt_w / total);
  return data;
}

int ParametersPerChannel(Model model) {
  return static_cast<int>(DescribeModel(model).parameters.size());
}

int ParameterCount(Model model) {
  int n = 0;
  for (const ParameterInfo& p : DescribeModel(model).parameters) n += p.rgb ? 3 : 1;
  return n;
}

bool Underdetermined(std::size_t samples_used, Model model) {
  return samples_used < static_cast<std::size_t>(kSamplesPerParameter) *
                            static_cast<std::size_t>(ParametersPerChannel(model));
}

std::string UnderdeterminedWarning(std::size_t samples_used, Model model) {
  if (!Underdetermined(samples_used, model)) return {};
  const int per_channel = ParametersPerChannel(model);
  return std::to_string(samples_used) + " usable sample" + (samples_used == 1 ? "" : "s") +
         " for " + std::to_string(ParameterCount(model)) + " parameters (" +
         std::to_string(per_channel) + " per colour channel): the data does not determine the " +
         std::string(ModelName(model)) + " fit (at least " +
         std::to_string(kSamplesPerParameter * per_channel) +
         " usable samples needed); not representable";
}

void FillErrors(const FitData& data, const Material& material, FitReport* report) {
  report->samples_used = data.samples.size();
  report->excluded_invalid = data.excluded_invalid;
  report->excluded_saturated = data.excluded_saturated;
  report->excluded_theta_out = data.excluded_theta_out;
  const std::size_t n_slices = data.theta_in_deg.size();
  std::vector<double> sq(n_slices, 0.0);
  std::vector<std::size_t> count(n_slices, 0);
  std::vector<std::vector<double>> rel(n_slices);
  std::vector<double> all_rel;
  all_rel.reserve(3 * data.samples.size());
  {
    std::vector<std::size_t> per_slice(n_slices, 0);
    for (const FitSample& x : data.samples) ++per_slice[static_cast<std::size_t>(x.slice)];
    for (std::size_t s = 0; s < n_slices; ++s) rel[s].reserve(3 * per_slice[s]);
  }
  double all_sq = 0;
  // Chromaticity bins: per slice, θh edges below.
  static constexpr double kThetaHEdges[] = {0, 2, 5, 10, 20, 35, 60, 90};
  constexpr int kBins = 7;
  std::vector<std::array<std::array<double, 6>, kBins>> bins(n_slices);  // measured rgb, model rgb
  for (auto& b : bins)
    for (auto& cellv : b) cellv.fill(0.0);
  for (const FitSample& x : data.samples) {
    const std::array<double, 3> f =
        models::EvaluateRgb(material.model, x.g, material.values.data());
    const std::size_t s = static_cast<std::size_t>(x.slice);
    ++count[s];
    int bin = kBins - 1;
    for (int b = 0; b < kBins; ++b)
      if (x.theta_h_deg < kThetaHEdges[b + 1]) {
        bin = b;
        break;
      }
    const double w = x.sqrt_w * x.sqrt_w;
    for (int c = 0; c < 3; ++c) {
      const double d = f[c] - x.m[c];
      sq[s] += d * d;
      all_sq += d * d;
      const double r = std::fabs(d) / std::max(x.m[c], 1e-3);
      rel[s].push_back(r);
      all_rel.push_back(r);
      bins[s][static_cast<std::size_t>(bin)][static_cast<std::size_t>(c)] += w * x.m[c];
      bins[s][static_cast<std::size_t>(bin)][static_cast<std::size_t>(3 + c)] += w * f[c];
    }
  }
  report->slices.clear();
  for (std::size_t s = 0; s < n_slices; ++s) {
    if (count[s] == 0) continue;
    SliceFitError e;
    e.theta_in_deg = data.theta_in_deg[s];
    e.samples = count[s];
    e.rmse = std::sqrt(sq[s] / (3.0 * static_cast<double>(count[s])));
    e.median_relative_error = Median(rel[s]);
    report->slices.push_back(e);
  }
  std::sort(report->slices.begin(), report->slices.end(),
            [](const SliceFitError& a, const SliceFitError& b) {
              return a.theta_in_deg < b.theta_in_deg;
            });
  report->rmse = std::sqrt(all_sq / (3.0 * static_cast<double>(data.samples.size())));
  report->median_relative_error = Median(all_rel);

  // Hue that changes with angle differently from the model's.
  double worst = 0;
  std::string where;
  auto luminance = [](double r, double g, double b) {
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
  };
  for (std::size_t s = 0; s < n_slices; ++s) {
    double slice_lum = 0;
    for (const auto& b : bins[s]) slice_lum += luminance(b[0], b[1], b[2]);
    if (!(slice_lum > 0)) continue;
    for (int bi = 0; bi < kBins; ++bi) {
      const auto& b = bins[s][static_cast<std::size_t>(bi)];
      if (luminance(b[0], b[1], b[2]) < 0.02 * slice_lum) continue;
      const double sm = b[0] + b[1] + b[2], sf = b[3] + b[4] + b[5];
      if (!(sm > 0) || !(sf > 0)) continue;
      const double d = std::hypot(b[0] / sm - b[3] / sf, b[1] / sm - b[4] / sf);
      if (d > worst) {
        worst = d;
        char buf[160];
        std::snprintf(buf, sizeof buf, "θin %g°, half-vector angle %g–%g°", data.theta_in_deg[s],
                      kThetaHEdges[bi], kThetaHEdges[bi + 1]);
        where = buf;
      }
    }
  }
  report->chromaticity_error = worst;

  // A hue that changes with angle beyond what a mix of two colours (a diffuse colour and a
  // specular colour, the most any model here has) can make: the chromaticities of additive
  // mixtures of two colours lie on one straight line, so the bins' measured chromaticities are
  // fitted by a line (total least squares) and the largest distance from it is the spread.
  std::vector<std::array<double, 3>> points;  // r, g chromaticity and luminance weight
  for (std::size_t s = 0; s < n_slices; ++s) {
    double slice_lum = 0;
    for (const auto& b : bins[s]) slice_lum += luminance(b[0], b[1], b[2]);
    if (!(slice_lum > 0)) continue;
    for (const auto& b : bins[s]) {
      const double lum = luminance(b[0], b[1], b[2]), sum = b[0] + b[1] + b[2];
      if (lum >= 0.02 * slice_lum && sum > 0) points.push_back({b[0] / sum, b[1] / sum, 1.0});
    }
  }
  double spread = 0;
  if (points.size() >= 3) {
    double mr = 0, mg = 0;
    for (const auto& p : points) mr += p[0], mg += p[1];
    mr /= static_cast<double>(points.size()), mg /= static_cast<double>(points.size());
    double srr = 0, sgg = 0, srg = 0;
    for (const auto& p : points) {
      srr += (p[0] - mr) * (p[0] - mr), sgg += (p[1] - mg) * (p[1] - mg);
      srg += (p[0] - mr) * (p[1] - mg);
    }
    const double angle = 0.5 * std::atan2(2 * srg, srr - sgg);  // principal direction
    const double nx = -std::sin(angle), ny = std::cos(angle);   // its normal
    for (const auto& p : points)
      spread = std::max(spread, std::fabs((p[0] - mr) * nx + (p[1] - mg) * ny));
  }
  report->hue_spread = spread;
  report->colour_shift = spread > 0.02;
  report->representable = !report->colour_shift && worst <= 0.05;
  if (const std::string w = UnderdeterminedWarning(data.samples.size(), material.model);
      !w.empty()) {
    report->representable = false;
    report->warnings.push_back(w);
  }
  if (report->colour_shift) {
    report->warnings.push_back(ColourShiftWarning(spread, material.model));
  } else if (worst > 0.05) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "the fit's hue differs from the measurement's by %.3f in rg chromaticity at %s: "
                  "%s cannot follow how the colour changes with angle",
                  worst, where.c_str(), std::string(ModelName(material.model)).c_str());
    report->warnings.push_back(buf);
  }
}

std::string ColourShiftWarning(double hue_spread, std::optional<Model> model) {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "the measured hue changes with angle beyond any mix of a diffuse and a specular "
                "colour (chromaticities up to %.3f off one line): a colour-shifting finish "
                "(thin film, interference or pearlescent pigment) that %s",
                hue_spread,
                model ? (std::string(ModelName(*model)) + " cannot represent").c_str()
                      : "none of these models can represent");
  return buf;
}

}  // namespace brdf::processing
