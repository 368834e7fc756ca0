#pragma once
// Direction sampling for the renderer's non-eye paths (BSDF lobes, light cones), with the fast sin/cos of fastTrig.h
// and eyelib's frame (eyelib/sampling.h keeps libm's sin/cos for the eye's optics).
#include "hdeye/render/fastTrig.h"

#include <eyelib/sampling.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

namespace hdeye {

/// A cosine-weighted direction about +z (pdf cos / pi), unit to rounding.
inline glm::dvec3 CosineHemisphereLocal(double u1, double u2) {
  const double r = std::sqrt(u1);
  double s, c;
  SinCos2Pi(u2, &s, &c);
  return {r * c, r * s, std::sqrt(std::max(0.0, 1 - u1))};
}

/// A direction uniform in solid angle within the cone about unit w whose half-angle theta has 1 - cos(theta) =
/// oneMinusCosMax (given as such: for a far small light it is tiny and 1 - cosMax would cancel), unit to rounding.
/// The pdf is 1 / (2 pi oneMinusCosMax).
inline glm::dvec3 SampleConeAbout(const glm::dvec3& w, double oneMinusCosMax, double u1, double u2) {
  const double oneMinusCos = u1 * oneMinusCosMax;  // 1 - cos(theta), uniform in [0, oneMinusCosMax]
  const double cosT = 1 - oneMinusCos, sinT = std::sqrt(std::max(0.0, oneMinusCos * (2 - oneMinusCos)));
  double s, c;
  SinCos2Pi(u2, &s, &c);
  glm::dvec3 t, b;
  eyelib::OrthonormalBasis(w, &t, &b);
  return cosT * w + sinT * (c * t + s * b);
}

}  // namespace hdeye
