// Per-face materials (MeshTopology::geomSubsets) and holes through the delegate's public flow: the albedo AOV
// shows each face's material on polygon and subdivided meshes (refined faces take their parent face's), faces in
// no subset keep the mesh's material, and hole faces are not rendered.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"
#include "test_support.h"

#include <catch2/catch.hpp>

using namespace hdeye;

namespace {

/// Three unit quads side by side along x in z = 0 (faces 0, 1, 2 from left to right), seen from (0, 0, 5) by a
/// 15 x 5 albedo buffer: pixel columns 2, 7 and 12 look at the faces' middles.
struct Scene : test::RenderStack {
  static constexpr int kWidth = 15, kHeight = 5;

  explicit Scene(int refineLevel, std::vector<GeomSubset> subsets, std::vector<int> holes = {}) {
    delegate.Settings().samplesPerPixel = 1;
    MeshTopology topology;
    topology.faceVertexCounts = {4, 4, 4};
    topology.faceVertexIndices = {0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6};
    topology.refineLevel = refineLevel;
    topology.geomSubsets = std::move(subsets);
    topology.holeIndices = std::move(holes);
    std::vector<Vec3f> points;
    for (float y : {-1.5f, 1.5f})
      for (float x : {-4.5f, -1.5f, 1.5f, 4.5f}) points.push_back({x, y, 0});
    scene.AddMaterial("/blue", Material(0.1f, 0.2f, 0.9f));
    scene.AddMaterial("/red", Material(0.9f, 0.1f, 0.1f));
    scene.AddMaterial("/green", Material(0.1f, 0.8f, 0.2f));
    scene.AddMesh("/mesh", topology, points, Matrix4d(1.0), "/blue");
    CameraParams camera;
    camera.horizontalAperture = 2 * 4.5 * camera.focalLength / 5 * 15.0 / 13.0;  // the strip's width + margin
    camera.verticalAperture = camera.horizontalAperture * kHeight / kWidth;
    scene.AddCamera("/cam", camera, test::LookDownZ(5));
    scene.AddRenderBuffer("/color", kWidth, kHeight, 4);
    scene.AddRenderBuffer("/albedo", kWidth, kHeight, 3);
  }
  static MaterialParams Material(float r, float g, float b) {
    MaterialParams m;
    m.diffuseColor = {r, g, b};
    return m;
  }
  void Render() { pass.Execute("/cam", {{"color", "/color"}, {"albedo", "/albedo"}}); }
  glm::dvec3 Albedo(int x) {
    const RenderBuffer& b = Buffer("/albedo");
    return {b.Resolved(x, kHeight / 2, 0), b.Resolved(x, kHeight / 2, 1), b.Resolved(x, kHeight / 2, 2)};
  }
};

const int kFaceColumns[3] = {2, 7, 12};

}  // namespace

TEST_CASE("geomSubsets give each face its material, faces in no subset keep the mesh's (levels 0 and 2)") {
  for (int level : {0, 2}) {
    Scene s(level, {{"/red", {0}}, {"/green", {2}}});
    s.Render();
    const glm::dvec3 left = s.Albedo(kFaceColumns[0]), middle = s.Albedo(kFaceColumns[1]),
                     right = s.Albedo(kFaceColumns[2]);
    INFO("level " << level << ": albedo left " << left.x << " " << left.y << " " << left.z << ", middle " << middle.x
                  << " " << middle.y << " " << middle.z << ", right " << right.x << " " << right.y << " " << right.z);
    CHECK(left == glm::dvec3(glm::vec3(0.9f, 0.1f, 0.1f)));
    CHECK(middle == glm::dvec3(glm::vec3(0.1f, 0.2f, 0.9f)));
    CHECK(right == glm::dvec3(glm::vec3(0.1f, 0.8f, 0.2f)));
  }
}

TEST_CASE("a face in two subsets takes the first, a subset with no material takes the mesh's") {
  Scene s(0, {{"", {0}}, {"/red", {0, 1}}});
  s.Render();
  CHECK(s.Albedo(kFaceColumns[0]) == glm::dvec3(glm::vec3(0.1f, 0.2f, 0.9f)));
  CHECK(s.Albedo(kFaceColumns[1]) == glm::dvec3(glm::vec3(0.9f, 0.1f, 0.1f)));
}

TEST_CASE("hole faces are not rendered, on polygon and subdivided meshes") {
  for (int level : {0, 2}) {
    Scene s(level, {}, {1});
    s.Render();
    const auto& mesh = *static_cast<const Mesh*>(s.index.GetRprim("/mesh"));
    INFO("level " << level << ": " << mesh.TriangleCount() << " triangles");
    CHECK(mesh.TriangleCount() == 2 * 2 * (level == 0 ? 1 : 16));
    CHECK(s.Albedo(kFaceColumns[1]) == glm::dvec3(0));
    CHECK(s.Albedo(kFaceColumns[0]) != glm::dvec3(0));
  }
}

TEST_CASE("a geomSubset or hole naming a face the mesh does not have is an error naming the mesh") {
  CHECK_THAT(test::ErrorOf([] {
               Scene(0, {{"/red", {3}}}).Render();
             }),
             Catch::Contains("mesh /mesh: geomSubset /red names face 3"));
  CHECK_THAT(test::ErrorOf([] { Scene(2, {}, {-1}).Render(); }), Catch::Contains("holeIndices names face -1"));
}

TEST_CASE("displayColor shows on faces with no bound material only (Hydra's fallback surface)") {
  Scene s(2, {{"/red", {0}}});
  s.scene.SetMaterialId("/mesh", "");
  s.scene.SetPrimvar("/mesh", "displayColor", Primvar{Interpolation::Constant, 3, {0.25f, 0.5f, 0.75f}});
  s.Render();
  CHECK(s.Albedo(kFaceColumns[0]) == glm::dvec3(glm::vec3(0.9f, 0.1f, 0.1f)));
  CHECK(s.Albedo(kFaceColumns[1]) == glm::dvec3(glm::vec3(0.25f, 0.5f, 0.75f)));
}
