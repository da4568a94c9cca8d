// Piecewise-constant distributions on [0, 1) and [0, 1)², the building block of the map and the
// tabulated BRDF samplers. Private to brdf_preview.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace brdf::preview::detail {

// Density on [0, 1) proportional to `weights` (n equal bins). Zero-weight bins are never drawn.
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::vector<double> weights) : weight_(std::move(weights)) {
    cdf_.assign(weight_.size() + 1, 0.0);
    for (std::size_t i = 0; i < weight_.size(); ++i) cdf_[i + 1] = cdf_[i] + weight_[i];
    total_ = cdf_.back();
    if (total_ > 0.0)
      for (double& c : cdf_) c /= total_;
    cdf_.back() = 1.0;
  }

  std::size_t size() const { return weight_.size(); }
  double total() const { return total_; }
  // Probability of bin i.
  double BinProbability(std::size_t i) const { return total_ > 0.0 ? weight_[i] / total_ : 0.0; }
  // Density on [0, 1) inside bin i.
  double Density(std::size_t i) const { return BinProbability(i) * static_cast<double>(size()); }

  // Draws a bin from u ∈ [0, 1) and the position of u inside it, rescaled to [0, 1).
  // Requires total() > 0. The bin found always has positive probability: it is the last bin
  // whose cumulative start is ≤ u, and u < its end.
  std::size_t SampleBin(double u, double* within) const {
    const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
    std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - cdf_.begin() - 1, 0));
    i = std::min(i, size() - 1);
    while (i + 1 < size() && weight_[i] <= 0.0) ++i;  // guards rounding at u = 0
    const double width = cdf_[i + 1] - cdf_[i];
    double t = width > 0.0 ? (u - cdf_[i]) / width : 0.5;
    *within = std::clamp(t, 0.0, 0x1.fffffffffffffp-1);
    return i;
  }

 private:
  std::vector<double> weight_;
  std::vector<double> cdf_;
  double total_ = 0.0;
};

// Density on [0, 1)² proportional to `weights` (rows × columns bins, row-major): a marginal over
// rows and one conditional over columns per row.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(const std::vector<double>& weights, std::size_t rows, std::size_t columns)
      : rows_(rows), columns_(columns) {
    std::vector<double> row_weights(rows);
    conditional_.reserve(rows);
    for (std::size_t r = 0; r < rows; ++r) {
      std::vector<double> row(weights.begin() + static_cast<std::ptrdiff_t>(r * columns),
                              weights.begin() + static_cast<std::ptrdiff_t>((r + 1) * columns));
      conditional_.emplace_back(std::move(row));
      row_weights[r] = conditional_.back().total();
    }
    marginal_ = Distribution1D(std::move(row_weights));
  }

  double total() const { return marginal_.total(); }
  std::size_t rows() const { return rows_; }
  std::size_t columns() const { return columns_; }

  // Draws a cell; `within_row`, `within_column` locate the point inside it in [0, 1).
  void SampleCell(double u_row, double u_column, std::size_t* row, std::size_t* column,
                  double* within_row, double* within_column) const {
    *row = marginal_.SampleBin(u_row, within_row);
    *column = conditional_[*row].SampleBin(u_column, within_column);
  }
  // Probability of cell (row, column).
  double CellProbability(std::size_t row, std::size_t column) const {
    return marginal_.BinProbability(row) * conditional_[row].BinProbability(column);
  }

 private:
  std::size_t rows_ = 0, columns_ = 0;
  Distribution1D marginal_;
  std::vector<Distribution1D> conditional_;
};

}  // namespace brdf::preview::detail
