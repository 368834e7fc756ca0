#pragma once
// Images the renderer looks up: material and iris textures by (u, v), dome lights by direction.
// Loaded once per file (TextureCache) at sync time; lookups are read-only and thread-safe.
#include <glm/glm.hpp>

#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace hdeye {

/// A linear RGB float image. PNG files are decoded from sRGB; EXR files are read as linear.
class Texture {
 public:
  /// Throws std::runtime_error with a one-line message naming the file if it cannot be read.
  static std::shared_ptr<const Texture> Load(const std::string& path);
  Texture(int width, int height, std::vector<glm::vec3> texels);

  int Width() const { return width_; }
  int Height() const { return height_; }
  /// Bilinear lookup, wrapping (repeat) in u and v; v = 0 is the bottom row (USD's st convention).
  glm::vec3 Lookup(glm::vec2 uv) const;
  const glm::vec3& Texel(int x, int y) const { return texels_[std::size_t(y) * std::size_t(width_) + std::size_t(x)]; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<glm::vec3> texels_;  ///< row-major, row 0 at the top of the image
};

/// Textures by file path, loaded on first use and shared.
class TextureCache {
 public:
  std::shared_ptr<const Texture> Get(const std::string& path);

 private:
  std::mutex mutex_;
  std::unordered_map<std::string, std::shared_ptr<const Texture>> textures_;
};

}  // namespace hdeye
