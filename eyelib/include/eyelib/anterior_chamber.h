#pragma once
// The anterior chamber: the anterior surface above, the iris plane below at a chosen depth, the
// pupil, and the limbus band where cornea blends into sclera. All lengths mm, canonical frame.
#include "eyelib/anterior_surface.h"
#include "eyelib/eye_constants.h"

#include <optional>
#include <string>

namespace eyelib {

/// Artist-facing parameters of the chamber. Defaults are the paper's.
struct ChamberParams {
  CorneaModel model = CorneaModel::EllipsoidCone;
  double irisDepth = paper::kIrisDepth;                ///< mm below the apex, > 0
  double pupilDiameter = paper::kPupilDiameter;        ///< mm, >= 0 and below the iris disk
  double limbusInnerRatio = paper::kLimbusInnerRatio;  ///< inner limbus diameter / 15.08 mm, (0, 1]
  double limbusOuterRatio = paper::kLimbusOuterRatio;  ///< outer limbus diameter / 15.08 mm, (0, 1]
  double corneaIor = paper::kCorneaIor;                ///< >= 1
};

/// Empty if the parameters are valid, else a one-line message naming the first offending value.
std::string ValidateChamberParams(const ChamberParams& params);

/// A ray's crossing of the iris disk.
template <class T> struct IrisHit {
  T t;
  Vec3<T> point;  ///< mm, on the plane z = -irisDepth
};

/// The surface a ray inside the chamber meets next (AnteriorChamber::NextSurfaceFromInside).
template <class T> struct ChamberSurfaceHit {
  /// Iris and Pupil: on the iris plane (Pupil: into the lens); Cornea: the anterior surface from inside; Lost:
  /// nothing (through the sub-micrometre gap at the rim).
  enum Kind { Iris, Pupil, Cornea, Lost } kind = Lost;
  Vec3<T> point{0};   ///< mm
  Vec3<T> normal{0};  ///< Cornea: the surface's outward normal
};

template <class T> class AnteriorChamber {
 public:
  /// `params` must pass ValidateChamberParams (checked by callers that take user input).
  explicit AnteriorChamber(const ChamberParams& params = {}) : params_(params), surface_(params.model) {
    irisZ_ = T(-params.irisDepth);
    irisRadius_ = std::min(surface_.RimRadius(), surface_.InverseSag(irisZ_));
    pupilRadius_ = T(params.pupilDiameter / 2);
    limbusInner_ = T(params.limbusInnerRatio * paper::kRimRadius);
    limbusOuter_ = T(params.limbusOuterRatio * paper::kRimRadius);
  }

  const ChamberParams& Params() const { return params_; }
  const AnteriorSurface<T>& Surface() const { return surface_; }
  T IrisZ() const { return irisZ_; }
  /// Radius of the visible iris disk: where the iris plane meets the anterior surface, capped at
  /// the rim (mm).
  T IrisRadius() const { return irisRadius_; }
  T PupilRadius() const { return pupilRadius_; }
  T LimbusInnerRadius() const { return limbusInner_; }
  T LimbusOuterRadius() const { return limbusOuter_; }
  T CorneaIor() const { return T(params_.corneaIor); }

  /// Crossing of the iris disk (pupilRadius <= r <= irisRadius) for 0 < t <= tMax, from either side.
  std::optional<IrisHit<T>> IntersectIris(const Ray<T>& ray, T tMax = std::numeric_limits<T>::infinity()) const {
    if (!(ray.dir.z != 0) || !IsFinite(ray.origin) || !IsFinite(ray.dir)) return std::nullopt;
    const T t = (irisZ_ - ray.origin.z) / ray.dir.z;
    if (!(t > 0) || !(t <= tMax)) return std::nullopt;
    Vec3<T> p = ray.origin + t * ray.dir;
    p.z = irisZ_;
    const T r2 = RadiusSquared(p);
    if (r2 > irisRadius_ * irisRadius_ || r2 < pupilRadius_ * pupilRadius_) return std::nullopt;
    return IrisHit<T>{t, p};
  }

  /// What a ray from p inside the chamber along unit d meets first (mm): the iris plane or the cornea, from
  /// inside (only exits of the anterior surface count there).
  ChamberSurfaceHit<T> NextSurfaceFromInside(const Vec3<T>& p, const Vec3<T>& d) const {
    ChamberSurfaceHit<T> hit;
    const T tPlane = d.z < 0 ? (irisZ_ - p.z) / d.z : std::numeric_limits<T>::infinity();
    auto onPlane = [&] {  // the plane point into `hit`; its radius
      hit.point = p + tPlane * d;
      hit.point.z = irisZ_;
      const T r = Radius(hit.point.x, hit.point.y);
      hit.kind = r < pupilRadius_ ? ChamberSurfaceHit<T>::Pupil : ChamberSurfaceHit<T>::Iris;
      return r;
    };
    // The chamber is convex: a ray from inside that reaches the iris plane inside the disk (with a margin for
    // rounding at its edge) has not left through the cornea before, so the cap is not intersected.
    if (tPlane < std::numeric_limits<T>::infinity() && onPlane() <= irisRadius_ * (1 - T(1e-6))) return hit;
    const auto cap = surface_.ExitFromInside({p, d});
    if (tPlane < (cap ? cap->t : std::numeric_limits<T>::infinity())) return hit;  // the plane point, set above
    hit = ChamberSurfaceHit<T>{};
    if (!cap) return hit;
    hit.kind = ChamberSurfaceHit<T>::Cornea;
    hit.point = cap->point;
    hit.normal = cap->normal;
    return hit;
  }

  /// Sclera weight at radius r (mm): 0 inside the inner limbus edge (clear cornea), 1 outside the
  /// outer edge (sclera), a C1 smoothstep between.
  T LimbusWeight(T r) const {
    if (r <= limbusInner_) return 0;
    if (r >= limbusOuter_) return 1;
    const T s = (r - limbusInner_) / (limbusOuter_ - limbusInner_);
    return s * s * (3 - 2 * s);
  }

 private:
  ChamberParams params_;
  AnteriorSurface<T> surface_;
  T irisZ_, irisRadius_, pupilRadius_, limbusInner_, limbusOuter_;
};

}  // namespace eyelib
