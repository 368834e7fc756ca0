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

#include <cstdint>
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
};

class Renderer {
 public:
  /// Renders settings.samplesPerPixel samples per pixel, starting at settings.firstSample, into the
  /// bound buffers (which must all have the colour buffer's size). `scene` must be committed.
  RenderStats Render(RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                     const RenderSettings& settings, const AovBuffers& aovs) const;
  /// Whether a material in the scene has an opacityThreshold (cut-outs): shadow rays then find what they
  /// meet instead of stopping at the first surface. Set by the render pass before Render.
  void SetCutouts(bool cutouts) { cutouts_ = cutouts; }
  /// Whether a material in the scene has a textured input: without one, ray cones (texture footprints) are not
  /// needed and not computed. Set by the render pass before Render.
  void SetTextured(bool textured) { textured_ = textured; }

  /// The committed Embree scene's version (RenderParam::SceneVersion): the eyes' chamber-light caches
  /// (chamberLightCache.h), kept across Render calls, are rebuilt when it or the lights change.
  void SetSceneVersion(std::uint64_t version) { sceneVersion_ = version; }

 private:
  bool cutouts_ = false;
  bool textured_ = true;
  std::uint64_t sceneVersion_ = 0;
  mutable std::shared_ptr<ChamberLightCaches> chamberCaches_;  ///< created by the first Render
};

}  // namespace hdeye
