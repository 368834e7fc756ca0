#include "hdeye/render/catchlightPixels.h"

#include "hdeye/render/pixelSampling.h"
#include "hdeye/render/tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace hdeye {

namespace {

/// Corners probed at most (about 512 x 512): a larger image is probed every `step` pixels, the smallest step keeping
/// to it, so the probe stays a small share of a first pass (catchlights narrower than the step may be missed there).
constexpr double kFullCorners = 512.0 * 512.0;

}  // namespace

CatchlightPixels CatchlightPixels::Find(RTCScene scene, const CameraView& camera,
                                        const std::vector<RenderLight>& lights, const RenderSettings& settings,
                                        bool cutouts, int width, int height, tbb::task_arena* arena) {
  const int step = std::max(1, int(std::ceil(std::sqrt(double(width) * height / kFullCorners))));
  const int cornersX = (width + step - 1) / step + 1, cornersY = (height + step - 1) / step + 1;
  std::vector<std::uint8_t> sees(std::size_t(cornersX) * cornersY, 0);
  const Shutter shutter = camera.GetShutter();
  const CameraView view = camera.motion ? camera.AtTime(shutter.open) : camera;
  const double aspect = FilmAspect(settings, width, height);
  std::atomic<std::int64_t> rays{0};
  arena->execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, cornersY), [&](const tbb::blocked_range<int>& rows) {
      Tracer tracer(scene, lights, settings, cutouts, shutter);
      for (int j = rows.begin(); j != rows.end(); ++j)
        for (int i = 0; i < cornersX; ++i) {
          const double u = double(std::min(width, i * step)) / width, v = double(std::min(height, j * step)) / height;
          sees[std::size_t(j) * cornersX + i] = tracer.SeesCatchlight(view.GenerateRay(u, v, aspect), shutter.open);
        }
      rays += tracer.GetCounts().rays;
    });
  });
  CatchlightPixels pixels;
  pixels.rays_ = rays;
  pixels.width_ = width;
  pixels.marked_.assign(std::size_t(width) * height, 0);
  // A lattice cell (the pixels from corner (i, j) to corner (i + 1, j + 1)) is marked when the corners of it and of
  // the cells around it disagree; its pixels take its mark. Decided once per cell, not once per pixel.
  for (int cj = 0; cj + 1 < cornersY; ++cj)
    for (int ci = 0; ci + 1 < cornersX; ++ci) {
      bool any = false, all = true;
      for (int j = std::max(0, cj - 1); j <= std::min(cornersY - 1, cj + 2); ++j)
        for (int i = std::max(0, ci - 1); i <= std::min(cornersX - 1, ci + 2); ++i) {
          const bool s = sees[std::size_t(j) * cornersX + i];
          any = any || s, all = all && s;
        }
      if (!any || all) continue;
      const int x0 = ci * step, x1 = std::min(width, x0 + step);
      for (int y = cj * step; y < std::min(height, (cj + 1) * step); ++y) {
        std::fill_n(pixels.marked_.begin() + std::ptrdiff_t(std::size_t(y) * width + x0), x1 - x0, std::uint8_t(1));
        pixels.count_ += x1 - x0;
      }
    }
  if (pixels.count_ == 0) pixels.marked_.clear();
  return pixels;
}

}  // namespace hdeye
