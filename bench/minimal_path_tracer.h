#pragma once
// The least a path tracer has to do for the ball scene's light transport, on the renderer's own committed BVH: a
// calibration for the renderer-against-bare-Embree ratio. Whatever this reaches of bare Embree is about the most any
// path tracer doing the same transport can, so the renderer's ratio is read against it as well as against 100 %.
//
// Per camera sample: a camera ray through a random point of the pixel (the renderer's CameraView), then up to
// `maxDepth` bounces off a surface of one albedo, with next event estimation of one of the two lights (the sphere
// light by its cone, the constant dome by the uniform sphere), each weighted by the power heuristic against the
// BSDF-sampled bounce, which finds the same lights; Russian roulette after three bounces. One rtcIntersect1 or
// rtcOccluded1 per ray, built as the renderer builds them. Two of the renderer's parts can be swapped in, to see what
// each costs: its sampler (ZSobol, instead of a counter hash) and its UsdPreviewSurface BSDF (instead of Lambert).
// What it always leaves out, and the renderer does not: smooth shading normals, materials and textures per prim,
// light linking, thin walls, cut-outs, eyes, motion, any number and kind of light, AOVs, the image's accumulation.
#include "hdeye/render/cameraView.h"

#include <eyelib/zsobol.h>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include <cstdint>

namespace bench {

struct MinimalScene {
  RTCScene scene = nullptr;
  hdeye::CameraView camera;
  int width = 0, height = 0, spp = 0, maxDepth = 8;
  glm::dvec3 keyPosition{0};  ///< the sphere light's centre (scene units)
  double keyRadius = 0;       ///< its radius (scene units)
  glm::dvec3 keyRadiance{0}, domeRadiance{0};
  double albedo = 0.5;
  const eyelib::ZSobolKeyTable* sampleKeys = nullptr;  ///< hdeye::SampleStream::KeyTable(0), for the ZSobol variants
};

/// Which sampler and BSDF the minimal path tracer runs with.
enum class MinimalVariant { Lambert, ZSobol, PreviewSurface, Both };
const char* MinimalVariantName(MinimalVariant variant);

struct MinimalResult {
  std::int64_t rays = 0;        ///< rtcIntersect1 plus rtcOccluded1 calls
  std::int64_t shadowRays = 0;  ///< of which rtcOccluded1
  double meanRadiance = 0;      ///< over pixels, samples and channels (a check that light arrived)
};

/// Renders the scene's width x height x spp camera samples on the calling thread.
MinimalResult TraceMinimal(const MinimalScene& scene, MinimalVariant variant);

}  // namespace bench
