#pragma once
// Two things every code path that leaves a surface point needs: per-vertex values interpolated at a hit's
// barycentrics, and where a ray leaving the point starts.
#include <glm/glm.hpp>

#include <vector>

namespace hdeye {

/// values[tri[0..2]] (per-vertex, any glm vector of 3 floats) interpolated at barycentrics (u, v) of the
/// triangle: (1 - u - v) at tri[0], u at tri[1], v at tri[2].
template <class V> glm::dvec3 InterpolateAtTriangle(const std::vector<V>& values, const int* tri, double u, double v) {
  return (1 - u - v) * glm::dvec3(values[tri[0]]) + u * glm::dvec3(values[tri[1]]) + v * glm::dvec3(values[tri[2]]);
}

/// How far off surface point p (world units) a ray leaving it starts: more than Embree's float hit error, which
/// is a few ulps of |p|. `scale` (world units) is the absolute part: 1 by default, an eye's SpawnScale() on an
/// eye, so that an eye's offsets keep their size relative to the eye in any scene units.
inline double SpawnOffset(const glm::dvec3& p, double scale = 1) { return 1e-5 * (scale + glm::length(p)); }

/// The origin of a ray leaving surface point p on the side of unit vector `side`: p moved SpawnOffset(p, scale)
/// along it.
inline glm::dvec3 SpawnOrigin(const glm::dvec3& p, const glm::dvec3& side, double scale = 1) {
  return p + side * SpawnOffset(p, scale);
}

}  // namespace hdeye
