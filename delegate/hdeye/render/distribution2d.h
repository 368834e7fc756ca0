#pragma once
// Piecewise-constant distributions on [0, 1] and [0, 1]^2 for importance sampling images (the dome
// light's lat-long texture). Each sampling routine has its pdf beside it.
#include <glm/glm.hpp>

#include <vector>

namespace hdeye {

/// A piecewise-constant density on [0, 1] with n equal cells, proportional to non-negative weights.
class Distribution1D {
 public:
  Distribution1D() = default;
  /// Negative or non-finite weights count as 0. If every weight is 0 the distribution is uniform.
  explicit Distribution1D(const std::vector<double>& weights);

  int Count() const { return int(weights_.size()); }
  /// The sum of the weights over the count: the integral of the (unnormalised) function over [0, 1].
  double Integral() const { return integral_; }
  /// A point x in [0, 1) from uniform u; *cell receives its cell, *pdf the density at x.
  double Sample(double u, int* cell, double* pdf) const;
  /// The density of Sample at a point of the given cell.
  double Pdf(int cell) const;

 private:
  std::vector<double> weights_;
  std::vector<double> cdf_;  ///< Count() + 1 values, cdf_[0] = 0, cdf_.back() = 1
  double integral_ = 0;
};

/// A piecewise-constant density on [0, 1]^2 over a width x height grid of cells, row y covering
/// v in [y / height, (y + 1) / height). Sampled by the marginal over rows, then the row's conditional.
class Distribution2D {
 public:
  Distribution2D() = default;
  /// weights: row-major, width * height values, row 0 first.
  Distribution2D(int width, int height, const std::vector<double>& weights);

  bool Empty() const { return rows_.empty(); }
  /// A point (u, v) in [0, 1)^2 from two uniform numbers; *pdf is its density with respect to du dv.
  glm::dvec2 Sample(double u1, double u2, double* pdf) const;
  /// The density of Sample at (u, v) (0 outside [0, 1]^2).
  double Pdf(const glm::dvec2& uv) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<Distribution1D> rows_;  ///< conditional over u, per row
  Distribution1D marginal_;           ///< over rows
};

}  // namespace hdeye
