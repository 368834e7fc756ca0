#pragma once
// The path tracer proper (HdEmbreeRenderer's role). It sees the Embree scene, a camera view, a light
// list and AOV buffers; never prim classes. Unidirectional path tracing with next event estimation
// and multiple importance sampling (power heuristic), Russian roulette, UsdPreviewSurface materials
// (previewSurface.h) with emission, and the eyes' optics (eyeShading.h). Random numbers are a pure
// function of (seed, pixel, sample index, dimension), and each pixel's samples are added in sample
// order, so an image is bit-identical for any thread count, and disjoint sample ranges merge exactly.
#include "hdeye/render/accumulationBuffer.h"
#include "hdeye/render/cameraView.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/renderSettings.h"

#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace hdeye {

class ChamberLightCaches;

/// The AOVs a render pass can bind; null ones are not written. "color" has 4 components (RGB,
/// alpha = camera ray hit geometry), albedo and normal 3, depth (distance along the camera ray, 0
/// where nothing was hit) and primId (-1 where nothing was hit) 1. The data AOVs (albedo, normal,
/// depth, primId) come from sample index 0 only, so they are never averaged across edges. irisMnee
/// (3 components) is the part of color that came to an iris through MNEE; limbalArc (3) the part that
/// came through a sclera walk that teleported.
struct AovBuffers {
  AccumulationBuffer* color = nullptr;
  AccumulationBuffer* albedo = nullptr;
  AccumulationBuffer* normal = nullptr;
  AccumulationBuffer* depth = nullptr;
  AccumulationBuffer* primId = nullptr;
  AccumulationBuffer* irisMnee = nullptr;  ///< 3: the light that reached irises through MNEE, as the camera sees it
  /// The eye AOVs (3 each): color split by where its light came from, so that nonEye + glint + iris + sclera +
  /// limbalArc = color (RGB) to float precision. A path's light goes to the part of the first eye event on its way:
  /// glint, a reflection off the cornea at entry; iris, a refraction into the cornea (the direct caustic, the
  /// chamber's light, and what the path brings back out); sclera, a sclera hit (shaded or walked); nonEye, the light
  /// met before any eye event, or with none. limbalArc: everything a path gathers after its first sclera walk that
  /// crossed the teleportation cylinder (the limbal arc), taken out of the part it was in.
  AccumulationBuffer* glint = nullptr;
  AccumulationBuffer* iris = nullptr;
  AccumulationBuffer* sclera = nullptr;
  AccumulationBuffer* nonEye = nullptr;
  AccumulationBuffer* limbalArc = nullptr;
  /// 3: the first hit's primIndex (-1: none), instance index and materialBind subset (-1: none), added by every
  /// sample (not sample 0 alone): a pass of one sample per pixel holds that sample's hit, which the front end
  /// ranks into cryptomatte coverage. Exact as floats up to 2^24.
  AccumulationBuffer* hitId = nullptr;
};

struct RenderStats {
  std::int64_t samples = 0;  ///< pixel samples traced
  std::int64_t rays = 0;     ///< rays cast (closest-hit and shadow)
  double seconds = 0;
  int passes = 0;                     ///< samples per pixel completed
  std::int64_t nonFiniteSamples = 0;  ///< NaN/Inf radiance samples dropped (a bug if ever non-zero)
  bool timeLimitReached = false;
  std::int64_t scleraWalks = 0;      ///< sclera random walks run (eye meshes with RenderSettings::scleraScattering)
  std::int64_t teleportedWalks = 0;  ///< walks that crossed the teleportation cylinder at least once
  /// Walks dropped at their step cap (ScleraScatteringSettings::maxSteps): energy lost, reported.
  std::int64_t cappedWalks = 0;
  /// Walks ended as eyelib::WalkStatus::Invalid (bad artist values, a boundary query the mesh boundary
  /// could not answer): the path is dropped; a bug or a bad asset if ever non-zero.
  std::int64_t invalidWalks = 0;
  /// Seconds from the start of Render to the end of its first pass (every pixel has a sample): 0 if none ran.
  double firstPassSeconds = 0;
  /// Seconds to the first stage of a first pass in stages (ProgressiveControl::firstPassStride): 0 without stages.
  double previewSeconds = 0;
  bool stopped = false;  ///< a stop request or the pass callback ended the render before its samples
  /// Pixels at a catchlight's edge (catchlightPixels.h), sampled with RenderSettings::catchlightSamples sub-samples,
  /// and the seconds spent finding them (before the first pass).
  std::int64_t catchlightPixels = 0;
  double catchlightSeconds = 0;
};

/// Where a progressive render stands after a pass, as the pass callback sees it.
struct PassProgress {
  int samplesDone = 0;          ///< samples per pixel completed by this Render call
  int samplesTotal = 0;         ///< the samples per pixel it was asked for
  int passSamples = 0;          ///< samples per pixel the last pass took
  double seconds = 0;           ///< since Render started
  double firstPassSeconds = 0;  ///< to the end of the first pass
  /// While the first pass runs in stages (ProgressiveControl::firstPassStride): the pixels with x and y multiples of
  /// `stride` have their sample (samplesDone is still 0). 1: the pass is whole.
  int stride = 1;
  double previewSeconds = 0;  ///< to the end of the first stage (0: the first pass ran in one stage)
};

/// How a render is split into passes and stopped between them. A pass takes its samples of every pixel (each pixel's
/// in sample order), so any split gives the same image bit for bit; with neither a callback, a stop flag nor a time
/// limit the render is one pass.
struct ProgressiveControl {
  /// Called between passes on the thread that called Render; returns false to stop (the samples taken are kept).
  std::function<bool(const PassProgress&)> onPass;
  const std::atomic<bool>* stop = nullptr;  ///< may be set from any thread: the render stops after the current pass
  /// Seconds a pass aims at: the first pass takes one sample (the first full image soonest), each later one as many
  /// as fit this long by the rate so far (at most twice the last, never past a time limit's estimate).
  double passSeconds = 0.25;
  /// A power of two > 1: the first pass renders the pixels on a grid of this stride first, then the finer grids
  /// (the callback after each), so that a coarse image of the whole frame comes sooner. 1: one stage.
  int firstPassStride = 1;
  bool Progressive(const RenderSettings& settings) const { return onPass || stop || settings.timeLimitSeconds > 0; }
};

/// The samples per pixel of the next pass: `remaining` samples left, `lastPass` the size of the last (0: none yet),
/// `secondsPerSample` the measured seconds of one sample per pixel, `timeLeft` seconds before a time limit (negative:
/// none). A pure function, so the schedule can be tested alone.
int NextPassSamples(int remaining, int lastPass, double secondsPerSample, double passSeconds, double timeLeft);

class Renderer {
 public:
  /// Renders settings.samplesPerPixel samples per pixel, starting at settings.firstSample, into the
  /// bound buffers (which must all have the colour buffer's size), in passes as `control` asks, until the samples
  /// are taken, settings.timeLimitSeconds is spent (after at least one pass) or a stop is asked for. `scene` must
  /// be committed.
  RenderStats Render(RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                     const RenderSettings& settings, const AovBuffers& aovs,
                     const ProgressiveControl& control = {}) const;
  /// Whether a material in the scene has an opacityThreshold (cut-outs): shadow rays then find what they
  /// meet instead of stopping at the first surface. Set by the render pass before Render.
  void SetCutouts(bool cutouts) { cutouts_ = cutouts; }
  /// Whether a material in the scene has a textured input: without one, ray cones (texture footprints) are not
  /// needed and not computed. Set by the render pass before Render.
  void SetTextured(bool textured) { textured_ = textured; }
  /// Whether the scene has an eye (analytic or mesh): without one no pixel looks for a catchlight. Set by the render
  /// pass before Render.
  void SetEyes(bool eyes) { eyes_ = eyes; }

  /// The committed Embree scene's version (RenderParam::SceneVersion): the eyes' chamber-light caches
  /// (chamberLightCache.h), kept across Render calls, are rebuilt when it or the lights change.
  void SetSceneVersion(std::uint64_t version) { sceneVersion_ = version; }

 private:
  bool cutouts_ = false;
  bool textured_ = true;
  bool eyes_ = true;
  std::uint64_t sceneVersion_ = 0;
  mutable std::shared_ptr<ChamberLightCaches> chamberCaches_;  ///< created by the first Render
};

}  // namespace hdeye
