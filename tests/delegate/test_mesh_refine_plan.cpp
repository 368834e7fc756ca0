// The render plan's subdivision level for plain meshes: the eye meshes' screen-size rule on each mesh's projected
// bounding sphere (largest over its instances), applied; meshes first synced under the plan wait at level 0.
#include "hdeye/plan/renderPlan.h"
#include "hdeye/prims/mesh.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>

using namespace hdeye;

namespace {

/// A camera at (0, 0, 10) looking down -z (50 mm lens, 36 mm film) and a level-2 cube of half-size `h` at the origin.
struct CubeScene : test::RenderStack {
  explicit CubeScene(double h, const PrimId& instancer = "") {
    MeshTopology cube;
    std::vector<Vec3f> points;
    test::Cube(h, &cube, &points);
    cube.refineLevel = 2;
    scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(10));
    scene.AddMesh("/cube", cube, points, Matrix4d(1.0), "", instancer);
  }
  const Mesh& GetMesh() { return *static_cast<const Mesh*>(index.GetRprim("/cube")); }
  const MeshPlan& Planned(const RenderPlan& plan) {
    REQUIRE(plan.meshes.size() == 1);
    return plan.meshes[0];
  }
};

}  // namespace

TEST_CASE("a mesh a few pixels wide is planned and rendered at level 0, and one filling the frame at level 2") {
  CubeScene small(0.05);  // bounding sphere 0.087 units at 10: about 7 px of 128
  const RenderPlan plan = small.pass.Plan("/cam", 128, 128, PlanOverrides{});
  const MeshPlan& m = small.Planned(plan);
  INFO("pixels " << m.pixels << ": " << m.why);
  CHECK(m.pixels == Approx(0.05 * std::sqrt(3.0) * 50 / (10 * 18) * 128).epsilon(1e-6));
  CHECK(m.refineLevel == 0);
  CHECK(m.sceneLevel == 2);
  CHECK(small.GetMesh().RefineLevel() == 0);  // waited for the plan at level 0
  CHECK(small.GetMesh().Stats().refinements == 0);
  RenderSettings settings;
  ApplyRenderPlan(plan, &small.index, &settings);
  small.index.SyncAll();
  CHECK(small.GetMesh().RefineLevel() == 0);
  CHECK(small.GetMesh().Stats().refinements == 0);  // never refined: the plan kept level 0

  CubeScene big(3.0);
  const RenderPlan bigPlan = big.pass.Plan("/cam", 128, 128, PlanOverrides{});
  INFO(big.Planned(bigPlan).why);
  CHECK(big.Planned(bigPlan).refineLevel == 2);
  ApplyRenderPlan(bigPlan, &big.index, &settings);
  big.index.SyncAll();
  CHECK(big.GetMesh().RefineLevel() == 2);
  CHECK(big.GetMesh().Stats().refinements == 1);  // level 0 first (no refinement), then level 2 once
  const std::vector<std::string> lines = bigPlan.SummaryLines();
  CHECK(std::any_of(lines.begin(), lines.end(),
                    [](const std::string& l) { return l.find("level 2 x1") != std::string::npos; }));

  // The --complexity ceiling caps it; clearing the plan gives the scene's level back.
  PlanOverrides low;
  low.refineLevelCeiling = 1;
  const RenderPlan lowPlan = big.pass.Plan("/cam", 128, 128, low);
  CHECK(big.Planned(lowPlan).refineLevel == 1);
  ClearRenderPlan(&big.index);
  big.index.SyncAll();
  CHECK(big.GetMesh().RefineLevel() == 2);
}

TEST_CASE("an instanced mesh is planned by its largest instance on screen") {
  CubeScene crowd(0.05, "/inst");
  crowd.scene.AddInstancer(
      "/inst", {glm::translate(Matrix4d(1.0), glm::dvec3(-1, 0, 0)), glm::scale(Matrix4d(1.0), glm::dvec3(200.0))});
  const RenderPlan plan = crowd.pass.Plan("/cam", 128, 128, PlanOverrides{});
  const MeshPlan& m = crowd.Planned(plan);
  INFO(m.why);
  CHECK(m.instances == 2);
  CHECK(m.refineLevel == 2);                            // the 200x instance surrounds the camera
  CHECK(m.pixels == Approx(std::hypot(128.0, 128.0)));  // it reaches the camera plane
}

TEST_CASE("the projected sphere size is 0 behind the camera and the diagonal around it") {
  CameraView view;
  view.transform = test::LookDownZ(10);
  CHECK(ProjectedSpherePixels(view, 100, 50, glm::dvec3(0, 0, 30), 1) == 0);
  CHECK(ProjectedSpherePixels(view, 100, 50, glm::dvec3(0, 0, 9.5), 1) == Approx(std::hypot(100.0, 50.0)));
  CHECK(ProjectedSpherePixels(view, 100, 50, glm::dvec3(0, 0, 0), 1) == Approx(1.0 * 50 / (10 * 18) * 100));
}
