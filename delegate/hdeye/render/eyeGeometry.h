#pragma once
// An eye as the renderer sees it: the analytic anterior chamber in the canonical frame (mm, apex at
// the origin, gaze +z) and the similarity transform to world space. The one place where world and
// canonical coordinates meet.
#include "hdeye/params/motion.h"
#include "hdeye/params/primParams.h"
#include "hdeye/render/texture.h"

#include <eyelib/anterior_chamber.h>
#include <eyelib/eye_constants.h>

#include <cmath>
#include <memory>
#include <vector>

namespace hdeye {

/// An eye that moves over the shutter: at frame time t its prim transform is prim->At(t) and its canonical frame
/// prim->At(t) * canonicalInPrim (the model transform, with the eye mesh's rigid-frame correction measured at
/// sync): a rigid interpolation of the frame (translation lerp, rotation slerp, scale lerp).
struct EyeMotion {
  std::shared_ptr<const TransformMotion> prim;  ///< frames; never null
  glm::dmat4 canonicalInPrim{1.0};              ///< canonical frame to the prim's local space
  Shutter shutter;                              ///< maps Embree ray times to frames (analytic eyes' intersection)
};

struct EyeGeometry {
  /// The parts a ray can hit (the user geometry's primID).
  enum Part : unsigned { kCornea = 0, kBack = 1 };

  eyelib::AnteriorChamber<double> chamber;
  glm::dmat4 canonicalToWorld{1.0}, worldToCanonical{1.0};
  /// The prim's local (object) space to the canonical frame: the inverse of EyeParams::modelTransform.
  /// Eye meshes map their hit points (object space) through it.
  glm::dmat4 objectToCanonical{1.0};
  double worldPerMm = 1;  ///< the transform's uniform scale
  glm::dvec3 irisColor{0.35, 0.2, 0.1}, scleraColor{0.8, 0.78, 0.75};
  /// EyeParams::irisTexture, loaded at sync; irisColor multiplies it.
  std::shared_ptr<const Texture> irisTexture;
  /// Eye meshes with a bound material shade their sclera with it (else with scleraColor).
  bool scleraUsesMaterial = false;
  /// EyeParams::limbalArc: the sclera walk's teleportation cylinder (eye meshes only).
  bool limbalArc = true;
  /// EyeParams::scleraMeanFreePath: the sclera walk's scattering distance per RGB channel, mm.
  glm::dvec3 scleraMeanFreePath{1.0, 0.8, 0.6};
  /// Eye meshes (eyeMeshMapping.h): the prim's local (object) space to world (the prim transform).
  glm::dmat4 objectToWorld{1.0};
  /// Eye meshes: object space to the iris projection's canonical coordinates (mm): a rest point maps
  /// to (x, y) there and its z is compared with the iris plane (EyeParams::irisProjection).
  glm::dmat4 objectToProjection{1.0};
  /// Eye meshes: EyeParams::reprojection (off: the affine-frame baseline, see eyeMeshMapping.h).
  bool reprojection = true;
  /// Eye meshes: -1 when the mesh is turned inside out relative to its rest pose (its signed volume
  /// changed sign), so its outward side stays outward; else 1.
  double outwardSign = 1;
  /// The eye's motion over the open shutter, or null: these frames hold for every path.
  std::shared_ptr<const EyeMotion> motion;

  EyeGeometry() = default;
  EyeGeometry(const EyeParams& params, const Matrix4d& primTransform);

  /// The absolute part of SpawnOffset (surfacePoint.h) on this eye: its centimetre in world units (10 x
  /// worldPerMm), so that rays leave the eye's surfaces alike from 1e-8 to 1e4 world units per mm.
  /// The eye as a path at frame time `time` sees it: its frames (canonical, object to world, scale) at that time.
  /// A copy of itself when it does not move.
  EyeGeometry AtTime(double time) const;
  /// The canonical-to-world frame at `count` evenly spaced times over the eye's shutter, ends included (its one frame
  /// when it does not move): what a moving eye's bounds are measured at.
  std::vector<glm::dmat4> CanonicalToWorldOverShutter(int count) const;

  double SpawnScale() const { return 10 * worldPerMm; }

  glm::dvec3 ToCanonical(const glm::dvec3& p) const { return glm::dvec3(worldToCanonical * glm::dvec4(p, 1)); }
  glm::dvec3 ToWorld(const glm::dvec3& p) const { return glm::dvec3(canonicalToWorld * glm::dvec4(p, 1)); }
  /// Directions map by the linear part; the result is normalised (a similarity keeps angles).
  glm::dvec3 DirToCanonical(const glm::dvec3& d) const {
    return glm::normalize(glm::dvec3(worldToCanonical * glm::dvec4(d, 0)));
  }
  glm::dvec3 DirToWorld(const glm::dvec3& d) const {
    return glm::normalize(glm::dvec3(canonicalToWorld * glm::dvec4(d, 0)));
  }

  /// Diffuse albedo of the iris at canonical point x (mm, on the iris plane): the texture over the
  /// 15.08 mm iris disk (u = 0.5 + x / 15.08 along +x, v = 0.5 + y / 15.08 along +y; EyeParams'
  /// convention) times irisColor (the schema's tint), else irisColor. Texels are clamped to [0, 1]: an
  /// albedo above 1 would add energy.
  glm::dvec3 IrisAlbedo(const glm::dvec3& x) const {
    if (!irisTexture) return irisColor;
    const double d = eyelib::paper::kIrisDiameter;
    const glm::dvec3 c(irisTexture->Lookup(glm::vec2(float(0.5 + x.x / d), float(0.5 + x.y / d))));
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) return glm::dvec3(0);  // a bad texel absorbs
    return irisColor * glm::clamp(c, glm::dvec3(0), glm::dvec3(1));
  }
};

/// A point of an analytic eye's cornea as an intersection found it, in double precision: canonical mm, and the unit
/// outward normal there.
struct CorneaPoint {
  glm::dvec3 point, normal;
};

/// A cornea hit an analytic eye's Embree intersect callback accepted.
struct ExactCorneaHit {
  const EyeGeometry* eye = nullptr;  ///< whose cornea (null: none)
  float t = 0;                       ///< the distance the callback gave Embree
  CorneaPoint at;
};

/// What the tracer and the analytic eyes' Embree callbacks share on one thread (Embree runs a user geometry's
/// callbacks on the thread that traces the ray): the tracer sets it before each ray.
struct EyeRayExchange {
  /// The eye whose cornea the ray leaves outwards (an exit, a reflection, a shadow ray from a cornea point, heading
  /// to the outer side of the cap's tangent plane there): the region under a cap is convex, so the ray cannot meet
  /// it, and that eye's callbacks skip it. Null: none.
  const EyeGeometry* leaving = nullptr;
  /// The cornea hit the intersect callback accepted last (eye null: none since the tracer cleared it). The tracer
  /// takes it for the ray's hit when that hit is this eye's cornea at this distance, so shading need not intersect
  /// again.
  ExactCorneaHit cornea;
};
EyeRayExchange& ThisThreadsEyeRays();

}  // namespace hdeye
