// Renderer::Render: the progressive pass control (passes sized by NextPassSamples, a first pass in stages, stops
// between whole passes) over the pixel sampling of pixelSampling.cpp.
#include "hdeye/render/renderer.h"

#include "hdeye/render/pixelSampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

namespace hdeye {

namespace {

/// Seconds since `start`.
double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// What every pass of one Render call shares: the scene, the tile count, the thread arena, the counters.
struct PassContext {
  RTCScene scene;
  const CameraView& camera;
  const std::vector<RenderLight>& lights;
  const RenderSettings& settings;
  const AovBuffers& aovs;
  bool cutouts, textured;
  ChamberLightCaches* chamberCaches;
  SampleKeys keys;
  CatchlightPixels catchlights;
  int tiles;
  tbb::task_arena* arena;
  SharedCounts* counts;
};

/// Samples [firstSample, firstSample + samples) of the grid's pixels, on the arena's threads.
void RenderPassSamples(const PassContext& c, int firstSample, int samples, const PixelGrid& grid = {}) {
  c.arena->execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, c.tiles), [&](const tbb::blocked_range<int>& range) {
      RenderTiles(range, firstSample, samples, grid, c.scene, c.camera, c.lights, c.settings, c.cutouts, c.textured,
                  c.aovs, c.counts, c.chamberCaches, c.keys, c.catchlights);
    });
  });
}

/// The first pass (one sample) in coarse-to-fine stages, strides control.firstPassStride, its half, ..., 1, with the
/// callback after each stage but the last (PassProgress::stride; its return value waits for the pass's end: a
/// render stops only between whole passes). Every pixel takes its sample once, so the image is as one stage's.
/// Returns the seconds to the end of the first stage. Each stride is a multiple of the next (powers of two: a stride
/// that is not one is rounded down to one), so no pixel is in two stages.
double RenderFirstPassInStages(const PassContext& c, const ProgressiveControl& control, PassProgress progress,
                               std::chrono::steady_clock::time_point start) {
  int coarser = 0, first = 1;
  while (first * 2 <= control.firstPassStride) first *= 2;
  for (int stride = first; stride > 1; coarser = stride, stride /= 2) {
    RenderPassSamples(c, c.settings.firstSample, 1, PixelGrid{stride, coarser});
    progress.stride = stride;
    progress.seconds = SecondsSince(start);
    if (progress.previewSeconds == 0) progress.previewSeconds = progress.seconds;
    if (control.onPass) control.onPass(progress);
  }
  RenderPassSamples(c, c.settings.firstSample, 1, PixelGrid{1, coarser});
  return progress.previewSeconds;
}

/// The pixels at a catchlight's edge, if the scene has an eye, a light a cornea can mirror (not a dome) and the
/// settings ask for catchlight sub-samples; else none (and no probe).
CatchlightPixels FindCatchlights(const PassContext& c, bool eyes, int width, int height) {
  const bool mirrored =
      std::any_of(c.lights.begin(), c.lights.end(), [](const RenderLight& l) { return l.type != LightType::Dome; });
  if (!eyes || !mirrored || c.settings.catchlightSamples <= 1) return {};
  return CatchlightPixels::Find(c.scene, c.camera, c.lights, c.settings, c.cutouts, width, height, c.arena);
}

void CopyCounts(const SharedCounts& counts, RenderStats* stats) {
  stats->rays = counts.rays;
  stats->nonFiniteSamples = counts.nonFinite;
  stats->scleraWalks = counts.walks;
  stats->teleportedWalks = counts.teleported;
  stats->cappedWalks = counts.capped;
  stats->invalidWalks = counts.invalid;
}

}  // namespace

int NextPassSamples(int remaining, int lastPass, double secondsPerSample, double passSeconds, double timeLeft) {
  if (remaining <= 0) return 0;
  if (lastPass <= 0 || !(secondsPerSample > 0)) return 1;
  const double target = timeLeft >= 0 ? std::min(passSeconds, timeLeft) : passSeconds;
  const double fit = std::clamp(std::floor(target / secondsPerSample), 1.0, 2.0 * lastPass);
  return std::min(int(fit), remaining);
}

RenderStats Renderer::Render(RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                             const RenderSettings& settings, const AovBuffers& aovs,
                             const ProgressiveControl& control) const {
  CheckBuffers(aovs);
  const int width = aovs.color->Width(), height = aovs.color->Height();
  RenderStats stats;
  if (width == 0 || height == 0) return stats;
  const auto start = std::chrono::steady_clock::now();
  SharedCounts counts;
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  if (!chamberCaches_) chamberCaches_ = std::make_shared<ChamberLightCaches>();
  chamberCaches_->BeginRender(lights, sceneVersion_);
  const eyelib::ZSobolKeyTable pathKeys = SampleStream::KeyTable(settings.seed);
  const eyelib::ZSobolKeyTable catchlightKeys = SampleStream::KeyTable(CatchlightSeed(settings.seed));
  const int tiles = ((width + kTile - 1) / kTile) * ((height + kTile - 1) / kTile);
  PassContext context{
      scene, camera, lights, settings, aovs, cutouts_, textured_, chamberCaches_.get(), {&pathKeys, &catchlightKeys},
      {},    tiles,  &arena, &counts};
  const auto probeStart = std::chrono::steady_clock::now();
  context.catchlights = FindCatchlights(context, eyes_, width, height);
  counts.rays += context.catchlights.Rays();
  stats.catchlightPixels = context.catchlights.Count();
  stats.catchlightSeconds = SecondsSince(probeStart);

  // Without a callback, a stop flag or a time limit every pixel takes all its samples at once (in cache); else pass
  // after pass as NextPassSamples sizes them, stopping only between whole passes so every pixel has the same samples.
  const bool progressive = control.Progressive(settings), limited = settings.timeLimitSeconds > 0;
  PassProgress progress;
  progress.samplesTotal = settings.samplesPerPixel;
  double secondsPerSample = 0;
  while (progress.samplesDone < settings.samplesPerPixel) {
    const int remaining = settings.samplesPerPixel - progress.samplesDone;
    const double timeLeft = limited ? std::max(0.0, settings.timeLimitSeconds - SecondsSince(start)) : -1.0;
    const int samples =
        progressive ? NextPassSamples(remaining, progress.passSamples, secondsPerSample, control.passSeconds, timeLeft)
                    : remaining;
    const auto passStart = std::chrono::steady_clock::now();
    if (progress.samplesDone == 0 && progressive && control.firstPassStride > 1)
      stats.previewSeconds = progress.previewSeconds = RenderFirstPassInStages(context, control, progress, start);
    else
      RenderPassSamples(context, settings.firstSample + progress.samplesDone, samples);
    secondsPerSample = SecondsSince(passStart) / samples;
    progress.samplesDone += samples;
    progress.passSamples = samples;
    progress.seconds = SecondsSince(start);
    if (progress.firstPassSeconds == 0) progress.firstPassSeconds = progress.seconds;
    stats.passes += samples;
    stats.samples += std::int64_t(width) * height * samples;
    const bool more = progress.samplesDone < settings.samplesPerPixel;
    if (control.onPass && !control.onPass(progress) && more) {
      stats.stopped = true;
      break;
    }
    if (more && control.stop && control.stop->load()) {
      stats.stopped = true;
      break;
    }
    if (more && limited && SecondsSince(start) >= settings.timeLimitSeconds) {
      stats.timeLimitReached = true;
      break;
    }
  }
  CopyCounts(counts, &stats);
  stats.firstPassSeconds = progress.firstPassSeconds;
  stats.seconds = SecondsSince(start);
  return stats;
}

}  // namespace hdeye
