#include "hdeye/render/accumulationBuffer.h"

#include <stdexcept>

namespace hdeye {

AccumulationBuffer::AccumulationBuffer(std::string name, int width, int height, int components)
    : name_(std::move(name)) {
  Allocate(width, height, components);
}

void AccumulationBuffer::Allocate(int width, int height, int components) {
  if (width < 0 || height < 0 || !(components == 1 || components == 3 || components == 4))
    throw std::invalid_argument("render buffer " + name_ + ": bad size or component count");
  width_ = width, height_ = height, components_ = components;
  Clear();
}

void AccumulationBuffer::Clear() {
  sums_.assign(std::size_t(width_) * height_ * components_, 0.0);
  counts_.assign(std::size_t(width_) * height_, 0.0);
}

void AccumulationBuffer::AddSample(int x, int y, const float* value) {
  const std::size_t p = std::size_t(y) * width_ + x;
  for (int c = 0; c < components_; ++c) sums_[p * components_ + c] += value[c];
  counts_[p] += 1;
}

void AccumulationBuffer::Merge(const AccumulationBuffer& other) {
  if (other.width_ != width_ || other.height_ != height_ || other.components_ != components_)
    throw std::invalid_argument("render buffer " + name_ + ": cannot merge a buffer of another size");
  for (std::size_t i = 0; i < sums_.size(); ++i) sums_[i] += other.sums_[i];
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
}

void AccumulationBuffer::AddState(const std::vector<double>& sums, const std::vector<double>& counts) {
  if (sums.size() != sums_.size() || counts.size() != counts_.size())
    throw std::invalid_argument("render buffer " + name_ + ": cannot add the state of a buffer of another size");
  for (std::size_t i = 0; i < sums_.size(); ++i) sums_[i] += sums[i];
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += counts[i];
}

float AccumulationBuffer::Resolved(int x, int y, int c) const {
  const std::size_t p = std::size_t(y) * width_ + x;
  return counts_[p] > 0 ? float(sums_[p * components_ + c] / counts_[p]) : 0.0f;
}

std::vector<std::vector<float>> AccumulationBuffer::ResolvedPlanes() const {
  std::vector<std::vector<float>> planes(std::size_t(components_), std::vector<float>(std::size_t(width_) * height_));
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x)
      for (int c = 0; c < components_; ++c) planes[c][std::size_t(y) * width_ + x] = Resolved(x, y, c);
  return planes;
}

}  // namespace hdeye
