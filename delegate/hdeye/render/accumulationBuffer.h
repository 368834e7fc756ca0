#pragma once
// Per-pixel sums and sample counts of one AOV: what the renderer writes into. Partial renders of disjoint
// sample ranges merge exactly (in any order, up to float summation). The render buffer bprim
// (prims/renderBuffer.h) is one of these with a prim id.
#include <string>
#include <vector>

namespace hdeye {

class AccumulationBuffer {
 public:
  /// `name` labels error messages ("render buffer <name>: ..."). Throws std::invalid_argument like Allocate.
  AccumulationBuffer(std::string name, int width, int height, int components);
  virtual ~AccumulationBuffer() = default;

  /// Resizes and clears. components: 1 (depth, primId), 3 (normal, albedo) or 4 (color).
  void Allocate(int width, int height, int components);
  void Clear();
  int Width() const { return width_; }
  int Height() const { return height_; }
  int Components() const { return components_; }

  /// Adds one sample's value (Components() floats) to pixel (x, y). Not thread-safe per pixel:
  /// the renderer gives each pixel to one thread.
  void AddSample(int x, int y, const float* value);
  /// Adds another buffer's sums and counts (same size and components).
  void Merge(const AccumulationBuffer& other);
  /// The raw accumulation state, for shipping a partial render to another process: per pixel (row-major,
  /// top row first) Components() sums, and one sample count.
  const std::vector<double>& Sums() const { return sums_; }
  const std::vector<double>& Counts() const { return counts_; }
  /// Adds a shipped state (Sums()/Counts() of a buffer of this size): Merge across processes.
  void AddState(const std::vector<double>& sums, const std::vector<double>& counts);
  /// The mean of pixel (x, y)'s samples, component c (0 if it has none).
  float Resolved(int x, int y, int c) const;
  /// Every pixel's mean as one plane per component, row-major, top row first.
  std::vector<std::vector<float>> ResolvedPlanes() const;

 private:
  std::string name_;
  int width_ = 0, height_ = 0, components_ = 4;
  std::vector<double> sums_;  ///< double: merged sums of many samples stay exact to float precision
  std::vector<double> counts_;
};

}  // namespace hdeye
