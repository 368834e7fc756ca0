#pragma once
// Small procedural scenes for the delegate tests.
#include "hdeye/types.h"

#include <cmath>
#include <vector>

namespace test {

/// A convex UV sphere (planar quads, triangles at the poles) of the given radius around the origin.
inline void UvSphere(double radius, int rings, int segments, hdeye::MeshTopology* topology,
                     std::vector<hdeye::Vec3f>* points) {
  const double pi = 3.14159265358979323846;
  points->clear();
  topology->faceVertexCounts.clear();
  topology->faceVertexIndices.clear();
  points->push_back({0, 0, float(radius)});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double th = pi * r / rings, ph = 2 * pi * s / segments;
      points->push_back(hdeye::Vec3f(float(radius * std::sin(th) * std::cos(ph)), float(radius * std::sin(th) * std::sin(ph)),
                                     float(radius * std::cos(th))));
    }
  points->push_back({0, 0, float(-radius)});
  const int south = int(points->size()) - 1;
  auto ring = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) {
    topology->faceVertexCounts.push_back(3);
    topology->faceVertexIndices.insert(topology->faceVertexIndices.end(), {0, ring(1, s), ring(1, s + 1)});
  }
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      topology->faceVertexCounts.push_back(4);
      topology->faceVertexIndices.insert(topology->faceVertexIndices.end(),
                                         {ring(r, s), ring(r + 1, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
  for (int s = 0; s < segments; ++s) {
    topology->faceVertexCounts.push_back(3);
    topology->faceVertexIndices.insert(topology->faceVertexIndices.end(), {south, ring(rings - 1, s + 1), ring(rings - 1, s)});
  }
}

/// A square in the plane z = 0, half-size h, as one quad.
inline void Quad(double h, hdeye::MeshTopology* topology, std::vector<hdeye::Vec3f>* points) {
  *points = {{float(-h), float(-h), 0}, {float(h), float(-h), 0}, {float(h), float(h), 0}, {float(-h), float(h), 0}};
  topology->faceVertexCounts = {4};
  topology->faceVertexIndices = {0, 1, 2, 3};
}

/// A cube of half-size h around the origin, as 6 quads.
inline void Cube(double h, hdeye::MeshTopology* topology, std::vector<hdeye::Vec3f>* points) {
  const float f = float(h);
  *points = {{-f, -f, -f}, {f, -f, -f}, {f, f, -f}, {-f, f, -f}, {-f, -f, f}, {f, -f, f}, {f, f, f}, {-f, f, f}};
  topology->faceVertexCounts = {4, 4, 4, 4, 4, 4};
  topology->faceVertexIndices = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3};
}

/// A camera at (0, 0, distance) looking down -z.
inline hdeye::Matrix4d LookDownZ(double distance) {
  hdeye::Matrix4d m(1.0);
  m[3] = glm::dvec4(0, 0, distance, 1);
  return m;
}

}  // namespace test
