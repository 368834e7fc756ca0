#include "hdeye/render/distribution2d.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hdeye {

Distribution1D::Distribution1D(const std::vector<double>& weights) : weights_(weights), cdf_(weights.size() + 1, 0.0) {
  if (weights_.empty()) throw std::invalid_argument("Distribution1D needs at least one weight");
  for (double& w : weights_)
    if (!(w > 0) || !std::isfinite(w)) w = 0;
  const double n = double(weights_.size());
  for (std::size_t i = 0; i < weights_.size(); ++i) cdf_[i + 1] = cdf_[i] + weights_[i] / n;
  integral_ = cdf_.back();
  if (integral_ > 0) {
    for (double& c : cdf_) c /= integral_;
  } else {
    for (std::size_t i = 0; i < cdf_.size(); ++i) cdf_[i] = double(i) / n;  // all zero: uniform
  }
  cdf_.back() = 1;
}

double Distribution1D::Pdf(int cell) const {
  if (cell < 0 || cell >= Count()) return 0;
  if (!(integral_ > 0)) return 1;
  return weights_[std::size_t(cell)] / integral_;
}

double Distribution1D::Sample(double u, int* cell, double* pdf) const {
  u = std::clamp(u, 0.0, 1.0);
  // The last cdf entry <= u whose cell has non-zero probability (upper_bound skips zero-width cells).
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
  int i = std::clamp(int(it - cdf_.begin()) - 1, 0, Count() - 1);
  while (i > 0 && !(cdf_[std::size_t(i) + 1] > cdf_[std::size_t(i)])) --i;  // u == 1 lands past the end
  const double width = cdf_[std::size_t(i) + 1] - cdf_[std::size_t(i)];
  const double within = width > 0 ? std::clamp((u - cdf_[std::size_t(i)]) / width, 0.0, 1.0) : 0.5;
  *cell = i;
  *pdf = Pdf(i);
  // Keep x inside the cell (x == 1 would be the next cell, outside the image).
  return std::min((i + within) / Count(), std::nextafter(double(i + 1) / Count(), 0.0));
}

Distribution2D::Distribution2D(int width, int height, const std::vector<double>& weights)
    : width_(width), height_(height) {
  if (width <= 0 || height <= 0 || weights.size() != std::size_t(width) * std::size_t(height))
    throw std::invalid_argument("Distribution2D: weights do not match the grid");
  std::vector<double> rowIntegrals(static_cast<std::size_t>(height));
  rows_.reserve(std::size_t(height));
  for (int y = 0; y < height; ++y) {
    rows_.emplace_back(std::vector<double>(weights.begin() + std::ptrdiff_t(y) * width,
                                           weights.begin() + std::ptrdiff_t(y + 1) * width));
    rowIntegrals[std::size_t(y)] = rows_.back().Integral();
  }
  marginal_ = Distribution1D(rowIntegrals);
}

glm::dvec2 Distribution2D::Sample(double u1, double u2, double* pdf) const {
  int row = 0, column = 0;
  double pdfV = 0, pdfU = 0;
  const double v = marginal_.Sample(u1, &row, &pdfV);
  const double u = rows_[std::size_t(row)].Sample(u2, &column, &pdfU);
  *pdf = pdfV * pdfU;
  return {u, v};
}

double Distribution2D::Pdf(const glm::dvec2& uv) const {
  if (Empty() || !(uv.x >= 0 && uv.x < 1) || !(uv.y >= 0 && uv.y < 1)) return 0;
  const int column = std::min(width_ - 1, int(uv.x * width_)), row = std::min(height_ - 1, int(uv.y * height_));
  return marginal_.Pdf(row) * rows_[std::size_t(row)].Pdf(column);
}

}  // namespace hdeye
