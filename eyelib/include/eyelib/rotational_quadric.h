#pragma once
// A quadric of revolution about the gaze axis, F(p) = x^2 + y^2 + b z^2 + c z + e = 0, and its exact,
// numerically robust intersection with a ray. Every piece of the anterior surface (ellipsoid, offset
// cone, paraboloid) has this form, so this one routine is the whole intersection kernel.
//
// Robustness, designed rather than patched (after pbrt-v4 and Haines et al., Ray Tracing Gems ch. 7):
//  - far origins are first moved along the ray to its closest approach of the eye with one fma per
//    component, which keeps the ray exact to half an ulp of the eye's size and removes the
//    cancellation in the discriminant that a 10 m ray would otherwise suffer;
//  - the discriminant B^2 - AC is formed with Kahan's fma trick, and the roots with the cancellation-free
//    pair q / A and C / q (which also covers A = 0: rays parallel to a paraboloid's axis or a cone's
//    generator);
//  - an origin lying on the quadric within a rounding-error bound of F is treated as exactly on it: the
//    root at t = 0 is dropped and the other root is -2B/A, so rays spawned on the surface never see a
//    phantom self-hit and need no epsilon offset;
//  - each root is polished by one bounded Newton step along the ray, kept only if it lowers |F|.
#include "eyelib/vec.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace eyelib {

template <class T> struct RotationalQuadric {
  T b = 0, c = 0, e = 0;

  /// F(p), mm^2.
  T Eval(const Vec3<T>& p) const { return p.x * p.x + p.y * p.y + (b * p.z + c) * p.z + e; }

  /// Gradient of F; points away from the eye's interior for the surfaces eyelib builds.
  Vec3<T> Gradient(const Vec3<T>& p) const { return {2 * p.x, 2 * p.y, 2 * b * p.z + c}; }

  /// A bound on |F(p) - F_exact(p)| covering rounding in Eval and an error of `positionError` (mm,
  /// per coordinate) in p itself.
  T EvalErrorBound(const Vec3<T>& p, T positionError) const {
    constexpr T eps = std::numeric_limits<T>::epsilon();
    const T magnitude = p.x * p.x + p.y * p.y + std::abs(b) * p.z * p.z + std::abs(c * p.z) + std::abs(e);
    const Vec3<T> g = Gradient(p);
    return 8 * eps * magnitude + positionError * (std::abs(g.x) + std::abs(g.y) + std::abs(g.z));
  }
};

namespace detail {

template <class T> inline T DifferenceOfProducts(T a, T b, T c, T d) {
  // a*b - c*d with one rounding (Kahan).
  const T cd = c * d;
  const T err = std::fma(-c, d, cd);
  return std::fma(a, b, -cd) + err;
}

}  // namespace detail

/// Visits, in ascending order, the ray parameters t > 0 where the ray origin + t * dir (finite, dir of length near 1:
/// any length works, but keep it within a few binades of 1 so that dir*dir neither overflows nor underflows) meets
/// q, each with its point computed where it is accurate (from the re-originated ray): visit(t, point) returns true
/// to stop. A root is polished only when it is visited, so a caller that takes the first pays for one.
/// `center` and `reach` describe where the surface lives (a sphere bounding the part of interest):
/// origins outside it are re-originated near `center` first.
template <class T, class Visit> void IntersectQuadric(const RotationalQuadric<T>& q, Vec3<T> origin, const Vec3<T>& dir,
                                                      const Vec3<T>& center, T reach, Visit&& visit) {
  // Re-originate far rays at their closest approach to `center`; fma keeps the new origin on the ray.
  T tShift = 0;
  const Vec3<T> toCenter = center - origin;
  if (glm::dot(toCenter, toCenter) > reach * reach) {
    tShift = glm::dot(toCenter, dir) / glm::dot(dir, dir);
    origin = {std::fma(tShift, dir.x, origin.x), std::fma(tShift, dir.y, origin.y), std::fma(tShift, dir.z, origin.z)};
  }

  const T A = dir.x * dir.x + dir.y * dir.y + q.b * dir.z * dir.z;
  const T B = origin.x * dir.x + origin.y * dir.y + (q.b * origin.z + q.c / 2) * dir.z;  // half of b
  const T C = q.Eval(origin);

  T roots[2];
  int n = 0;
  // Hit points are computed from origins within `reach` of the centre (far origins are moved there
  // first), so a point handed back as a new origin is off the surface by a few ulps of `reach` at most.
  const T pmax = std::max({std::abs(origin.x), std::abs(origin.y), std::abs(origin.z), reach});
  constexpr T eps = std::numeric_limits<T>::epsilon();
  if (tShift == 0 && std::abs(C) <= q.EvalErrorBound(origin, 4 * eps * pmax)) {
    // Origin on the surface: t = 0 is a root; the sum of roots is -2B/A.
    if (A != 0) roots[n++] = -2 * B / A;
  } else {
    const T D = detail::DifferenceOfProducts(B, B, A, C);
    if (D < 0) return;
    const T qv = -(B + std::copysign(std::sqrt(D), B));
    if (A != 0) roots[n++] = qv / A;
    if (qv != 0) roots[n++] = C / qv;
  }
  if (n == 2 && roots[1] < roots[0]) std::swap(roots[0], roots[1]);

  // The polish may move a root by at most a quarter of the gap to the other one, so near tangency
  // it can never jump across to its partner (and the roots stay in order).
  const T maxStep = n == 2 ? std::abs(roots[1] - roots[0]) / 4 : std::abs(roots[0]) / 4;
  for (int i = 0; i < n; ++i) {
    T tl = roots[i];
    // The polish moves a root by at most maxStep: one that stays behind the origin is not worth it.
    if (!std::isfinite(tl) || tl + tShift + 2 * maxStep < 0) continue;
    Vec3<T> p = origin + tl * dir;
    const T f = q.Eval(p);
    const T df = glm::dot(q.Gradient(p), dir);
    if (df != 0 && std::abs(f) <= maxStep * std::abs(df)) {
      const T t2 = tl - f / df;
      const Vec3<T> p2 = origin + t2 * dir;
      if (std::abs(q.Eval(p2)) < std::abs(f)) {
        tl = t2;
        p = p2;
      }
    }
    const T t = tl + tShift;
    if (t > 0 && visit(t, p)) return;
  }
}

}  // namespace eyelib
