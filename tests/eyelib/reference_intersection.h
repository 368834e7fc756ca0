#pragma once
// An independent reference for ray/anterior-surface intersection: golden-section search and
// bisection in long double on the height-field residual g(t) = z(t) - f(r(t)), with f written
// straight from the paper's equations. It shares no code with eyelib's quadric kernel.
//
// The cap's hypograph {z <= f(r), r <= rim} is convex (f is concave and non-increasing), so g is
// convex along any ray: it has one minimum, and at most one crossing on each side of it.
#include "eyelib/anterior_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace test {

using LD = long double;

struct ReferenceHit {
  bool hit = false;
  double t = 0;                   ///< in units of |dir|
  eyelib::Vec3<double> point;     ///< mm
  double rimMargin = 1e300;       ///< mm: how near the ray passes the rim circle (|g| where it crosses r = rim)
  double tangencyMargin = 1e300;  ///< mm: how near the ray is to grazing the surface (|min g| inside the cap)
  double originMargin = 1e300;    ///< mm: how near the origin is to the surface (rays not said to start on it)
  bool ambiguous = false;         ///< the answer is not determined at double precision

  /// Whether hit-or-miss is decided by more than `tolerance` mm of geometry.
  bool Decided(double tolerance) const {
    return rimMargin > tolerance && tangencyMargin > tolerance && originMargin > tolerance;
  }
};

inline LD PaperSag(eyelib::CorneaModel model, LD r) {
  if (model == eyelib::CorneaModel::Paraboloid) return -r * r / 14.5L;
  auto ellipsoid = [](LD rr) { return -2 * rr * rr / (15.6L + std::sqrt(15.6L * 15.6L - 3 * rr * rr)); };
  const LD rj = 10.02L / 2, tan38 = std::tan(38.0L * 3.14159265358979323846264338327950288L / 180);
  return r < rj ? ellipsoid(r) : ellipsoid(rj) - (r - rj) * tan38;
}

/// First crossing for t > 0 of origin + t * dir with the cap, or no hit. For a ray that starts on
/// the surface (within `originTolerance` mm), the crossing nearest the origin is the origin itself and
/// is dropped, whichever side of the surface rounding put the origin on.
inline ReferenceHit ReferenceIntersect(eyelib::CorneaModel model, const eyelib::Vec3<double>& origin,
                                       const eyelib::Vec3<double>& dir, bool startsOnSurface = false,
                                       double originTolerance = 0) {
  const LD ox = origin.x, oy = origin.y, oz = origin.z, dx = dir.x, dy = dir.y, dz = dir.z;
  const LD rim = 15.08L / 2;
  ReferenceHit out;
  auto g = [&](LD t) {
    const LD x = ox + t * dx, y = oy + t * dy;
    return oz + t * dz - PaperSag(model, std::min(rim, std::sqrt(x * x + y * y)));
  };
  if (!startsOnSurface && ox * ox + oy * oy <= rim * rim) out.originMargin = double(std::abs(g(0)));
  // The whole line's parameter interval inside the rim cylinder and the slab -5 <= z <= 1.
  const LD inf = std::numeric_limits<LD>::infinity();
  LD ta = -inf, tb = inf;
  const LD a = dx * dx + dy * dy, b = ox * dx + oy * dy, c = ox * ox + oy * oy - rim * rim;
  if (a == 0) {
    if (c > 0) return out;
  } else {
    const LD disc = b * b - a * c;
    if (disc < 0) return out;
    const LD s = std::sqrt(disc);
    ta = (-b - s) / a;
    tb = (-b + s) / a;
    for (LD tc : {ta, tb})  // where the ray crosses the rim circle's cylinder, how far from the rim?
      if (tc > 0) out.rimMargin = std::min(out.rimMargin, double(std::abs(oz + tc * dz - PaperSag(model, rim))));
  }
  if (dz == 0) {
    if (oz < -5 || oz > 1) return out;
  } else {
    const LD t1 = (-5 - oz) / dz, t2 = (1 - oz) / dz;
    ta = std::max(ta, std::min(t1, t2));
    tb = std::min(tb, std::max(t1, t2));
  }
  if (!(ta < tb)) {
    out.ambiguous = !out.Decided(1e-12);
    return out;
  }

  // Golden-section search for the minimum of the convex g.
  LD lo = ta, hi = tb;
  const LD invPhi = (std::sqrt(5.0L) - 1) / 2;
  for (int i = 0; i < 400 && hi - lo > 0; ++i) {
    const LD m1 = hi - invPhi * (hi - lo), m2 = lo + invPhi * (hi - lo);
    if (g(m1) < g(m2))
      hi = m2;
    else
      lo = m1;
  }
  const LD tMin = (lo + hi) / 2, gMin = g(tMin);
  const LD span = tb - ta;
  if (tMin - ta > 1e-12L * span && tb - tMin > 1e-12L * span && tMin > 0) out.tangencyMargin = double(std::abs(gMin));

  auto bisect = [&](LD l, LD h) {  // g(l) and g(h) of opposite signs
    const bool rising = g(l) < 0;
    for (int i = 0; i < 400; ++i) {
      const LD m = (l + h) / 2;
      if (m <= l || m >= h) break;
      ((g(m) < 0) == rising ? l : h) = m;
    }
    return (l + h) / 2;
  };
  LD roots[2];
  int n = 0;
  if (gMin <= 0 && g(ta) > 0) roots[n++] = bisect(ta, tMin);
  if (gMin <= 0 && g(tb) > 0) roots[n++] = bisect(tMin, tb);
  if (startsOnSurface && n > 0 && std::abs(g(0)) <= originTolerance) {
    if (n == 2 && std::abs(roots[0]) < std::abs(roots[1])) roots[0] = roots[1];
    --n;
  }
  LD tHit = inf;
  for (int i = 0; i < n; ++i)
    if (roots[i] > 0) tHit = std::min(tHit, roots[i]);
  out.ambiguous = !out.Decided(1e-12);
  if (tHit == inf) return out;
  out.hit = true;
  out.t = double(tHit);
  out.point = {double(ox + tHit * dx), double(oy + tHit * dy), double(oz + tHit * dz)};
  return out;
}

}  // namespace test
