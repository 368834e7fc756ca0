#pragma once
// Direction sampling shared by eyelib and the renderer, each routine with its pdf beside it
// (solid angle measure).
#include "eyelib/eye_constants.h"
#include "eyelib/vec.h"

#include <algorithm>
#include <cmath>

namespace eyelib {

/// Two unit vectors completing unit w to a right-handed orthonormal frame (t, b, w), continuous except where w.z
/// changes sign (Duff et al. 2017, "Building an orthonormal basis, revisited"): one division, no square root.
template <class T> inline void OrthonormalBasis(const Vec3<T>& w, Vec3<T>* t, Vec3<T>* b) {
  const T sign = std::copysign(T(1), w.z);
  const T a = -1 / (sign + w.z), c = w.x * w.y * a;
  *t = Vec3<T>(1 + sign * w.x * w.x * a, sign * c, -sign * w.x);
  *b = Vec3<T>(c, sign + w.y * w.y * a, -w.y);
}

/// A direction uniform in solid angle within the cone around unit w whose half-angle has cosine cosMax.
template <class T> inline Vec3<T> SampleUniformCone(const Vec3<T>& w, T cosMax, T u1, T u2) {
  const T cosT = 1 - u1 * (1 - cosMax), sinT = std::sqrt(std::max(T(0), 1 - cosT * cosT));
  const T phi = T(2 * paper::kPi) * u2;
  Vec3<T> t, b;
  OrthonormalBasis(w, &t, &b);
  return glm::normalize(cosT * w + sinT * (std::cos(phi) * t + std::sin(phi) * b));
}
template <class T> inline T UniformConePdf(T cosMax) { return 1 / (T(2 * paper::kPi) * (1 - cosMax)); }

/// 1 - cos(theta) from sin^2(theta), theta <= 90 degrees, without the cancellation of 1 - sqrt(1 - s^2)
/// (which loses 1 % of a cone of 1e-7 rad and all of one below 1e-8 rad in double).
template <class T> inline T OneMinusCosFromSin2(T sin2) { return sin2 / (1 + std::sqrt(std::max(T(0), 1 - sin2))); }

/// A cosine-weighted direction in the hemisphere around unit n; pdf = cos / pi.
/// t, b: OrthonormalBasis(n), for a caller that has it already (the same direction as the overload below).
template <class T>
inline Vec3<T> SampleCosineHemisphere(const Vec3<T>& n, const Vec3<T>& t, const Vec3<T>& b, T u1, T u2) {
  const T r = std::sqrt(u1), phi = T(2 * paper::kPi) * u2;
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(T(0), 1 - u1)) * n);
}
template <class T> inline Vec3<T> SampleCosineHemisphere(const Vec3<T>& n, T u1, T u2) {
  Vec3<T> t, b;
  OrthonormalBasis(n, &t, &b);
  return SampleCosineHemisphere(n, t, b, u1, u2);
}

}  // namespace eyelib
