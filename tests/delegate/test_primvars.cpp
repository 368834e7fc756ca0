// Mesh primvars through the delegate's public flow: "st", "displayColor", "normals" and "rest" under
// every interpolation the mesh accepts, on polygon and subdivided meshes; bad primvars reported by prim
// and primvar; DirtyPrimvar re-syncing primvars alone.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/prims/subdivRefiner.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

using namespace hdeye;

namespace {

/// A mesh at the origin seen by a camera at (0, 0, 5) looking down -z, with color / albedo / normal
/// buffers of odd size (the centre pixel's ray goes through the origin).
struct Scene : test::RenderStack {
  static constexpr int kSize = 9;

  Scene(const MeshTopology& topology, const std::vector<Vec3f>& points) {
    delegate.Settings().samplesPerPixel = 1;
    scene.AddMesh("/mesh", topology, points);
    scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(5));
    for (const char* b : {"/color", "/albedo", "/normal"}) scene.AddRenderBuffer(b, kSize, kSize, b[1] == 'c' ? 4 : 3);
  }
  RenderStats Render() {
    for (const char* b : {"/color", "/albedo", "/normal"}) Buffer(b).Clear();
    return pass.Execute("/cam", {{"color", "/color"}, {"albedo", "/albedo"}, {"normal", "/normal"}});
  }
  glm::dvec3 Pixel(const PrimId& id, int x, int y) {
    const RenderBuffer& b = Buffer(id);
    return {b.Resolved(x, y, 0), b.Resolved(x, y, 1), b.Resolved(x, y, 2)};
  }
  Mesh& GetMesh() { return *static_cast<Mesh*>(index.GetRprim("/mesh")); }
};

/// Two unit quads side by side in z = 0: points 0-2 along y = -1, 3-5 along y = 1; faces [0 1 4 3]
/// and [1 2 5 4]. Fan triangles: (0 1 4) (0 4 3) (1 2 5) (1 5 4), face corners (0 1 2) (0 2 3) (4 5 6) (4 6 7).
void Strip(MeshTopology* topology, std::vector<Vec3f>* points) {
  *points = {{-1, -1, 0}, {0, -1, 0}, {1, -1, 0}, {-1, 1, 0}, {0, 1, 0}, {1, 1, 0}};
  topology->faceVertexCounts = {4, 4};
  topology->faceVertexIndices = {0, 1, 4, 3, 1, 2, 5, 4};
}

Primvar Make(Interpolation interpolation, int components, std::vector<float> values) {
  return Primvar{interpolation, components, std::move(values)};
}

/// Reverses every face's winding (clockwise seen from outside).
void ReverseWinding(MeshTopology* topology) {
  std::size_t base = 0;
  for (int n : topology->faceVertexCounts) {
    std::reverse(topology->faceVertexIndices.begin() + long(base),
                 topology->faceVertexIndices.begin() + long(base + n));
    base += std::size_t(n);
  }
}

}  // namespace

TEST_CASE("st reaches every triangle corner under each interpolation on a polygon mesh") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  Strip(&topology, &points);
  Scene s(topology, points);
  const std::vector<int> vertexOfCorner = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
  const std::vector<int> faceCorner = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};

  SECTION("constant") {
    s.scene.SetPrimvar("/mesh", "st", Make(Interpolation::Constant, 2, {0.25f, 0.75f}));
    s.Render();
    REQUIRE(s.GetMesh().St().size() == 12);
    for (const Vec2f& st : s.GetMesh().St()) CHECK(st == Vec2f(0.25f, 0.75f));
  }
  SECTION("uniform: each triangle takes its face's value") {
    s.scene.SetPrimvar("/mesh", "st", Make(Interpolation::Uniform, 2, {0, 0.5f, 1, 0.25f}));
    s.Render();
    const auto& st = s.GetMesh().St();
    REQUIRE(st.size() == 12);
    for (int k = 0; k < 12; ++k) CHECK(st[k] == (k < 6 ? Vec2f(0, 0.5f) : Vec2f(1, 0.25f)));
  }
  SECTION("vertex and varying: each corner takes its point's value") {
    for (Interpolation mode : {Interpolation::Vertex, Interpolation::Varying}) {
      std::vector<float> values;
      for (const Vec3f& p : points) values.insert(values.end(), {(p.x + 1) / 2, (p.y + 1) / 2});
      s.scene.SetPrimvar("/mesh", "st", Make(mode, 2, values));
      s.Render();
      const auto& st = s.GetMesh().St();
      REQUIRE(st.size() == 12);
      for (int k = 0; k < 12; ++k) {
        const Vec3f& p = points[vertexOfCorner[k]];
        CHECK(st[k] == Vec2f((p.x + 1) / 2, (p.y + 1) / 2));
      }
    }
  }
  SECTION("faceVarying: each corner takes its face corner's value") {
    std::vector<float> values;
    for (int c = 0; c < 8; ++c) values.insert(values.end(), {float(c), float(10 * c)});
    s.scene.SetPrimvar("/mesh", "st", Make(Interpolation::FaceVarying, 2, values));
    s.Render();
    const auto& st = s.GetMesh().St();
    REQUIRE(st.size() == 12);
    for (int k = 0; k < 12; ++k) CHECK(st[k] == Vec2f(float(faceCorner[k]), float(10 * faceCorner[k])));
  }
}

TEST_CASE("displayColor primvars are interpolated at the hit with its barycentrics (albedo AOV)") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  SECTION("faceVarying on one quad: the centre lies on the diagonal, halfway between corners 0 and 2") {
    test::Quad(1, &topology, &points);
    Scene s(topology, points);
    s.scene.SetPrimvar(
        "/mesh", "displayColor",
        Make(Interpolation::FaceVarying, 3, {0.1f, 0.2f, 0.3f, 0.9f, 0.0f, 0.0f, 0.5f, 0.6f, 0.7f, 0.0f, 0.9f, 0.0f}));
    CHECK(s.Render().nonFiniteSamples == 0);
    const glm::dvec3 centre = s.Pixel("/albedo", Scene::kSize / 2, Scene::kSize / 2);
    std::printf("faceVarying displayColor at the quad centre: (%.5f %.5f %.5f), expected (0.3 0.4 0.5)\n", centre.x,
                centre.y, centre.z);
    CHECK(centre.x == Approx(0.3).margin(2e-3));
    CHECK(centre.y == Approx(0.4).margin(2e-3));
    CHECK(centre.z == Approx(0.5).margin(2e-3));
  }
  SECTION("uniform and constant on a strip: one colour per face, then one for all") {
    Strip(&topology, &points);
    Scene s(topology, points);
    s.scene.SetPrimvar("/mesh", "displayColor", Make(Interpolation::Uniform, 3, {1, 0, 0, 0, 0, 1}));
    s.Render();
    const int y = Scene::kSize / 2;
    CHECK(s.Pixel("/albedo", 2, y) == glm::dvec3(1, 0, 0));  // image x grows with world x
    CHECK(s.Pixel("/albedo", Scene::kSize - 3, y) == glm::dvec3(0, 0, 1));
    s.scene.SetPrimvar("/mesh", "displayColor", Make(Interpolation::Constant, 3, {0.2f, 0.4f, 0.6f}));
    s.Render();
    CHECK(s.Pixel("/albedo", 2, y).y == Approx(0.4));
    CHECK(s.Pixel("/albedo", Scene::kSize - 3, y).z == Approx(0.6));
    // Removing it brings back the material's colour.
    s.scene.SetPrimvar("/mesh", "displayColor", Primvar{});
    s.Render();
    CHECK(s.Pixel("/albedo", 2, y).x == Approx(0.18));
  }
}

TEST_CASE("subdivided st: vertex st refines with the points' stencils (affine precision)") {
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(1, &cube, &points);
  cube.refineLevel = 2;
  Scene s(cube, points);
  std::vector<float> values;
  for (const Vec3f& p : points) values.insert(values.end(), {p.x, 2 * p.y + p.z});
  s.scene.SetPrimvar("/mesh", "st", Make(Interpolation::Vertex, 2, values));
  s.Render();
  // Stencil weights sum to one, so an affine function of the points refines to the same function of
  // the refined points.
  SubdivRefiner refiner(cube, 8, 2);
  std::vector<Vec3f> refined;
  refiner.EvaluatePoints(points, &refined);
  const auto& st = s.GetMesh().St();
  const auto& vertices = s.GetMesh().Layout().vertices;
  REQUIRE(st.size() == vertices.size());
  double worst = 0;
  for (std::size_t k = 0; k < st.size(); ++k) {
    const Vec3f& p = refined[vertices[k]];
    worst = std::max({worst, double(std::abs(st[k].x - p.x)), double(std::abs(st[k].y - (2 * p.y + p.z)))});
  }
  std::printf("subdivided vertex st vs refined points: worst %.2e\n", worst);
  CHECK(worst < 1e-5);
}

TEST_CASE("subdivided faceVarying st on a cube keeps its seams: every face stays in its own UV island") {
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(1, &cube, &points);
  cube.refineLevel = 3;
  Scene s(cube, points);
  // Face f's island is [f, f + 1] x [0, 1]: every edge of the cube is a seam (one point, three values).
  const float corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::vector<float> values;
  for (int f = 0; f < 6; ++f)
    for (int k = 0; k < 4; ++k) values.insert(values.end(), {f + corner[k][0], corner[k][1]});
  s.scene.SetPrimvar("/mesh", "st", Make(Interpolation::FaceVarying, 2, values));
  s.Render();
  CHECK(s.GetMesh().Stats().faceVaryingRefinements == 1);
  const auto& st = s.GetMesh().St();
  const auto& faces = s.GetMesh().Layout().faces;
  REQUIRE(st.size() == 3 * faces.size());
  std::vector<glm::dvec2> lo(6, glm::dvec2(1e9)), hi(6, glm::dvec2(-1e9)), sum(6, glm::dvec2(0));
  std::vector<int> count(6, 0);
  double outside = 0;
  for (std::size_t k = 0; k < st.size(); ++k) {
    const int f = faces[k / 3];
    const glm::dvec2 v(st[k]);
    outside = std::max({outside, f - v.x, v.x - (f + 1), -v.y, v.y - 1});
    lo[f] = glm::min(lo[f], v), hi[f] = glm::max(hi[f], v), sum[f] += v, ++count[f];
  }
  std::printf("faceVarying st islands: worst excursion outside its island %.2e\n", outside);
  CHECK(outside < 1e-5);  // no blending across seams
  for (int f = 0; f < 6; ++f) {
    INFO("face " << f << ": st in [" << lo[f].x << ", " << hi[f].x << "] x [" << lo[f].y << ", " << hi[f].y << "]");
    // The island's corners are kept (cornersPlus1): its st spans the whole square ...
    CHECK(lo[f].x == Approx(f).margin(1e-5));
    CHECK(hi[f].x == Approx(f + 1).margin(1e-5));
    CHECK(lo[f].y == Approx(0).margin(1e-5));
    CHECK(hi[f].y == Approx(1).margin(1e-5));
    // ... and, the data being symmetric under the face's half turn, its mean is the square's centre.
    CHECK(sum[f].x / count[f] == Approx(f + 0.5).margin(1e-4));
    CHECK(sum[f].y / count[f] == Approx(0.5).margin(1e-4));
  }
}

TEST_CASE("authored normals shade polygon meshes, and subdivided meshes keep their limit normals") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::Quad(1, &topology, &points);
  const int c = Scene::kSize / 2;
  SECTION("vertex normals replace the computed ones (normal AOV), unit-normalised") {
    Scene s(topology, points);
    s.Render();
    CHECK(s.Pixel("/normal", c, c).z == Approx(1));
    std::vector<float> tilted;
    for (int i = 0; i < 4; ++i) tilted.insert(tilted.end(), {3, 0, 4});  // (0.6, 0, 0.8) once normalised
    s.scene.SetPrimvar("/mesh", "normals", Make(Interpolation::Vertex, 3, tilted));
    s.Render();
    const glm::dvec3 n = s.Pixel("/normal", c, c);
    CHECK(n.x == Approx(0.6).margin(1e-5));
    CHECK(n.z == Approx(0.8).margin(1e-5));
  }
  SECTION("faceVarying normals per corner") {
    Scene s(topology, points);
    // Corners 0 and 2 (the diagonal through the centre) lean to -x and +x: the centre averages to +z.
    s.scene.SetPrimvar(
        "/mesh", "normals",
        Make(Interpolation::FaceVarying, 3, {-0.6f, 0, 0.8f, 0, 0.6f, 0.8f, 0.6f, 0, 0.8f, 0, -0.6f, 0.8f}));
    s.Render();
    REQUIRE(s.GetMesh().AuthoredNormals().size() == 6);
    CHECK(s.GetMesh().AuthoredNormals()[0].x == Approx(-0.6f));
    const glm::dvec3 n = s.Pixel("/normal", c, c);
    CHECK(n.x == Approx(0).margin(1e-5));
    CHECK(n.z == Approx(1).margin(1e-5));
  }
  SECTION("a subdivided mesh ignores them") {
    MeshTopology cube;
    test::Cube(1, &cube, &points);
    cube.refineLevel = 2;
    Scene s(cube, points);
    s.Render();
    const glm::dvec3 before = s.Pixel("/normal", c, c);
    std::vector<float> sideways;
    for (int i = 0; i < 8; ++i) sideways.insert(sideways.end(), {1, 0, 0});
    s.scene.SetPrimvar("/mesh", "normals", Make(Interpolation::Vertex, 3, sideways));
    s.Render();
    CHECK(s.GetMesh().AuthoredNormals().empty());
    CHECK(s.Pixel("/normal", c, c) == before);
  }
}

TEST_CASE("a leftHanded mesh wound clockwise gets outward normals, polygon and subdivided") {
  for (int level : {0, 2}) {
    MeshTopology sphere;
    std::vector<Vec3f> points;
    test::UvSphere(1, 8, 12, &sphere, &points);
    ReverseWinding(&sphere);
    sphere.refineLevel = level;
    for (bool leftHanded : {false, true}) {
      sphere.leftHanded = leftHanded;
      Scene s(sphere, points);
      s.Render();
      const Mesh& mesh = s.GetMesh();
      int outward = 0;
      for (std::size_t i = 0; i < mesh.Points().size(); ++i)
        if (glm::dot(mesh.Normals()[i], mesh.Points()[i]) > 0) ++outward;
      INFO("level " << level << (leftHanded ? " leftHanded" : " rightHanded") << ": " << outward << " of "
                    << mesh.Points().size() << " normals outward");
      CHECK(outward == (leftHanded ? int(mesh.Points().size()) : 0));
    }
  }
}

TEST_CASE(
    "a bad primvar is dropped with one warning naming the mesh and the primvar, and the mesh renders without it") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  Strip(&topology, &points);
  Scene s(topology, points);
  s.Render();
  using Catch::Contains;
  // Each bad primvar in turn: the render goes on, the mesh keeps nothing of it, and the newest warning says why.
  auto dropped = [&](const char* name, const Primvar& primvar) {
    s.scene.SetPrimvar("/mesh", name, primvar);
    const RenderStats stats = s.Render();
    s.scene.SetPrimvar("/mesh", name, Primvar{});
    const std::vector<std::string> warnings = s.delegate.GetRenderParam()->Warnings();
    CHECK(stats.nonFiniteSamples == 0);
    CHECK(s.GetMesh().St().empty());
    return warnings.empty() ? std::string() : warnings.back();
  };
  CHECK_THAT(dropped("st", Make(Interpolation::Vertex, 2, std::vector<float>(2 * 5, 0))),
             Contains("mesh /mesh: primvar st: vertex needs 6 elements, got 5 (ignored)"));
  CHECK_THAT(dropped("st", Make(Interpolation::FaceVarying, 2, std::vector<float>(2 * 6 + 1, 0))),
             Contains("/mesh") && Contains("faceVarying needs 8 elements, got 13 values"));
  CHECK_THAT(dropped("st", Make(Interpolation::Uniform, 3, std::vector<float>(3 * 2, 0))),
             Contains("st") && Contains("3 components per element, need 2"));
  std::vector<float> color(3 * 6, 0.5f);
  color[7] = std::numeric_limits<float>::quiet_NaN();
  CHECK_THAT(dropped("displayColor", Make(Interpolation::Vertex, 3, color)),
             Contains("/mesh") && Contains("displayColor") && Contains("element 2 is not finite"));
  color[7] = std::numeric_limits<float>::infinity();
  CHECK_THAT(dropped("displayColor", Make(Interpolation::Vertex, 3, std::vector<float>(color))),
             Contains("displayColor") && Contains("not finite"));
  CHECK_THAT(dropped("rest", Make(Interpolation::Uniform, 3, std::vector<float>(3 * 2, 0))),
             Contains("/mesh") && Contains("rest") && Contains("vertex"));
  // Each message once, however often the mesh syncs.
  const std::size_t count = s.delegate.GetRenderParam()->Warnings().size();
  dropped("rest", Make(Interpolation::Uniform, 3, std::vector<float>(3 * 2, 0)));
  CHECK(s.delegate.GetRenderParam()->Warnings().size() == count);
}

TEST_CASE("DirtyPrimvar alone re-syncs primvars and nothing else") {
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(1, &cube, &points);
  cube.refineLevel = 2;
  Scene s(cube, points);
  s.Render();
  const MeshSyncStats before = s.GetMesh().Stats();
  CHECK(before.primvarSyncs == 1);
  std::vector<float> rest;
  for (const Vec3f& p : points) rest.insert(rest.end(), {p.x, p.y, p.z});
  s.scene.SetPrimvar("/mesh", "rest", Make(Interpolation::Vertex, 3, rest));
  s.Render();
  const MeshSyncStats after = s.GetMesh().Stats();
  CHECK(after.primvarSyncs == 2);
  CHECK(after.refinements == before.refinements);
  CHECK(after.topologyBuilds == before.topologyBuilds);
  CHECK(after.stencilEvaluations == before.stencilEvaluations);
  CHECK(after.pointUploads == before.pointUploads);
  CHECK(after.normalEvaluations == before.normalEvaluations);
  CHECK(after.transformUpdates == before.transformUpdates);
  // Rest positions go to the limit like the points: an undeformed mesh's rest equals its points.
  const Mesh& mesh = s.GetMesh();
  REQUIRE(mesh.RestPoints().size() == mesh.Points().size());
  double worst = 0;
  for (std::size_t i = 0; i < mesh.Points().size(); ++i)
    worst = std::max(worst, double(glm::length(mesh.RestPoints()[i] - mesh.Points()[i])));
  CHECK(worst < 1e-6);
  // Moving points leaves primvars alone.
  for (Vec3f& p : points) p *= 1.5f;
  s.scene.SetPoints("/mesh", points);
  s.Render();
  CHECK(s.GetMesh().Stats().primvarSyncs == 2);
  CHECK(s.GetMesh().Stats().stencilEvaluations == before.stencilEvaluations + 1);
}
