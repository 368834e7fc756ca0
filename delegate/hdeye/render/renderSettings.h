#pragma once
// The render settings the renderer reads (HdRenderSettingsMap's role, as a struct): set on the render
// delegate, handed to the renderer by the render pass for each Execute.
#include "hdeye/render/eyeSwitches.h"

#include <optional>
#include <string>

namespace hdeye {

/// Where a path's random numbers come from (sampleStream.h): Owen-scrambled Sobol points in Z order (stratified
/// per pixel), or independent hashed numbers (the earlier sampler, kept to measure the difference).
enum class SamplerKind { ZSobol, Independent };

/// How an iris point gathers chamber light (light that left another iris point and reflected off the cornea's
/// inside back onto it): docs/iris_benchmark.md measures them.
enum class ChamberEstimator {
  /// The chamber walk alone: MNEE at every iris vertex the walk reaches (it finds the lit iris by chance).
  Path,
  /// The eye's chamber-light cache (chamberLightCache.h) at the walk's first iris vertex; MNEE only there.
  /// Biased by the cache's resolution (on scene B a two-seed floor of 0.10-0.12 % of the pixel at the default grid).
  Cache,
  /// The cache as a control variate: its value at the first iris vertex, plus, at the second, the path's MNEE
  /// minus the cache's prediction of everything from there on. Unbiased up to the cache's interpolation of its
  /// own hemisphere integral.
  ControlVariate,
};

/// The estimator's setting name: "path", "cache", "controlVariate".
inline std::string ChamberEstimatorName(ChamberEstimator e) {
  return e == ChamberEstimator::Cache ? "cache" : e == ChamberEstimator::ControlVariate ? "controlVariate" : "path";
}
/// The estimator a setting names, or nothing.
inline std::optional<ChamberEstimator> ParseChamberEstimator(const std::string& name) {
  for (ChamberEstimator e : {ChamberEstimator::Path, ChamberEstimator::Cache, ChamberEstimator::ControlVariate})
    if (name == ChamberEstimatorName(e)) return e;
  return std::nullopt;
}

/// Render settings (name, default), read by the render pass for each Execute.
struct RenderSettings {
  int samplesPerPixel = 16;
  double timeLimitSeconds = 0;  ///< 0: no limit
  unsigned seed = 0;
  int threads = 0;      ///< 0: all cores
  int maxDepth = 8;     ///< path vertices after the camera
  int firstSample = 0;  ///< sample range [firstSample, firstSample + samplesPerPixel): splits a frame
  bool mis = true;      ///< combine light and BSDF sampling (off: light sampling only, for tests)
  /// The switches of eyes no render plan was applied to (an applied plan sets them to its global switches, and each
  /// planned eye renders with its own: EyeRenderOptions::switches).
  EyeSwitches eyeSwitches;
  /// Eyes with MNEE: how the iris gathers chamber light. The cache by default: on scene B its bias floor is 0.12 %
  /// and its noise at equal samples a sixth of the control variate's (docs/iris_benchmark.md).
  ChamberEstimator chamberEstimator = ChamberEstimator::Cache;
  /// Whether camera rays see dome lights (off: the dome lights the scene but the background is black, as
  /// usdrecord renders without --enableDomeLightVisibility).
  bool domeLightCameraVisibility = true;
  /// Textures are filtered over each ray's footprint (the ray cone of rayCone.h: MIP-mapped, anisotropic).
  /// Off: every lookup is at the finest level (point sampling, for A/B comparisons).
  bool textureFiltering = true;
  /// The camera's ray cone as a fraction of a pixel (docs/textures.md measures the choice). Below 1 the
  /// texture filter overlaps the pixel filter (the jittered samples) less, so converged images blur less.
  double textureFootprintScale = 0.5;
  /// A pixel's width over its height (UsdRender's pixelAspectRatio): the image covers the camera's film as if it
  /// were width x pixelAspectRatio pixels wide. Positive and finite; 1: square pixels.
  double pixelAspectRatio = 1;
  /// Motion blur: 0 draws each camera path's time uniformly over the camera's shutter (one more sample dimension);
  /// N > 0 renders N discrete times, the centres of N equal strata of the shutter, sample s at stratum s mod N (the
  /// accumulation-buffer method: the image is the average of N sharp images, which tests check exactly, without
  /// catchlight sub-samples: those draw times of their own). Unused when the shutter is closed.
  int timeStrata = 0;
  SamplerKind sampler = SamplerKind::ZSobol;
  /// Eyes: MNEE estimates of the light at a camera path's first iris vertex, averaged (each weighs 1 / N). More
  /// than 1 only pays where the light's own sampling is noisy (large or several lights).
  int irisLightSplits = 1;
  /// Eyes: chamber walks continued from a camera path's first iris vertex, each gathering the iris light it meets
  /// with weight 1 / N; the first also carries the path out of the eye (its exit keeps the full weight).
  int chamberSplits = 1;
  /// Eyes: reflection-only camera paths per sample in the pixels at a catchlight's edge (catchlightPixels.h), which
  /// estimate the cornea's reflection there in place of the sample's own; 1: none (every pixel as any other).
  int catchlightSamples = 16;
  /// Eyes with MNEE: where each small light's centre enters a still eye, tabulated once for the renderer's threads
  /// (eyelib::EntryPointTable: a bilinear guess and one fixed-point step; entryTables.h) for MNEE's start and light
  /// sampling origin, instead of three steps at every iris point. A moving eye or light always computes it. Off:
  /// computed everywhere, so a motion-blurred render's samples equal sharp renders' at their times (the strata tests).
  bool mneeEntryTables = true;
};

}  // namespace hdeye
