#pragma once
// Random directions and points for property tests.
#include "eyelib/vec.h"

#include <cmath>
#include <random>

namespace test {

inline double Uniform(std::mt19937_64& rng, double lo = 0, double hi = 1) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline eyelib::Vec3<double> UniformSphere(std::mt19937_64& rng) {
  const double z = Uniform(rng, -1, 1), phi = Uniform(rng, 0, 2 * 3.14159265358979323846);
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

/// Any unit vector perpendicular to n.
inline eyelib::Vec3<double> Perpendicular(const eyelib::Vec3<double>& n) {
  const eyelib::Vec3<double> a = std::abs(n.x) < 0.9 ? eyelib::Vec3<double>(1, 0, 0) : eyelib::Vec3<double>(0, 1, 0);
  return glm::normalize(glm::cross(n, a));
}

}  // namespace test

namespace test {

/// Rounds a double vector to precision T and back. Not inlined: GCC 12's SLP vectoriser at -O2 was
/// seen to fold the double -> float -> double round trip of glm vectors into nothing, which would
/// hand the reference a different ray from the one the float kernel saw.
template <class T> [[gnu::noinline]] eyelib::Vec3<T> RoundTo(const eyelib::Vec3<double>& v) {
  volatile T x = static_cast<T>(v.x), y = static_cast<T>(v.y), z = static_cast<T>(v.z);
  return {x, y, z};
}

}  // namespace test
