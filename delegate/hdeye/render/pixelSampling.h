#pragma once
// The pixels of a pass: each (pixel, sample) of a range of tiles traced from its own random stream and added to the
// AOV buffers. Internal to the renderer: renderer.cpp splits a render into passes over these.
#include "hdeye/render/catchlightPixels.h"
#include "hdeye/render/renderer.h"
#include "hdeye/render/tracer.h"

#include <tbb/blocked_range.h>

#include <atomic>
#include <cstdint>
#include <vector>

namespace hdeye {

/// Pixels per side of a tile, the unit of work a thread takes.
constexpr int kTile = 16;

/// The counters every tile's tracer adds to, shared across threads.
struct SharedCounts {
  std::atomic<std::int64_t> rays{0}, nonFinite{0}, walks{0}, teleported{0}, capped{0}, invalid{0};
  void Add(const Tracer::Counts& c) {
    rays += c.rays, walks += c.walks, teleported += c.teleportedWalks, capped += c.cappedWalks;
    invalid += c.invalidWalks;
  }
};

/// The pixels a pass stage renders: those on the stride grid (x and y multiples of `stride`) that are not on the
/// coarser grid of the stage before (0: none before). A first pass in stages 4, 2, 1 renders each pixel once.
struct PixelGrid {
  int stride = 1, coarser = 0;
  bool Has(int x, int y) const {
    // Asked once per pixel: the common grids (every pixel; a stage's power-of-two strides) take no division.
    return Divides(stride, x) && Divides(stride, y) && !(coarser && Divides(coarser, x) && Divides(coarser, y));
  }
  static bool Divides(int n, int x) { return (n & (n - 1)) == 0 ? (x & (n - 1)) == 0 : x % n == 0; }
};

/// The film's width over its height: the image's, stretched by RenderSettings::pixelAspectRatio.
double FilmAspect(const RenderSettings& settings, int width, int height);

/// The seed of the catchlight sub-samples' own stream (AddCatchlightSubSamples), apart from the paths'.
inline std::uint64_t CatchlightSeed(unsigned seed) { return std::uint64_t(seed) ^ 0x3c6ef372fe94f82bull; }

/// The ZSobol pair keys of a render's two streams, computed once per render (SampleStream::KeyTable); null: computed
/// where drawn.
struct SampleKeys {
  const eyelib::ZSobolKeyTable* path = nullptr;
  const eyelib::ZSobolKeyTable* catchlight = nullptr;
};

/// Throws std::invalid_argument unless a colour buffer is bound and every bound buffer has its size.
void CheckBuffers(const AovBuffers& aovs);

/// Samples [firstSample, firstSample + samples) of the grid's pixels in a range of tiles, each (pixel, sample) from its
/// own random stream. A pixel's samples are taken one after another (in sample order, so its sums are those of one pass
/// per sample): its buffer entries stay in cache, where a pass over the whole image would fetch them again each time.
void RenderTiles(const tbb::blocked_range<int>& range, int firstSample, int samples, const PixelGrid& grid,
                 RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                 const RenderSettings& settings, bool cutouts, bool textured, const AovBuffers& aovs,
                 SharedCounts* counts, ChamberLightCaches* chamberCaches, const SampleKeys& keys,
                 const CatchlightPixels& catchlights);

}  // namespace hdeye
