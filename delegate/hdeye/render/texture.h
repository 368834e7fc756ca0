#pragma once
// Every image the renderer reads (material inputs, the iris, the sclera, dome and rect lights) goes through
// OpenImageIO's TextureSystem: any format OIIO reads (PNG, JPEG, TIFF, EXR, HDR, TGA, ... and tiled,
// MIP-mapped .tx from maketx), MIP maps built in memory for files that have none, filtered lookups
// sized by a footprint in (s, t), UDIM sets (`<UDIM>` in the file name), and UsdUVTexture's wrap modes,
// scale, bias, fallback and sourceColorSpace. A file that cannot be read is not an error here: the
// texture is invalid, says why (Error()), and every lookup returns its fallback. Callers warn.
//
// One process-wide TextureSystem (OIIO's shared one) caches tiles for every render delegate, so a
// file is decoded once per process. Lookups are read-only, thread-safe and deterministic: the
// result depends only on (st, footprint), never on the thread or on what the cache holds.
#include "hdeye/params/textureParams.h"

#include <glm/glm.hpp>

#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace hdeye {

/// The area a lookup averages over: derivatives of (s, t) along two axes of the ray's footprint on the
/// surface (st units per footprint width). Zero: the finest MIP level, bilinear.
struct TextureFootprint {
  glm::vec2 dstDx{0}, dstDy{0};
};

/// Opaque per-thread lookup state (OIIO's TextureSystem::Perthread). Fetch it once per render thread
/// (CurrentTextureThread) and pass it to every lookup on that thread; null also works, a little slower.
struct TextureThread;
TextureThread* CurrentTextureThread();

/// One file (or UDIM set) with its UsdUVTexture parameters. Made by TextureCache or Texture::Open.
class Texture {
 public:
  /// Opens and checks the file: it must exist, be an image OIIO reads, and decode completely (its
  /// coarsest MIP level is read, which reads every texel). Never throws; see Valid().
  static std::shared_ptr<const Texture> Open(const TextureParams& params);
  /// Opens a plain colour image (TextureParams::Image) and throws std::runtime_error with a one-line
  /// message naming the file if it cannot be read (for callers that must have the pixels).
  static std::shared_ptr<const Texture> Load(const std::string& path);
  ~Texture();

  bool Valid() const { return error_.empty(); }
  /// Why the file cannot be used ("" when Valid()): "cannot read texture <file>: <reason>".
  const std::string& Error() const { return error_; }
  const TextureParams& Params() const { return params_; }
  int Width() const { return width_; }  ///< texels of the finest level (UDIM: of the first tile)
  int Height() const { return height_; }
  int Channels() const { return channels_; }
  bool Srgb() const { return srgb_; }  ///< whether lookups decode the sRGB transfer curve

  /// RGBA at st (USD's convention: t = 0 is the image's bottom row) averaged over the footprint,
  /// decoded to linear, then scaled and biased. The fallback where the texture is invalid. Finite.
  glm::vec4 Lookup(glm::vec2 st, const TextureFootprint& footprint, TextureThread* thread) const;
  /// Lookup at the finest level (bilinear), RGB: for callers with no footprint.
  glm::vec3 Lookup(glm::vec2 st) const;
  /// Every texel of the finest level, linear RGB after scale and bias, row 0 at the top (dome
  /// importance sampling). Empty for an invalid texture or a UDIM set.
  std::vector<glm::vec3> Texels() const;

 private:
  Texture() = default;
  void OpenFile();
  glm::vec4 Decode(const float raw[4]) const;

  TextureParams params_;
  std::string error_;
  void* handle_ = nullptr;  ///< OIIO TextureSystem::TextureHandle of the file (the UDIM pattern for a set)
  bool udim_ = false;
  int width_ = 0, height_ = 0, channels_ = 0;
  bool srgb_ = false;
};

/// Textures by parameters, opened on first use and shared by the prims that use them. Thread-safe.
class TextureCache {
 public:
  std::shared_ptr<const Texture> Get(const TextureParams& params);
  /// Get(TextureParams::Image(path)).
  std::shared_ptr<const Texture> Get(const std::string& path) { return Get(TextureParams::Image(path)); }

 private:
  std::mutex mutex_;
  std::unordered_map<std::string, std::vector<std::shared_ptr<const Texture>>> textures_;  ///< by file
};

/// Why `file` cannot be used as a texture ("" when it can): what a scene delegate asks before it binds
/// a texture, so it can warn once naming the prim. Shares the process-wide cache with every lookup.
std::string TextureProblem(const std::string& file);

}  // namespace hdeye
