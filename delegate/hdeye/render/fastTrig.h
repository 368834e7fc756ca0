#pragma once
// sin and cos of 2 pi u for the renderer's direction sampling (the cosine hemisphere, GGX visible normals, light
// cones, the lens, the dome): a quadrant reduction and two short polynomials, branch-free, about 4x cheaper than
// libm's sincos, to 1e-13 absolute (far below what a sample direction needs, as pbrt-v4 and Cycles also
// judge). Not for optics: eyelib's refraction and MNEE keep libm.
#include <cstdint>
#include <cstring>

namespace hdeye {

/// *s = sin(a), *c = cos(a) for |a| <= pi/4: Taylor series to a^13 and a^14, whose remainders at pi/4 are 2e-14
/// and 1e-15 (so s^2 + c^2 = 1 to 1e-13: directions built from them are unit to that).
inline void SinCosReduced(double a, double* s, double* c) {
  const double a2 = a * a;
  *s = a * (1 + a2 * (-1.0 / 6 +
                      a2 * (1.0 / 120 + a2 * (-1.0 / 5040 + a2 * (1.0 / 362880 +
                                                                  a2 * (-1.0 / 39916800 + a2 * (1.0 / 6227020800)))))));
  *c = 1 + a2 * (-0.5 + a2 * (1.0 / 24 +
                              a2 * (-1.0 / 720 +
                                    a2 * (1.0 / 40320 +
                                          a2 * (-1.0 / 3628800 + a2 * (1.0 / 479001600 - a2 * (1.0 / 87178291200)))))));
}

/// *s = sin(2 pi u), *c = cos(2 pi u) for u in [0, 1] (any u in [0, 2^50) works: the reduction is to the nearest
/// quarter turn, by truncation, so not for negative u). Absolute error below 1e-13.
inline void SinCos2Pi(double u, double* s, double* c) {
  // u = k / 4 + r with r in [-1/8, 1/8]: the angle a = 2 pi r lies in [-pi/4, pi/4].
  const std::int64_t k = std::int64_t(4 * u + 0.5);  // the nearest quarter (truncation: u >= 0)
  const double a = 6.283185307179586477 * (u - 0.25 * double(k));
  double sa, ca;
  SinCosReduced(a, &sa, &ca);
  // Quadrant k mod 4: (sin, cos) = (sa, ca), (ca, -sa), (-sa, -ca), (-ca, sa). Selected with bit masks, not
  // branches (the quadrant of a random number mispredicts three times in four).
  const std::uint64_t swap = std::uint64_t(0) - std::uint64_t(k & 1);
  std::uint64_t bs, bc;
  std::memcpy(&bs, &sa, 8), std::memcpy(&bc, &ca, 8);
  std::uint64_t rs = (bs & ~swap) | (bc & swap), rc = (bc & ~swap) | (bs & swap);
  rs ^= std::uint64_t(k & 2) << 62;        // quadrants 2 and 3: sin negative
  rc ^= std::uint64_t((k + 1) & 2) << 62;  // quadrants 1 and 2: cos negative
  std::memcpy(s, &rs, 8), std::memcpy(c, &rc, 8);
}

}  // namespace hdeye
