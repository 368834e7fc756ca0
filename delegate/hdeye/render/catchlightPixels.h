#pragma once
// The pixels at the edge of a catchlight: where the cornea mirrors a light (a sphere, rect, disk or distant light; not
// a dome), the glint covers part of the pixel, and its value is binomial in the pixel jitter (a few hundred samples
// leave the glint's edge pixels tens of percent off). Those pixels estimate the cornea's reflection at the camera's
// first eye event with RenderSettings::catchlightSamples sub-samples per sample (pixelSampling.cpp). Which pixels
// they are is a function of the scene, the camera and the image size only, so every sample stays a pure function of
// (seed, pixel, sample) and a frame split over sample ranges merges exactly.
#include "hdeye/render/cameraView.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/renderSettings.h"

#include <embree3/rtcore.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <vector>

namespace hdeye {

class CatchlightPixels {
 public:
  CatchlightPixels() = default;  ///< none

  /// Asks Tracer::SeesCatchlight along the camera ray through every pixel corner (the lens's centre, the shutter's
  /// opening; past 512 x 512 pixels, every few pixels' corner) and marks each pixel whose 4 x 4 block of corners (its
  /// own cell's and its neighbours') disagrees: every pixel within one cell of a catchlight's edge.
  static CatchlightPixels Find(RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                               const RenderSettings& settings, bool cutouts, int width, int height,
                               tbb::task_arena* arena);

  bool Has(int x, int y) const { return !marked_.empty() && marked_[std::size_t(y) * width_ + x]; }
  std::int64_t Count() const { return count_; }
  /// The rays Find traced.
  std::int64_t Rays() const { return rays_; }

 private:
  int width_ = 0;
  std::vector<std::uint8_t> marked_;
  std::int64_t count_ = 0, rays_ = 0;
};

}  // namespace hdeye
