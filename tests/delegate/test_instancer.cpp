// Instancing (Instancer + one Embree instance per instance over one prototype scene): an instanced mesh renders
// as its flattened copies do, normals follow the instance's inverse transpose, per-instance colours reach the
// albedo, and moving one instance re-syncs the instancer and the instances only.
#include "hdeye/prims/mesh.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace hdeye;

namespace {

constexpr int kSize = 24;

/// A camera at (0, 0, 12) looking down -z, a sphere key light and colour / albedo / normal buffers.
struct Stage : test::RenderStack {
  Stage() {
    delegate.Settings().samplesPerPixel = 4;
    delegate.Settings().seed = 7;
    scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(12));
    LightParams key;
    key.intensity = 40, key.radius = 1;
    scene.AddLight("/key", primTypes::kSphereLight, key, glm::translate(Matrix4d(1.0), glm::dvec3(3, 4, 8)));
    for (const char* b : {"/color", "/albedo", "/normal"}) scene.AddRenderBuffer(b, kSize, kSize, b[1] == 'c' ? 4 : 3);
  }
  void Render() {
    for (const char* b : {"/color", "/albedo", "/normal"}) Buffer(b).Clear();
    pass.Execute("/cam", {{"color", "/color"}, {"albedo", "/albedo"}, {"normal", "/normal"}});
  }
  glm::dvec3 Pixel(const PrimId& id, int x, int y) {
    const RenderBuffer& b = Buffer(id);
    return {b.Resolved(x, y, 0), b.Resolved(x, y, 1), b.Resolved(x, y, 2)};
  }
  const Mesh& GetMesh(const PrimId& id) { return *static_cast<const Mesh*>(index.GetRprim(id)); }
};

/// Instance transforms on a 4 x 3 grid, each rotated, scaled non-uniformly and sheared differently.
std::vector<Matrix4d> GridTransforms() {
  std::vector<Matrix4d> out;
  for (int i = 0; i < 12; ++i) {
    Matrix4d m = glm::translate(Matrix4d(1.0), glm::dvec3(-3.3 + 2.2 * (i % 4), -2.2 + 2.2 * (i / 4), 0.1 * i));
    m = glm::rotate(m, 0.4 * i, glm::normalize(glm::dvec3(1, 0.5 * i, 0.3)));
    m = glm::scale(m, glm::dvec3(1.0 + 0.1 * i, 0.7, 1.0 - 0.03 * i));
    m[1][0] += 0.15;  // a shear: the normal matrix is not the rotation
    out.push_back(m);
  }
  return out;
}

/// Maximum absolute difference over every channel of a render buffer of two stages.
double MaxDifference(Stage& a, Stage& b, const PrimId& buffer) {
  double worst = 0;
  const int components = a.Buffer(buffer).Components();
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < components; ++c)
        worst =
            std::max(worst, double(std::abs(a.Buffer(buffer).Resolved(x, y, c) - b.Buffer(buffer).Resolved(x, y, c))));
  return worst;
}

}  // namespace

TEST_CASE("an instanced subdivision mesh renders bit-identically to its flattened copies") {
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(0.6, &cube, &points);
  cube.refineLevel = 2;
  const Matrix4d own = glm::rotate(Matrix4d(1.0), 0.3, glm::dvec3(0, 0, 1));
  const std::vector<Matrix4d> transforms = GridTransforms();

  Stage instanced, flattened;
  instanced.scene.AddInstancer("/inst", transforms);
  instanced.scene.AddMesh("/inst/proto", cube, points, own, "", "/inst");
  for (std::size_t i = 0; i < transforms.size(); ++i)
    flattened.scene.AddMesh("/copy" + std::to_string(i), cube, points, transforms[i] * own);
  instanced.Render();
  flattened.Render();

  // One refinement and one prototype scene for all twelve; the flattened scene refines twelve times.
  const MeshSyncStats& s = instanced.GetMesh("/inst/proto").Stats();
  CHECK(s.refinements == 1);
  CHECK(s.instancesDrawn == 12);
  double covered = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) covered += instanced.Buffer("/color").Resolved(x, y, 3);
  INFO("covered pixels " << covered);
  CHECK(covered > 0.1 * kSize * kSize);  // the instances are in the picture
  for (const char* b : {"/color", "/albedo", "/normal"}) {
    const double worst = MaxDifference(instanced, flattened, b);
    INFO(b << ": worst difference " << worst);
    CHECK(worst == 0.0);
  }
}

TEST_CASE("instance normals are the instance transform's inverse transpose applied to the prototype's") {
  // A quad tilted 50 degrees about x (its own transform), instanced with a non-uniform scale: the shading normal
  // at the centre pixel must be normalize(inverse transpose(S R) * z).
  MeshTopology quad;
  std::vector<Vec3f> points;
  test::Quad(1.5, &quad, &points);
  const Matrix4d tilt = glm::rotate(Matrix4d(1.0), glm::radians(50.0), glm::dvec3(1, 0, 0));
  const Matrix4d stretch = glm::scale(Matrix4d(1.0), glm::dvec3(1.0, 2.5, 1.0));
  Stage stage;
  stage.scene.AddInstancer("/inst", {stretch});
  stage.scene.AddMesh("/inst/quad", quad, points, tilt, "", "/inst");
  stage.Render();
  const glm::dvec3 expected =
      glm::normalize(glm::transpose(glm::inverse(glm::dmat3(stretch * tilt))) * glm::dvec3(0, 0, 1));
  const glm::dvec3 got = stage.Pixel("/normal", kSize / 2, kSize / 2);
  const glm::dvec3 rotatedOnly = glm::dmat3(stretch * tilt) * glm::dvec3(0, 0, 1);
  INFO("normal AOV " << got.x << " " << got.y << " " << got.z << ", expected " << expected.x << " " << expected.y << " "
                     << expected.z);
  CHECK(glm::length(got - expected) < 1e-5);
  CHECK(glm::length(got - glm::normalize(rotatedOnly)) > 0.1);  // the naive transform would be visibly wrong
}

TEST_CASE("per-instance colours replace the prototype's displayColor in the albedo") {
  MeshTopology quad;
  std::vector<Vec3f> points;
  test::Quad(0.9, &quad, &points);
  Stage stage;
  stage.scene.AddInstancer(
      "/inst",
      {glm::translate(Matrix4d(1.0), glm::dvec3(-1, 0, 0)), glm::translate(Matrix4d(1.0), glm::dvec3(1, 0, 0))},
      {Vec3f(0.8f, 0.1f, 0.2f), Vec3f(0.1f, 0.7f, 0.3f)});
  stage.scene.AddMesh("/inst/quad", quad, points, Matrix4d(1.0), "", "/inst");
  stage.Render();
  const glm::dvec3 left = stage.Pixel("/albedo", kSize / 2 - 4, kSize / 2),
                   right = stage.Pixel("/albedo", kSize / 2 + 4, kSize / 2);
  INFO("left " << left.x << " " << left.y << " " << left.z << ", right " << right.x << " " << right.y << " "
               << right.z);
  CHECK(glm::length(left - glm::dvec3(0.8, 0.1, 0.2)) < 1e-6);
  CHECK(glm::length(right - glm::dvec3(0.1, 0.7, 0.3)) < 1e-6);
}

TEST_CASE("moving one instance re-syncs the instancer and the instances only") {
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(0.6, &cube, &points);
  cube.refineLevel = 1;
  std::vector<Matrix4d> transforms = GridTransforms();
  Stage stage;
  stage.scene.AddInstancer("/inst", transforms);
  stage.scene.AddMesh("/inst/proto", cube, points, Matrix4d(1.0), "", "/inst");
  stage.scene.AddMesh("/other", cube, points, glm::translate(Matrix4d(1.0), glm::dvec3(0, 0, -5)));
  stage.Render();
  const MeshSyncStats before = stage.GetMesh("/inst/proto").Stats(), otherBefore = stage.GetMesh("/other").Stats();
  const int instancerSyncs = stage.index.GetInstancer("/inst")->SyncCount();
  const double pixelBefore = stage.Buffer("/color").Resolved(kSize / 2, kSize / 2, 0);

  transforms[5] = glm::translate(Matrix4d(1.0), glm::dvec3(0, 0, 2));  // one instance moves to the centre
  stage.scene.SetInstanceTransforms("/inst", transforms);
  CHECK(stage.index.GetChangeTracker().GetDirtyBits("/inst/proto") == dirty::DirtyInstancer);
  CHECK(stage.index.GetChangeTracker().GetDirtyBits("/other") == dirty::Clean);
  stage.Render();
  const MeshSyncStats& after = stage.GetMesh("/inst/proto").Stats();
  const MeshSyncStats& otherAfter = stage.GetMesh("/other").Stats();
  CHECK(stage.index.GetInstancer("/inst")->SyncCount() == instancerSyncs + 1);
  CHECK(after.instanceSyncs == before.instanceSyncs + 1);
  CHECK(after.topologyBuilds == before.topologyBuilds);
  CHECK(after.refinements == before.refinements);
  CHECK(after.stencilEvaluations == before.stencilEvaluations);
  CHECK(after.pointUploads == before.pointUploads);
  CHECK(after.primvarSyncs == before.primvarSyncs);
  CHECK(after.transformUpdates == before.transformUpdates);
  CHECK(otherAfter.instanceSyncs == otherBefore.instanceSyncs);
  CHECK(otherAfter.pointUploads == otherBefore.pointUploads);
  const double pixelAfter = stage.Buffer("/color").Resolved(kSize / 2, kSize / 2, 0);
  INFO("centre pixel red before " << pixelBefore << ", after " << pixelAfter);
  CHECK(pixelAfter != pixelBefore);  // the moved instance is seen
}

TEST_CASE("instances with a singular or non-finite transform are not drawn, and a missing instancer is an error") {
  MeshTopology quad;
  std::vector<Vec3f> points;
  test::Quad(0.5, &quad, &points);
  Stage stage;
  Matrix4d nan(1.0);
  nan[3][0] = std::nan("");
  stage.scene.AddInstancer("/inst", {Matrix4d(1.0), glm::scale(Matrix4d(1.0), glm::dvec3(0)),
                                     glm::translate(Matrix4d(1.0), glm::dvec3(1, 0, 0))});
  stage.scene.AddMesh("/inst/quad", quad, points, Matrix4d(1.0), "", "/inst");
  stage.Render();
  CHECK(stage.GetMesh("/inst/quad").Stats().instancesDrawn == 2);
  stage.scene.SetInstanceTransforms("/inst", {nan});
  CHECK_THROWS_WITH(stage.Render(), Catch::Contains("/inst") && Catch::Contains("non-finite"));

  Stage orphan;
  orphan.scene.AddMesh("/quad", quad, points, Matrix4d(1.0), "", "/missing");
  CHECK_THROWS_WITH(orphan.Render(), Catch::Contains("/quad") && Catch::Contains("instancer /missing does not exist"));
}
