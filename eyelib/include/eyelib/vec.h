#pragma once
// Small value types shared by eyelib. Everything is in the canonical eye frame: millimetres, corneal
// apex at the origin, gaze along +z.
#include <glm/glm.hpp>

#include <cmath>

namespace eyelib {

template <class T> using Vec2 = glm::vec<2, T, glm::defaultp>;
template <class T> using Vec3 = glm::vec<3, T, glm::defaultp>;

/// A ray origin + t * dir. `dir` need not be unit length; t is measured in units of |dir|.
template <class T> struct Ray {
  Vec3<T> origin;  ///< mm
  Vec3<T> dir;     ///< any finite non-zero length
};

template <class T> inline bool IsFinite(const Vec3<T>& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Squared radial distance from the gaze axis, x^2 + y^2 (mm^2).
template <class T> inline T RadiusSquared(const Vec3<T>& p) { return p.x * p.x + p.y * p.y; }

/// Radial distance sqrt(x^2 + y^2) (mm) of eye-sized coordinates: no hypot, whose overflow guard costs more than
/// the square root, for values that cannot overflow.
template <class T> inline T Radius(T x, T y) { return std::sqrt(x * x + y * y); }

}  // namespace eyelib
