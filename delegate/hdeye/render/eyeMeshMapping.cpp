#include "hdeye/render/eyeMeshMapping.h"

#include "hdeye/render/surfacePoint.h"

#include <cmath>

namespace hdeye {

namespace {

glm::dvec3 SafeNormalize(const glm::dvec3& v) {
  const double length = glm::length(v);
  return length > 0 && std::isfinite(length) ? v / length : glm::dvec3(0);
}

bool Finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// A unit tangent at unit normal n from a preferred direction (its part orthogonal to n), else from
/// `second` (when `preferred` is nearly parallel to n). Never zero for unit n.
glm::dvec3 Tangent(const glm::dvec3& n, const glm::dvec3& preferred, const glm::dvec3& second) {
  glm::dvec3 t = SafeNormalize(preferred - glm::dot(preferred, n) * n);
  if (glm::length(preferred - glm::dot(preferred, n) * n) < 1e-3 * glm::length(preferred) || t == glm::dvec3(0))
    t = SafeNormalize(second - glm::dot(second, n) * n);
  if (t == glm::dvec3(0))
    t = SafeNormalize(glm::cross(n, std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  return t;
}

/// Keeps a unit direction at least kMinCos away from the plane with unit normal n, on the side `sign`
/// (+1: along n, -1: against it). Grazing rays that a turn pushed across the plane come back just over it.
glm::dvec3 KeepSide(glm::dvec3 d, const glm::dvec3& n, double sign) {
  constexpr double kMinCos = 1e-4;
  const double c = sign * glm::dot(d, n);
  if (c < kMinCos) d = SafeNormalize(d + sign * (kMinCos - c) * n);
  return d == glm::dvec3(0) ? sign * n : d;
}

}  // namespace

glm::dvec3 EyeMeshOutwardNormal(const GeometryContext& context, unsigned triangle) {
  const int* tri = &(*context.triangleVertices)[3 * std::size_t(triangle)];
  const std::vector<Vec3f>& p = *context.points;
  const glm::dvec3 p0(p[tri[0]]), p1(p[tri[1]]), p2(p[tri[2]]);
  const glm::dvec3 ng = glm::cross(p1 - p0, p2 - p0);
  // The shading normals carry the orientation (winding, leftHanded); at the centroid they are never
  // far from the face's, so the sign is reliable even on coarse meshes. A mesh deformed inside out
  // (a mirror) turns both around; its outwardSign turns them back.
  const glm::dvec3 ns = InterpolateAtTriangle(*context.vertexNormals, tri, 1.0 / 3, 1.0 / 3);
  const double sign = context.meshEye ? context.meshEye->outwardSign : 1.0;
  return glm::dot(ng, ns) < 0 ? -sign * ng : sign * ng;
}

EyeMeshHit EyeMeshHitToCanonical(const GeometryContext& context, const EyeGeometry& eye, unsigned triangle, double u,
                                 double v, const glm::dvec3& worldDir) {
  const int* tri = &(*context.triangleVertices)[3 * std::size_t(triangle)];
  const std::vector<Vec3f>& points = *context.points;
  EyeMeshHit hit;
  hit.reprojected = eye.reprojection;
  const glm::dvec3 current = InterpolateAtTriangle(points, tri, u, v);
  hit.worldPoint = glm::dvec3(eye.objectToWorld * glm::dvec4(current, 1));

  // The deformed surface, world: outward geometric normal (decides the side) and shading normal
  // (decides the angles). Fallbacks for degenerate triangles: each other, then the analytic normal
  // placed rigidly (filled in below, once the analytic point is known).
  const double sign = eye.outwardSign;
  glm::dvec3 ng = SafeNormalize(context.normalToWorld * EyeMeshOutwardNormal(context, triangle));
  glm::dvec3 ns =
      SafeNormalize(context.normalToWorld * (sign * InterpolateAtTriangle(*context.vertexNormals, tri, u, v)));
  if (ns == glm::dvec3(0)) ns = ng;
  if (ng == glm::dvec3(0)) ng = ns;

  // Position: the rest point (else the current one: no rest pose, no deformation to undo) in the
  // projection frame, or, for the baseline, the current point in the eye's affine frame.
  const bool rest = eye.reprojection && context.restPoints;
  const std::vector<Vec3f>& source = rest ? *context.restPoints : points;
  const glm::dmat4& toCanonical = eye.reprojection ? eye.objectToProjection : eye.objectToCanonical;
  hit.canonicalPoint = glm::dvec3(toCanonical * glm::dvec4(InterpolateAtTriangle(source, tri, u, v), 1));
  if (!Finite(hit.canonicalPoint)) hit.canonicalPoint = glm::dvec3(1e30, 0, 0);  // beyond every rim: sclera

  const eyelib::AnteriorSurface<double>& surface = eye.chamber.Surface();
  const double x = hit.canonicalPoint.x, y = hit.canonicalPoint.y, r = std::hypot(x, y);
  hit.onCornea = r < eye.chamber.LimbusOuterRadius() && hit.canonicalPoint.z >= eye.chamber.IrisZ();
  if (hit.onCornea) {
    hit.analyticPoint = glm::dvec3(x, y, surface.Sag(r));
    hit.analyticNormal = surface.Normal(x, y);
  }
  if (ng == glm::dvec3(0)) ng = ns = eye.DirToWorld(hit.analyticNormal);
  hit.worldNormal = ng;
  hit.fromOutside = glm::dot(worldDir, ng) < 0;
  if (!hit.onCornea) return hit;
  const glm::dvec3& na = hit.analyticNormal;

  if (!eye.reprojection) {
    // Baseline: the world direction through the eye's (affine) frame, as the analytic eye would see it.
    hit.canonicalDir = KeepSide(eye.DirToCanonical(worldDir), na, -1);
    return hit;
  }

  // The local rotation. Tangent references: the canonical x axis on the analytic side, its rigid world
  // image on the deformed side (so an undeformed eye gets exactly the rigid rotation), each projected
  // into its tangent plane.
  const glm::dvec3 xWorld = eye.DirToWorld(glm::dvec3(1, 0, 0)), yWorld = eye.DirToWorld(glm::dvec3(0, 1, 0));
  const glm::dvec3 ta0 = Tangent(na, glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0)), ba0 = glm::cross(na, ta0);
  const glm::dvec3 td0 = Tangent(ns, xWorld, yWorld), bd0 = glm::cross(ns, td0);
  // The angle that best turns the triangle's edges, projected rest (canonical) -> deformed (world), each
  // in its tangent basis: 2-D Procrustes, atan2(sum a x d, sum a . d). Scale drops out; a degenerate
  // triangle on either side gives no information and keeps the reference (angle 0).
  const std::vector<Vec3f>& restSource = context.restPoints ? *context.restPoints : points;
  const glm::dvec3 c0(eye.objectToProjection * glm::dvec4(glm::dvec3(restSource[tri[0]]), 1));
  const glm::dvec3 w0(eye.objectToWorld * glm::dvec4(glm::dvec3(points[tri[0]]), 1));
  double sumCos = 0, sumSin = 0, normA = 0, normD = 0;
  for (int k = 1; k < 3; ++k) {
    const glm::dvec3 ea = glm::dvec3(eye.objectToProjection * glm::dvec4(glm::dvec3(restSource[tri[k]]), 1)) - c0;
    const glm::dvec3 ed = glm::dvec3(eye.objectToWorld * glm::dvec4(glm::dvec3(points[tri[k]]), 1)) - w0;
    const glm::dvec2 a(glm::dot(ea, ta0), glm::dot(ea, ba0)), d(glm::dot(ed, td0), glm::dot(ed, bd0));
    sumCos += a.x * d.x + a.y * d.y;
    sumSin += a.x * d.y - a.y * d.x;
    normA += glm::dot(a, a), normD += glm::dot(d, d);
  }
  double angle = 0;
  if (std::hypot(sumCos, sumSin) > 1e-9 * std::sqrt(normA * normD) && std::isfinite(sumCos + sumSin))
    angle = std::atan2(sumSin, sumCos);
  const glm::dvec3 td = std::cos(angle) * td0 + std::sin(angle) * bd0, bd = glm::cross(ns, td);
  // R = [ta0 ba0 na] [td bd ns]^T: world -> canonical, a proper rotation (both bases right-handed).
  const glm::dmat3 analyticBasis(ta0, ba0, na), deformedBasis(td, bd, ns);
  hit.worldToLocal = analyticBasis * glm::transpose(deformedBasis);
  // A ray at grazing incidence against the shading normal may turn tangent or outgoing: bend it just
  // under the tangent plane (a grazing entry, where Fresnel reflects nearly all of it anyway).
  hit.canonicalDir = KeepSide(SafeNormalize(hit.worldToLocal * worldDir), na, -1);
  return hit;
}

glm::dvec3 EyeMeshLeavingDirection(const EyeMeshHit& hit, const glm::dvec3& canonicalDir) {
  const glm::dvec3 d = SafeNormalize(glm::transpose(hit.worldToLocal) * canonicalDir);
  // The ray must leave on the outside of the triangle it met: a shading normal or the turn can tilt it under.
  return KeepSide(d == glm::dvec3(0) ? hit.worldNormal : d, hit.worldNormal, 1);
}

}  // namespace hdeye
