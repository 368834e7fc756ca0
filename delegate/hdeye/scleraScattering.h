#pragma once
// Sclera subsurface scattering for the eye shading code (DESIGN.md, "What happens when a ray meets an
// eye", step 5): a thin adapter that runs eyelib's random walk in the eye's canonical frame, so the
// limbal-arc teleportation cylinder follows the eye wherever it is and however it is turned, and hands
// back a world-space exit ray. The renderer supplies the eyeball's boundary (its Embree mesh or the
// analytic surface) as a world-space closest-hit callback; everything else lives in eyelib.
//
// XXX: not called yet. The integration into the path tracer (eyeShading / renderer) is a separate
// change; see docs/limbal_arc.md for what it needs.
#include "hdeye/eyeGeometry.h"

#include <eyelib/random_walk_sss.h>

#include <functional>

namespace hdeye {

/// The eyeball's boundary in world space: the closest crossing of origin + t * dir (dir unit),
/// 0 < t <= tMax (world units), writing *t and the geometric normal (unit, either orientation). It must
/// not report the surface the origin lies on at t ~ 0 (Embree: tnear from an error bound).
using WorldBoundary = std::function<bool(const glm::dvec3& origin, const glm::dvec3& dir, double tMax,
                                         double* t, glm::dvec3* normal)>;

struct ScleraScatteringSettings {
  double ior = 1.376;       ///< sclera over outside
  double g = 0;             ///< Henyey-Greenstein asymmetry (the albedo inversion assumes 0)
  int maxSteps = 1024;      ///< every scattering, internal reflection and teleport counts
  bool limbalArc = true;    ///< the teleportation cylinder (diameter = the eye's outer limbus edge)
};

struct ScleraExit {
  eyelib::WalkStatus status = eyelib::WalkStatus::Invalid;
  glm::dvec3 origin{0.0};  ///< world, on the eyeball surface (Exited only)
  glm::dvec3 dir{0.0};     ///< world, unit, leaving the eyeball (Exited only)
  glm::dvec3 weight{0.0};  ///< RGB throughput (Exited; the dropped weight when Capped)
  int steps = 0;
  bool teleported = false;  ///< the path lit the limbal arc (for a `limbalArc` AOV)
  bool Exited() const { return status == eyelib::WalkStatus::Exited; }
};

/// One sclera walk. `entry` (world) is the hit on the eyeball, `inwardDir` (world, any length) the
/// direction already refracted into the sclera (entry Fresnel is the surface's job); `scleraColor` the
/// artist's albedo (RGB, [0, 1]) and `meanFreePathMm` the scattering distance in millimetres (RGB, the
/// eye's own unit whatever the scene's: worldPerMm converts). `random` gives uniforms in [0, 1).
ScleraExit ScatterInSclera(const EyeGeometry& eye, const glm::dvec3& entry, const glm::dvec3& inwardDir,
                           const glm::dvec3& scleraColor, const glm::dvec3& meanFreePathMm,
                           const WorldBoundary& boundary, const std::function<double()>& random,
                           const ScleraScatteringSettings& settings = {});

}  // namespace hdeye
