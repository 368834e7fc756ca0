#pragma once
// Small procedural scenes for the delegate tests, and the delegate stack they are rendered through.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/hd/types.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"

#include <eyelib/anterior_surface.h>

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <vector>

namespace test {

/// An Embree ray from o along d (world), unbounded, every mask, no hit yet: for tests that trace the delegate's scene
/// directly.
inline RTCRayHit UnboundedRayHit(const glm::dvec3& o, const glm::dvec3& d) {
  RTCRayHit rh{};
  rh.ray.org_x = float(o.x), rh.ray.org_y = float(o.y), rh.ray.org_z = float(o.z);
  rh.ray.dir_x = float(d.x), rh.ray.dir_y = float(d.y), rh.ray.dir_z = float(d.z);
  rh.ray.tnear = 0, rh.ray.tfar = std::numeric_limits<float>::infinity(), rh.ray.mask = ~0u;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

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
      points->push_back(hdeye::Vec3f(float(radius * std::sin(th) * std::cos(ph)),
                                     float(radius * std::sin(th) * std::sin(ph)), float(radius * std::cos(th))));
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
    topology->faceVertexIndices.insert(topology->faceVertexIndices.end(),
                                       {south, ring(rings - 1, s + 1), ring(rings - 1, s)});
  }
}

/// An eyeball in the canonical frame (mm, apex at the origin, gaze +z): the analytic anterior surface out
/// to the 15.08 mm rim on `front` of its `rings`, then a 12 mm sphere through the rim around the back, as a
/// UV sphere's topology (counter-clockwise seen from outside). Returns the back sphere's centre on the axis
/// (mm: the eyeball's centre).
inline double EyeballMesh(int rings, int front, int segments, int refineLevel, hdeye::MeshTopology* topology,
                          std::vector<hdeye::Vec3f>* points) {
  const double pi = 3.14159265358979323846;
  UvSphere(1, rings, segments, topology, points);
  topology->refineLevel = refineLevel;
  const eyelib::AnteriorSurface<double> cornea;
  const double rim = cornea.RimRadius(), zRim = cornea.Sag(rim), R = 12;
  const double zCentre = zRim - std::sqrt(R * R - rim * rim), alpha0 = std::asin(rim / R);
  auto place = [&](int ring, double phi) {  // ring 0 (apex) .. rings (back pole)
    glm::dvec2 rz;
    if (ring <= front) {
      const double r = rim * ring / front;
      rz = glm::dvec2(r, cornea.Sag(r));
    } else {
      const double a = alpha0 + (pi - alpha0) * (ring - front) / double(rings - front);
      rz = glm::dvec2(R * std::sin(a), zCentre + R * std::cos(a));
    }
    return hdeye::Vec3f(float(rz.x * std::cos(phi)), float(rz.x * std::sin(phi)), float(rz.y));
  };
  (*points)[0] = place(0, 0);
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) (*points)[1 + (r - 1) * segments + s] = place(r, 2 * pi * s / segments);
  points->back() = place(rings, 0);
  return zCentre;
}

/// A square in the plane z = 0, half-size h, as one quad.
inline void Quad(double h, hdeye::MeshTopology* topology, std::vector<hdeye::Vec3f>* points) {
  *points = {{float(-h), float(-h), 0}, {float(h), float(-h), 0}, {float(h), float(h), 0}, {float(-h), float(h), 0}};
  topology->faceVertexCounts = {4};
  topology->faceVertexIndices = {0, 1, 2, 3};
}

/// A pure-Lambert square ("/floor", material "/mat": no specular coat, what closed forms assume) of half-size h
/// and albedo `albedo` in the plane z = 0, added to a scene delegate.
inline void AddLambertPlane(hdeye::InMemorySceneDelegate& scene, double h, double albedo) {
  hdeye::MeshTopology plane;
  std::vector<hdeye::Vec3f> points;
  Quad(h, &plane, &points);
  hdeye::MaterialParams m;
  m.diffuseColor = glm::vec3(float(albedo));
  m.ior = 1;  // F0 = 0: no coat
  scene.AddMaterial("/mat", m);
  scene.AddMesh("/floor", plane, points, hdeye::Matrix4d(1.0), "/mat");
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

/// A camera "/cam" with a 100 mm lens at (0, 0, 40) looking down -z: an analytic eye at the origin (mm) fills it.
inline void AddEyeCamera(hdeye::InMemorySceneDelegate& scene) {
  hdeye::CameraParams lens;
  lens.focalLength = 100;
  scene.AddCamera("/cam", lens, LookDownZ(40));
}

/// A sphere light `id` of `radius` (world units) and `intensity` (nits) centred at `position`.
inline void AddSphereLight(hdeye::InMemorySceneDelegate& scene, const hdeye::PrimId& id, double radius,
                           double intensity, const glm::dvec3& position) {
  hdeye::LightParams key;
  key.type = hdeye::LightType::Sphere;
  key.radius = float(radius);
  key.intensity = float(intensity);
  hdeye::Matrix4d at(1.0);
  at[3] = glm::dvec4(position, 1);
  scene.AddLight(id, hdeye::primTypes::kSphereLight, key, at);
}

/// The delegate stack a test renders through: a render delegate, its render index, an in-memory scene
/// delegate feeding that index, and a render pass over it. Test scenes derive from it and add their prims.
struct RenderStack {
  hdeye::RenderDelegate delegate;
  hdeye::RenderIndex index{&delegate};
  hdeye::InMemorySceneDelegate scene{&index};
  hdeye::RenderPass pass{&index};

  /// The render buffer bprim `id` (it must exist).
  hdeye::RenderBuffer& Buffer(const hdeye::PrimId& id) {
    return *static_cast<hdeye::RenderBuffer*>(index.GetBprim(id));
  }
};

/// The iris's MNEE light of the stack's scene seen from `camera`: the irisMnee AOV's first channel summed over a
/// pixels x pixels image rendered at `spp` samples per pixel.
inline double IrisMneeSum(RenderStack& s, const hdeye::PrimId& camera, int pixels, int spp) {
  s.scene.AddRenderBuffer("/color", pixels, pixels, 4);
  s.scene.AddRenderBuffer("/iris", pixels, pixels, 3);
  s.delegate.Settings().samplesPerPixel = spp;
  s.pass.Execute(camera, {{"color", "/color"}, {"irisMnee", "/iris"}});
  double sum = 0;
  for (int y = 0; y < pixels; ++y)
    for (int x = 0; x < pixels; ++x) sum += s.Buffer("/iris").Resolved(x, y, 0);
  return sum;
}

}  // namespace test
