// Smooth shading normals through the delegate's public flow: limit normals for subdivided meshes,
// Hd_SmoothNormals-style vertex normals for polygon meshes, interpolated at the hit by the renderer and
// seen through the `normal` AOV; recomputed when points move.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/camera.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/prims/subdivRefiner.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

using namespace hdeye;

namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

double AngleDeg(const glm::dvec3& a, const glm::dvec3& b) {
  return kDegrees * std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

/// A mesh, a camera at (0, 0, 5) looking down -z, and color / normal / depth buffers of size x size.
struct Scene : test::RenderStack {
  int size;

  Scene(const MeshTopology& topology, const std::vector<Vec3f>& points, const Matrix4d& transform, int size)
      : size(size) {
    delegate.Settings().samplesPerPixel = 1;  // the data AOVs come from sample 0 (the pixel centre)
    scene.AddMesh("/mesh", topology, points, transform);
    scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(5));
    scene.AddRenderBuffer("/color", size, size, 4);
    scene.AddRenderBuffer("/normal", size, size, 3);
    scene.AddRenderBuffer("/depth", size, size, 1);
  }
  /// A fresh frame: buffers accumulate samples across renders (so sample ranges merge), hence the clear.
  void Render() {
    for (const char* b : {"/color", "/normal", "/depth"}) Buffer(b).Clear();
    pass.Execute("/cam", {{"color", "/color"}, {"normal", "/normal"}, {"depth", "/depth"}});
  }
  Mesh& GetMesh() { return *static_cast<Mesh*>(index.GetRprim("/mesh")); }

  bool OnObject(int x, int y) { return Buffer("/color").Resolved(x, y, 3) == 1.0f; }
  glm::dvec3 Normal(int x, int y) {
    const RenderBuffer& n = Buffer("/normal");
    return {n.Resolved(x, y, 0), n.Resolved(x, y, 1), n.Resolved(x, y, 2)};
  }
  /// The world hit point of pixel (x, y): the camera ray through the pixel centre, out to the depth AOV.
  glm::dvec3 HitPoint(int x, int y) {
    const CameraView& view = static_cast<Camera*>(index.GetSprim("/cam"))->View();
    const WorldRay ray = view.GenerateRay((x + 0.5) / size, (y + 0.5) / size, 1.0);
    return ray.origin + double(Buffer("/depth").Resolved(x, y, 0)) * ray.dir;
  }
};

/// A cube seen corner-on (three faces and a corner in view), squashed along its own z so that the
/// normals must go through the inverse transpose.
Matrix4d CubeTransform() {
  Matrix4d m = glm::rotate(Matrix4d(1.0), 0.6, glm::dvec3(1, 0, 0));
  m = glm::rotate(m, 0.8, glm::dvec3(0, 1, 0));
  return glm::scale(m, glm::dvec3(1, 1, 0.7));
}

}  // namespace

TEST_CASE("a level-3 subdivided cube shades with its limit normals, smooth across pixels", "[normals]") {
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(1, &cube, &points);
  cube.refineLevel = 3;
  const Matrix4d transform = CubeTransform();
  const glm::dmat3 normalToWorld = glm::transpose(glm::inverse(glm::dmat3(transform)));
  Scene s(cube, points, transform, 400);  // over 10 pixels per level-3 quad facing the camera
  s.Render();

  // The rendered geometry is the limit surface: its vertices are limit positions, each with its limit normal.
  const SubdivRefiner level3(cube, 8, 3);
  std::vector<Vec3f> limit3, normals3;
  level3.EvaluateLimit(points, &limit3, &normals3);
  REQUIRE(s.GetMesh().Points() == limit3);
  REQUIRE(s.GetMesh().Normals() == normals3);

  // Reference: the limit surface sampled densely (level 7, ~100k points), in world space.
  const SubdivRefiner dense(cube, 8, 7);
  std::vector<Vec3f> densePoints, denseNormals;
  dense.EvaluateLimit(points, &densePoints, &denseNormals);
  std::vector<glm::dvec3> worldPoints, worldNormals;
  for (std::size_t i = 0; i < densePoints.size(); ++i) {
    worldPoints.push_back(glm::dvec3(transform * glm::dvec4(glm::dvec3(densePoints[i]), 1.0)));
    worldNormals.push_back(glm::normalize(normalToWorld * glm::dvec3(denseNormals[i])));
  }

  // The facet angle flat shading would show: between the flat normals of edge-adjacent level-3 quads.
  const std::vector<int>& quads = level3.RefinedFaceIndices();
  std::map<std::pair<int, int>, std::vector<glm::dvec3>> edgeFaces;
  for (std::size_t q = 0; q < quads.size(); q += 4) {
    const glm::dvec3 a(limit3[quads[q]]), b(limit3[quads[q + 1]]), c(limit3[quads[q + 2]]), d(limit3[quads[q + 3]]);
    const glm::dvec3 flat = glm::normalize(glm::cross(c - a, d - b));
    for (int k = 0; k < 4; ++k) {
      const int i = quads[q + k], j = quads[q + (k + 1) % 4];
      edgeFaces[{std::min(i, j), std::max(i, j)}].push_back(flat);
    }
  }
  std::vector<double> facetAngles;
  for (const auto& e : edgeFaces)
    if (e.second.size() == 2) facetAngles.push_back(AngleDeg(e.second[0], e.second[1]));
  std::sort(facetAngles.begin(), facetAngles.end());
  const double medianFacet = facetAngles[facetAngles.size() / 2];

  // (a) At random hit points the shading normal is the limit normal there (the dense sample nearest to the
  // hit point); the flat normal would be off by up to half a facet angle.
  std::vector<std::pair<int, int>> object;
  for (int y = 0; y < s.size; ++y)
    for (int x = 0; x < s.size; ++x)
      if (s.OnObject(x, y)) object.push_back({x, y});
  REQUIRE(object.size() > 20000);
  std::mt19937 random(7);
  double worstLimit = 0;
  for (int k = 0; k < 500; ++k) {
    const auto [x, y] = object[random() % object.size()];
    const glm::dvec3 p = s.HitPoint(x, y), n = s.Normal(x, y);
    std::size_t nearest = 0;
    for (std::size_t i = 1; i < worldPoints.size(); ++i)
      if (glm::distance(worldPoints[i], p) < glm::distance(worldPoints[nearest], p)) nearest = i;
    worstLimit = std::max(worstLimit, AngleDeg(n, worldNormals[nearest]));
  }

  // (b) No jumps: horizontally adjacent pixels inside the object differ by far less than a facet. Only
  // where the surface faces the camera within 60 degrees: towards the silhouette one pixel spans ever more
  // surface, and even the true normal turns by up to 90 degrees within a pixel or two.
  double worstStep = 0;
  int steps = 0;
  for (int y = 0; y < s.size; ++y)
    for (int x = 0; x + 1 < s.size; ++x) {
      if (!s.OnObject(x, y) || !s.OnObject(x + 1, y)) continue;
      const glm::dvec3 toCamera = glm::normalize(glm::dvec3(0, 0, 5) - s.HitPoint(x, y));
      if (glm::dot(s.Normal(x, y), toCamera) < 0.5 || glm::dot(s.Normal(x + 1, y), toCamera) < 0.5) continue;
      worstStep = std::max(worstStep, AngleDeg(s.Normal(x, y), s.Normal(x + 1, y)));
      ++steps;
    }
  REQUIRE(steps > 15000);

  std::printf(
      "level-3 cube: %zu object pixels; facet angles median %.2f max %.2f deg; shading vs limit normal "
      "worst %.3f deg over 500 hits; worst adjacent-pixel step %.3f deg over %d pairs\n",
      object.size(), medianFacet, facetAngles.back(), worstLimit, worstStep, steps);
  CHECK(worstLimit < 2.0);
  CHECK(worstStep < 0.25 * medianFacet);
}

TEST_CASE("a polygon UV sphere's vertex normals are radial", "[normals]") {
  MeshTopology sphere;
  std::vector<Vec3f> points;
  test::UvSphere(1.5, 24, 48, &sphere, &points);
  Scene s(sphere, points, Matrix4d(1.0), 8);
  s.Render();
  const std::vector<Vec3f>& normals = s.GetMesh().Normals();
  REQUIRE(normals.size() == points.size());
  REQUIRE(s.GetMesh().Points() == points);  // level 0 renders the authored points
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    worst = std::max(worst, double(glm::length(normals[i] - glm::normalize(points[i]))));
  std::printf("UV sphere 24 x 48: worst |vertex normal - radial| %.3g\n", worst);
  CHECK(worst < 1e-5);
}

TEST_CASE("moving points moves the shading normals with them", "[normals]") {
  // Points moved by a similarity (rotation and scale) must render exactly as the unmoved points under
  // that transform: same normal AOV. Refined (limit normals) and polygon (smooth normals) meshes alike.
  const Matrix4d motion =
      glm::scale(glm::rotate(Matrix4d(1.0), 0.5, glm::normalize(glm::dvec3(1, 2, 0.5))), glm::dvec3(1.2));
  for (int level : {0, 3}) {
    MeshTopology cube;
    std::vector<Vec3f> points, moved;
    test::Cube(1, &cube, &points);
    cube.refineLevel = level;
    for (const Vec3f& p : points) moved.push_back(Vec3f(motion * glm::dvec4(glm::dvec3(p), 1.0)));

    Scene s(cube, points, Matrix4d(1.0), 64), reference(cube, points, motion, 64);
    s.Render();
    const int evaluations = s.GetMesh().Stats().normalEvaluations;
    std::vector<glm::dvec3> before;
    std::vector<bool> beforeOn;
    for (int y = 0; y < s.size; ++y)
      for (int x = 0; x < s.size; ++x) before.push_back(s.Normal(x, y)), beforeOn.push_back(s.OnObject(x, y));

    s.scene.SetPoints("/mesh", moved);
    s.Render();
    reference.Render();
    CHECK(s.GetMesh().Stats().normalEvaluations == evaluations + 1);  // once per points change
    s.scene.SetTransform("/mesh", Matrix4d(1.0));
    s.Render();
    CHECK(s.GetMesh().Stats().normalEvaluations == evaluations + 1);  // not for a transform

    double worst = 0, turned = 0;
    int both = 0;
    for (int y = 0; y < s.size; ++y)
      for (int x = 0; x < s.size; ++x) {
        if (!s.OnObject(x, y) || !reference.OnObject(x, y)) continue;
        ++both;
        worst = std::max(worst, AngleDeg(s.Normal(x, y), reference.Normal(x, y)));
        const std::size_t i = std::size_t(y) * s.size + x;
        if (beforeOn[i]) turned = std::max(turned, AngleDeg(s.Normal(x, y), before[i]));
      }
    std::printf(
        "cube level %d moved by SetPoints vs by transform: %d pixels, worst normal difference %.4f deg "
        "(normals turned by up to %.1f deg)\n",
        level, both, worst, turned);
    REQUIRE(both > 500);
    CHECK(worst < 0.05);
    CHECK(turned > 10);  // the AOV did change
  }
}
