#include "hdeye/eyeMeshMapping.h"

#include <cmath>

namespace hdeye {

namespace {

template <class V> glm::dvec3 Interpolate(const std::vector<V>& values, const int* tri, double u, double v) {
  return (1 - u - v) * glm::dvec3(values[tri[0]]) + u * glm::dvec3(values[tri[1]]) + v * glm::dvec3(values[tri[2]]);
}

glm::dvec3 SafeNormalize(const glm::dvec3& v) {
  const double length = glm::length(v);
  return length > 0 && std::isfinite(length) ? v / length : glm::dvec3(0);
}

}  // namespace

glm::dvec3 EyeMeshOutwardNormal(const GeometryContext& context, unsigned triangle) {
  const int* tri = &(*context.triangleVertices)[3 * std::size_t(triangle)];
  const std::vector<Vec3f>& p = *context.points;
  const glm::dvec3 p0(p[tri[0]]), p1(p[tri[1]]), p2(p[tri[2]]);
  const glm::dvec3 ng = glm::cross(p1 - p0, p2 - p0);
  // The shading normals carry the orientation (winding, leftHanded); at the centroid they are never
  // far from the face's, so the sign is reliable even on coarse meshes.
  const glm::dvec3 ns = Interpolate(*context.vertexNormals, tri, 1.0 / 3, 1.0 / 3);
  return glm::dot(ng, ns) < 0 ? -ng : ng;
}

EyeMeshHit EyeMeshHitToCanonical(const GeometryContext& context, const EyeGeometry& eye, unsigned triangle,
                                 double u, double v, const glm::dvec3& worldDir) {
  const int* tri = &(*context.triangleVertices)[3 * std::size_t(triangle)];
  EyeMeshHit hit;
  // Object space -> world through the eye's transforms (canonicalToWorld = prim transform x model).
  const glm::dmat4 objectToWorld = eye.canonicalToWorld * eye.objectToCanonical;
  const glm::dvec3 current = Interpolate(*context.points, tri, u, v);
  hit.worldPoint = glm::dvec3(objectToWorld * glm::dvec4(current, 1));
  hit.worldNormal = SafeNormalize(context.normalToWorld * EyeMeshOutwardNormal(context, triangle));
  hit.fromOutside = glm::dot(worldDir, hit.worldNormal) < 0;

  // Rigid mapping: the rest point if authored (so deformation does not slide the cornea), through the
  // inverse model transform.
  const glm::dvec3 source = context.restPoints ? Interpolate(*context.restPoints, tri, u, v) : current;
  hit.canonicalPoint = glm::dvec3(eye.objectToCanonical * glm::dvec4(source, 1));
  // The current shading normal: the ray meets the surface as it is now. A similarity maps normals like
  // directions.
  glm::dvec3 n = SafeNormalize(Interpolate(*context.vertexNormals, tri, u, v));
  if (n == glm::dvec3(0)) n = SafeNormalize(EyeMeshOutwardNormal(context, triangle));
  hit.canonicalNormal = SafeNormalize(glm::dvec3(eye.objectToCanonical * glm::dvec4(n, 0)));
  return hit;
}

}  // namespace hdeye
