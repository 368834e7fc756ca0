#pragma once
// The anterior surface of the eye as a height field z = f(r) in the canonical frame (mm, apex at the
// origin, gaze +z, r = sqrt(x^2 + y^2)), in the two models of Chiang and Burley 2018:
//  - ellipsoid-cone: 0.75 z^2 + 15.6 z + r^2 = 0 for 2r < 10.02 mm, then the 38 degree cone
//    z = f(5.01) - (r - 5.01) tan 38deg out to the 15.08 mm rim. (The paper prints z - r tan 38 = 0,
//    which omits the offset that makes the surface continuous; with it, f(7.54) = -3.734 mm, the
//    measured iris depth.)
//  - paraboloid: 14.5 z + r^2 = 0, the paper's continuous approximation, with the same 7.54 mm rim.
// Each piece is a RotationalQuadric; this class adds the piece layout, the height-field derivatives
// (sag, slope, curvature, the Hessian MNEE needs) and the exact ray intersection.
#include "eyelib/eye_constants.h"
#include "eyelib/rotational_quadric.h"
#include "eyelib/vec.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace eyelib {

enum class CorneaModel : std::uint8_t { EllipsoidCone, Paraboloid };
enum class SurfacePiece : std::uint8_t { Ellipsoid, Cone, Paraboloid };

const char* ToString(CorneaModel model);
const char* ToString(SurfacePiece piece);

/// Principal curvatures of the surface of revolution, 1/mm, positive where the surface is convex
/// (bends away from its outward normal).
template <class T> struct PrincipalCurvatures {
  T meridional;  ///< along r
  T sagittal;    ///< around the axis
};

/// The height field h(x, y) = f(r) and its first and second partial derivatives (mm, 1, 1/mm).
template <class T> struct HeightDerivatives {
  T h;
  T hx, hy;
  T hxx, hxy, hyy;
};

/// A ray's first crossing of the anterior surface.
template <class T> struct SurfaceHit {
  T t;             ///< ray parameter, in units of |ray.dir|
  Vec3<T> point;   ///< mm
  Vec3<T> normal;  ///< unit, outward (away from the anterior chamber)
  SurfacePiece piece;
  bool fromOutside;  ///< the ray arrives against the outward normal
};

template <class T> class AnteriorSurface {
 public:
  explicit AnteriorSurface(CorneaModel model = CorneaModel::EllipsoidCone) : model_(model) {
    using namespace paper;
    rim_ = T(kRimRadius);
    if (model == CorneaModel::Paraboloid) {
      junction_ = rim_;
      primary_ = {0, T(kParaboloidZ1), 0};
      zCenter_ = -std::numeric_limits<T>::infinity();
    } else {
      junction_ = T(kJunctionRadius);
      primary_ = {T(kEllipsoidZ2), T(kEllipsoidZ1), 0};
      zCenter_ = T(-kEllipsoidZ1 / (2 * kEllipsoidZ2));
      // Cone through the junction circle with slope -tan 38deg: r^2 - k^2 (zApex - z)^2 = 0, k = 1/tan.
      tanCone_ = T(TanConeAngle());
      const double zJ = EllipsoidSag(kJunctionRadius);
      const double zApex = zJ + kJunctionRadius * TanConeAngle();
      const double k2 = 1.0 / (TanConeAngle() * TanConeAngle());
      zJunction_ = T(zJ);
      zConeApex_ = T(zApex);
      cone_ = {T(-k2), T(2 * k2 * zApex), T(-k2 * zApex * zApex)};
    }
    const T smooth = std::abs(junction_ * -2 / (2 * primary_.b * PrimarySag(junction_) + primary_.c));
    maxSlope_ = model == CorneaModel::Paraboloid ? smooth : std::max(smooth, tanCone_);
    // A sphere that bounds the surface; used to re-originate far rays.
    center_ = Vec3<T>(0, 0, T(-2));
    reach_ = T(9);
  }

  CorneaModel Model() const { return model_; }
  /// Radius of the rim (half the 15.08 mm chord), mm.
  T RimRadius() const { return rim_; }
  /// Radius where the ellipsoid meets the cone (5.01 mm); equals the rim radius for the paraboloid.
  T JunctionRadius() const { return junction_; }

  /// The piece that owns radius r (mm). Radii past the rim belong to the outermost piece.
  SurfacePiece PieceAt(T r) const {
    if (model_ == CorneaModel::Paraboloid) return SurfacePiece::Paraboloid;
    return r < junction_ ? SurfacePiece::Ellipsoid : SurfacePiece::Cone;
  }

  /// The quadric of a piece, F = x^2 + y^2 + b z^2 + c z + e (mm^2).
  const RotationalQuadric<T>& Quadric(SurfacePiece piece) const {
    return piece == SurfacePiece::Cone ? cone_ : primary_;
  }

  /// Sag f(r), mm (0 at the apex, negative below). Defined for r >= 0; past the rim it extrapolates
  /// the outer piece.
  T Sag(T r) const { return PieceAt(r) == SurfacePiece::Cone ? ConeSag(r) : PrimarySag(r); }

  /// Slope df/dr (dimensionless).
  T Slope(T r) const { return PieceAt(r) == SurfacePiece::Cone ? -tanCone_ : r * SlopeOverRadius(r); }

  /// f'(r) / r, 1/mm; finite at r = 0 (the smooth pieces have f' = r * g(f)).
  T SlopeOverRadius(T r) const { return SlopeOverRadiusAtSag(r, Sag(r)); }

  /// f''(r), 1/mm.
  T SecondDerivative(T r) const {
    if (PieceAt(r) == SurfacePiece::Cone) return 0;
    const T fp = Slope(r);
    return -(2 + 2 * primary_.b * fp * fp) / (2 * primary_.b * Sag(r) + primary_.c);
  }

  /// Outward unit normal of the height field at (x, y).
  Vec3<T> Normal(T x, T y) const {
    const T g = SlopeOverRadius(std::sqrt(x * x + y * y));
    return glm::normalize(Vec3<T>(-g * x, -g * y, T(1)));
  }

  /// The steepest slope |f'(r)| on the cap (dimensionless): the sag is concave on each piece, so each piece's slope
  /// is steepest at its outer radius (the cone's is constant). About 0.78 (38 degrees) for the ellipsoid-cone, 1.04
  /// for the paraboloid.
  T MaxSlope() const { return maxSlope_; }

  PrincipalCurvatures<T> Curvatures(T r) const {
    const T fp = Slope(r);
    const T w = std::sqrt(1 + fp * fp);
    return {-SecondDerivative(r) / (w * w * w), -SlopeOverRadius(r) / w};
  }

  /// h(x, y) = f(r) with its gradient and Hessian; smooth at the axis. MNEE's inner loop: f, f'/r and
  /// f'' come from one evaluation of the sag.
  HeightDerivatives<T> Height(T x, T y) const { return HeightOnPiece(PieceAt(std::sqrt(x * x + y * y)), x, y); }

  /// The same on one piece's own analytic extension, whatever piece owns (x, y) (mm, 1, 1/mm): each piece
  /// is smooth there, where the surface itself has a slope kink and a curvature jump at the junction.
  /// The ellipsoid's extension ends where the ellipsoid does (r = 9.0 mm; its sag is clamped beyond), the
  /// cone's at its apex (r = 0, where the derivatives are not finite).
  HeightDerivatives<T> HeightOnPiece(SurfacePiece piece, T x, T y) const {
    const T r2 = x * x + y * y;
    const T r = std::sqrt(r2);
    T f, g, fpp;  // f, f'/r, f''
    if (piece == SurfacePiece::Cone) {
      f = ConeSag(r), g = -tanCone_ / r, fpp = 0;
    } else {
      f = PrimarySag(r);
      const T denom = 2 * primary_.b * f + primary_.c;  // f' = -2 r / denom
      g = -2 / denom;
      const T fp = r * g;
      fpp = -(2 + 2 * primary_.b * fp * fp) / denom;
    }
    HeightDerivatives<T> d;
    d.h = f;
    d.hx = g * x;
    d.hy = g * y;
    // h_ij = g delta_ij + (f'' - g) x_i x_j / r^2; the second term vanishes at the axis.
    const T k = r2 > 0 ? (fpp - g) / r2 : T(0);
    d.hxx = g + k * x * x;
    d.hxy = k * x * y;
    d.hyy = g + k * y * y;
    return d;
  }

  /// The other piece of the ellipsoid-cone model (the paraboloid is its own).
  SurfacePiece OtherPiece(SurfacePiece piece) const {
    if (model_ == CorneaModel::Paraboloid) return SurfacePiece::Paraboloid;
    return piece == SurfacePiece::Cone ? SurfacePiece::Ellipsoid : SurfacePiece::Cone;
  }

  /// The radius where f(r) = z, for z in [Sag(rim), 0] (mm); clamps outside that range.
  T InverseSag(T z) const {
    if (z >= 0) return 0;
    if (model_ == CorneaModel::EllipsoidCone && z <= zJunction_) return junction_ + (zJunction_ - z) / tanCone_;
    return std::sqrt(std::max(T(0), -(primary_.b * z + primary_.c) * z));
  }

  /// First crossing of the ray with the surface cap (r <= rim) for 0 < t <= tMax. Rays with a
  /// non-finite or zero direction or origin miss. A ray starting on the surface does not hit its own
  /// origin.
  std::optional<SurfaceHit<T>> Intersect(const Ray<T>& ray, T tMax = std::numeric_limits<T>::infinity()) const {
    return FirstCrossing(ray, tMax, false);
  }

  /// Whether the ray provably meets nothing of the region under the cap (the cap, or a disk closing it below):
  /// its origin lies above the cap, within the rim, and it heads away from the cap's tangent plane at the origin's
  /// radius, a plane the whole convex region lies under. A cheap test for rays leaving the eye (a shadow ray or
  /// a path from its cornea); false says nothing.
  bool HeadsAway(const Vec3<T>& origin, const Vec3<T>& dir) const {
    const T r = std::sqrt(origin.x * origin.x + origin.y * origin.y);
    if (!(r <= rim_)) return false;
    const T sag = Sag(r);
    if (!(origin.z > sag)) return false;
    const T g = SlopeOverRadiusAtSag(r, sag);  // the tangent plane's normal is (-g x, -g y, 1)
    return -g * (origin.x * dir.x + origin.y * dir.y) + dir.z >= 0;
  }

  /// Where a ray from inside the region under the cap (or from a point of the cap, heading in) leaves it through
  /// the cap: Intersect's first crossing when it is an exit, else nothing. The region is convex (the sag is concave,
  /// its kink at the junction too), so the exit is the ray's only crossing: once one piece gives it, the other
  /// piece is not tried.
  std::optional<SurfaceHit<T>> ExitFromInside(const Ray<T>& ray) const {
    auto hit = FirstCrossing(ray, std::numeric_limits<T>::infinity(), true);
    if (hit && hit->fromOutside) hit.reset();
    return hit;
  }

 private:
  /// f'(r) / r from the sag f(r) already known.
  T SlopeOverRadiusAtSag(T r, T sag) const {
    if (PieceAt(r) == SurfacePiece::Cone) return -tanCone_ / r;
    // Implicit differentiation of r^2 + b f^2 + c f = 0: f' = -2 r / (2 b f + c).
    return -2 / (2 * primary_.b * sag + primary_.c);
  }

  /// Intersect's search; `fromInside`: the origin is inside (ExitFromInside), so an exit ends it.
  std::optional<SurfaceHit<T>> FirstCrossing(const Ray<T>& ray, T tMax, bool fromInside) const {
    // Bring |dir| near 1 by a power of two when it is far from it: exact, so the ray is not
    // perturbed the way dividing by its length would (at 1 km, one rounding of the direction moves
    // the hit by 0.06 mm in float).
    const T dmax = std::max({std::abs(ray.dir.x), std::abs(ray.dir.y), std::abs(ray.dir.z)});
    if (!(dmax > 0) || !std::isfinite(dmax) || !IsFinite(ray.origin)) return std::nullopt;
    T scale = 1;
    if (dmax < T(1) / 256 || dmax > T(256)) {
      int exponent = 0;
      std::frexp(dmax, &exponent);
      scale = std::ldexp(T(1), -exponent);
    }
    const Vec3<T> d = ray.dir * scale;
    std::optional<SurfaceHit<T>> best;
    auto consider = [&](SurfacePiece piece) {
      IntersectQuadric(Quadric(piece), ray.origin, d, center_, reach_, [&](T tScaled, const Vec3<T>& p) {
        const T t = tScaled * scale;
        if (!(t <= tMax) || (best && t >= best->t)) return true;  // roots ascend: the later ones are further
        if (!OnPiece(piece, p)) return false;
        // Within a few ulps of the junction a root of one piece may be accepted; the radius decides
        // which piece, and so which normal, the hit reports.
        const SurfacePiece owner = model_ == CorneaModel::Paraboloid          ? piece
                                   : RadiusSquared(p) < junction_ * junction_ ? SurfacePiece::Ellipsoid
                                                                              : SurfacePiece::Cone;
        const Vec3<T> n = glm::normalize(Quadric(owner).Gradient(p));
        best = SurfaceHit<T>{t, p, n, owner, glm::dot(n, d) < 0};
        return true;  // the first valid root is this piece's nearest
      });
    };
    if (model_ == CorneaModel::Paraboloid) {
      consider(SurfacePiece::Paraboloid);
      return best;
    }
    // A ray from inside leaves through one piece, which the junction plane tells: only that one is intersected
    // (the other too if it yields nothing, as near the junction ring).
    const std::optional<SurfacePiece> exit = fromInside ? ExitPiece(ray.origin, d) : std::nullopt;
    if (exit) {
      consider(*exit);
      if (!best) consider(OtherPiece(*exit));
      return best;
    }
    // The cap bounds a convex region, which a ray enters at most once: an entering hit on either piece is the first
    // crossing, and the other piece need not be tried; nor, for a ray from inside, after an exit. The piece tried
    // first is the one the ray likely enters (EntryGuess).
    const SurfacePiece first = fromInside ? SurfacePiece::Ellipsoid : EntryGuess(ray.origin, d);
    consider(first);
    if (!best || (best->fromOutside == fromInside)) consider(OtherPiece(first));
    return best;
  }

  /// The piece a ray from outside more likely enters: the cone when it comes down through the junction plane
  /// z = f(5.01 mm) outside the junction disk, from above it (where the cone band lies below the plane), else the
  /// ellipsoid. Only an order: either answer gives the same crossing.
  SurfacePiece EntryGuess(const Vec3<T>& o, const Vec3<T>& d) const {
    if (!(o.z > zJunction_) || !(d.z < 0)) return SurfacePiece::Ellipsoid;
    return JunctionPlaneRadiusSquared(o, d) > junction_ * junction_ ? SurfacePiece::Cone : SurfacePiece::Ellipsoid;
  }

  /// x^2 + y^2 (mm^2) where the ray (d.z != 0) crosses the junction plane z = f(5.01 mm).
  T JunctionPlaneRadiusSquared(const Vec3<T>& o, const Vec3<T>& d) const {
    return RadiusSquared(o + (zJunction_ - o.z) / d.z * d);
  }

  /// The piece a ray from inside the region under the ellipsoid-cone cap (or from a point of the cap) leaves through:
  /// the ellipsoid owns the region above the junction plane z = f(5.01 mm), the cone the band below it, so it is the
  /// origin's side unless the ray crosses that plane inside the junction disk. Nothing within rounding of the
  /// junction ring.
  std::optional<SurfacePiece> ExitPiece(const Vec3<T>& o, const Vec3<T>& d) const {
    const bool above = o.z > zJunction_;
    const SurfacePiece own = above ? SurfacePiece::Ellipsoid : SurfacePiece::Cone;
    if (!(d.z != 0) || above == (d.z > 0)) return own;  // heads away from the plane
    const T r2 = JunctionPlaneRadiusSquared(o, d), j2 = junction_ * junction_;
    if (r2 < j2 * (1 - T(1e-6))) return OtherPiece(own);
    if (r2 > j2 * (1 + T(1e-6))) return own;
    return std::nullopt;
  }

  static double EllipsoidSag(double r) {
    using namespace paper;
    return -r * r / (kEllipsoidZ1 / 2 + std::sqrt(kEllipsoidZ1 * kEllipsoidZ1 / 4 - kEllipsoidZ2 * r * r));
  }
  // For r^2 + b z^2 + c z = 0, the root through the apex, z = -r^2 / (c/2 + sqrt(c^2/4 - b r^2)),
  // free of cancellation.
  T PrimarySag(T r) const {
    return -r * r / (primary_.c / 2 + std::sqrt(std::max(T(0), primary_.c * primary_.c / 4 - primary_.b * r * r)));
  }

  /// Whether a point of a piece's quadric belongs to the surface cap. Away from the junction the
  /// radius decides. Near it, where a grazing ray's root can land a few ulps on the wrong side in
  /// radius, the test is instead whether the point lies below the other piece (within rounding):
  /// near the junction the surface is the lower of the two pieces, and that test is well conditioned
  /// because both pieces pass through the junction circle.
  bool OnPiece(SurfacePiece piece, const Vec3<T>& p) const {
    const T r2 = RadiusSquared(p);
    const T rim2 = rim_ * rim_, j2 = junction_ * junction_;
    // Height tolerance for the near-junction test (sqrt only on that rare path).
    auto tol = [&] { return 8 * std::numeric_limits<T>::epsilon() * (1 + std::sqrt(r2) + std::abs(p.z)); };
    switch (piece) {
      case SurfacePiece::Paraboloid: return r2 <= rim2;
      case SurfacePiece::Ellipsoid:
        return p.z > zCenter_ && (r2 <= j2 || (r2 <= T(1.01) * j2 && p.z <= ConeSag(std::sqrt(r2)) + tol()));
      case SurfacePiece::Cone:
        return p.z < zConeApex_ && r2 <= rim2 &&
               (r2 >= j2 || (r2 >= T(0.99) * j2 && p.z <= PrimarySag(std::sqrt(r2)) + tol()));
    }
    return false;
  }
  T ConeSag(T r) const { return zJunction_ - (r - junction_) * tanCone_; }

  CorneaModel model_;
  T rim_, junction_;
  T tanCone_ = 0, zJunction_ = 0, zConeApex_ = 0, zCenter_ = 0, maxSlope_ = 0;
  RotationalQuadric<T> primary_;  // ellipsoid or paraboloid
  RotationalQuadric<T> cone_;
  Vec3<T> center_;
  T reach_;
};

}  // namespace eyelib
