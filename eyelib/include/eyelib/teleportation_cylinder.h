#pragma once
// The limbal-arc teleportation cylinder (Chiang and Burley 2018, section 3): a virtual cylinder inside
// the eyeball, axis along the gaze (the z axis), diameter the outer limbus edge (12.89 mm by default).
// A sclera random-walk segment that meets it continues from the diametrically opposite point,
// (x, y, z) -> (-x, -y, z), with its direction projected onto the xy plane and renormalised. This
// mimics the cornea's fibre-optic behaviour: light that enters at the limbus crosses the cornea by
// total internal reflection and lights the limbus on the other side.
//
// "No added energy", precisely: teleportation is a deterministic, lossless redirection of the walker.
// The walker's throughput weight is not touched (no pdf ratio, no cosine factor), so energy is neither
// created nor destroyed at the cylinder; the flux that leaves one side of the cylinder re-enters at the
// opposite side. The position map (x, y, z) -> (-x, -y, z) is a rotation by pi about the axis: a
// bijection of the cylinder onto itself that preserves area. The direction projection is not a
// bijection (every direction with the same azimuth maps to one horizontal direction), so the walk is
// redirected, not reversible; but a redirection only changes where energy goes, never how much there
// is. What can change is how much of it the medium absorbs on the way out, since path lengths change;
// the energy audit in tests/eyelib/test_random_walk_sss.cpp measures that (docs/limbal_arc.md).
//
// Geometry of the map: a walker leaving the cylinder at p (moving outward) arrives at -p moving inward
// in xy, and one entering at p arrives at -p moving outward; each side of the cylinder stays on its
// side. The sclera, outside the cylinder, thus never walks through the cornea: it jumps across it.
//
// Robustness, as in rotational_quadric.h: the crossing solves F(p) = x^2 + y^2 - R^2 = 0 in the xy
// plane with the cancellation-free root pair q / A, C / q and Kahan's discriminant; far origins are
// first moved to their closest approach to the axis; an origin whose |F| is within the rounding bound
// of F (a point just teleported) is exactly on the cylinder, so its t = 0 root is dropped rather than
// skipped with a magic epsilon. Crossing points are snapped radially onto the cylinder, which moves
// them by no more than their rounding error and keeps the next segment's on-cylinder test tight.
#include "eyelib/eye_constants.h"
#include "eyelib/rotational_quadric.h"
#include "eyelib/vec.h"

#include <cmath>
#include <limits>
#include <optional>

namespace eyelib {

/// Where a walk segment first meets the cylinder.
struct CylinderCrossing {
  double t = 0;        ///< mm along the segment's unit direction, in (0, length]
  Vec3<double> point;  ///< mm, on the cylinder (snapped radially to radius R)
};

/// A walker's state after teleportation.
struct TeleportedState {
  Vec3<double> point;  ///< mm, the diametrically opposite point (-x, -y, z)
  Vec3<double> dir;    ///< unit; the xy projection of the incoming direction, renormalised
};

class TeleportationCylinder {
 public:
  /// `diameter` in mm (callers pass the outer limbus diameter, 2 * AnteriorChamber::LimbusOuterRadius()).
  /// The cylinder is infinite along z unless [zMin, zMax] (mm, canonical frame) limits it; the paper
  /// does not bound it, and the eyeball's surface does. A non-finite or non-positive diameter gives a
  /// cylinder that is never crossed (Valid() false).
  explicit TeleportationCylinder(double diameter = paper::kLimbusOuterDiameter,
                                 double zMin = -std::numeric_limits<double>::infinity(),
                                 double zMax = std::numeric_limits<double>::infinity())
      : radius_(diameter / 2), zMin_(zMin), zMax_(zMax) {
    valid_ = std::isfinite(radius_) && radius_ > 0 && !std::isnan(zMin) && !std::isnan(zMax) && zMin <= zMax;
    quadric_.e = -radius_ * radius_;
  }

  bool Valid() const { return valid_; }
  double Radius() const { return radius_; }  ///< mm

  /// The first crossing of the segment origin + t * dir, 0 < t <= length (mm; dir unit), with the
  /// cylinder's side surface within [zMin, zMax]. None for NaN/Inf input, a direction parallel to the
  /// axis (its distance to the axis never changes), or an origin on the cylinder moving outward or
  /// tangentially within rounding.
  std::optional<CylinderCrossing> FirstCrossing(const Vec3<double>& origin, const Vec3<double>& dir,
                                                double length) const {
    if (!valid_ || !IsFinite(origin) || !IsFinite(dir) || !(length > 0)) return std::nullopt;
    const double A = dir.x * dir.x + dir.y * dir.y;
    if (!(A > 0)) return std::nullopt;

    // Re-originate far origins at their closest approach to the axis in xy (fma keeps the new origin
    // on the ray); then B and C are small and the discriminant suffers no cancellation.
    Vec3<double> o = origin;
    double tShift = 0;
    if (RadiusSquared(o) > 16 * radius_ * radius_) {
      tShift = -(o.x * dir.x + o.y * dir.y) / A;
      o = {std::fma(tShift, dir.x, o.x), std::fma(tShift, dir.y, o.y), std::fma(tShift, dir.z, o.z)};
    }
    const double B = o.x * dir.x + o.y * dir.y;  // half the linear coefficient
    const double C = quadric_.Eval(o);

    double roots[2];
    int n = 0;
    constexpr double eps = std::numeric_limits<double>::epsilon();
    const double positionError = 4 * eps * std::max({std::abs(o.x), std::abs(o.y), radius_});
    const double bound = quadric_.EvalErrorBound(o, positionError);
    if (tShift == 0 && std::abs(C) <= bound) {
      // On the cylinder: t = 0 is a root and the other is -2B/A. If B^2 <= A * bound the two are
      // indistinguishable within rounding (a tangent walker): no crossing at all.
      if (B < 0 && B * B > A * bound) roots[n++] = -2 * B / A;
    } else {
      const double D = detail::DifferenceOfProducts(B, B, A, C);
      if (D < 0) return std::nullopt;
      const double q = -(B + std::copysign(std::sqrt(D), B));
      roots[n++] = q / A;
      if (q != 0) roots[n++] = C / q;
      if (n == 2 && roots[1] < roots[0]) std::swap(roots[0], roots[1]);
    }
    for (int i = 0; i < n; ++i) {
      const double t = roots[i] + tShift;
      if (!(t > 0) || !(t <= length)) continue;
      const Vec3<double> p = o + roots[i] * dir;
      if (p.z < zMin_ || p.z > zMax_) continue;
      return CylinderCrossing{t, SnapToSurface(p)};
    }
    return std::nullopt;
  }

  /// The teleportation map at a crossing point (mm) with the walker's unit direction. The position
  /// (-x, -y, z) is exact (a sign flip). The direction is (dx, dy, 0) / |(dx, dy)|. A direction
  /// parallel to the axis has no projection: it is kept as it is. That adds no energy (the weight is
  /// untouched either way) and it cannot arise from FirstCrossing, which never reports a crossing for
  /// such a direction; it is only here so that no input can produce NaN.
  static TeleportedState Teleport(const Vec3<double>& point, const Vec3<double>& dir) {
    TeleportedState s{{-point.x, -point.y, point.z}, dir};
    const double len = std::hypot(dir.x, dir.y);  // hypot: no underflow for tiny components
    if (len > 0 && std::isfinite(len)) s.dir = glm::normalize(Vec3<double>(dir.x / len, dir.y / len, 0));
    return s;
  }

 private:
  // Radial projection onto the cylinder: moves an accurately computed crossing by rounding error only.
  Vec3<double> SnapToSurface(const Vec3<double>& p) const {
    const double r = std::hypot(p.x, p.y);
    if (!(r > 0)) return p;
    return {p.x * (radius_ / r), p.y * (radius_ / r), p.z};
  }

  double radius_, zMin_, zMax_;
  bool valid_ = false;
  RotationalQuadric<double> quadric_;  // x^2 + y^2 - R^2 (b = c = 0)
};

}  // namespace eyelib
