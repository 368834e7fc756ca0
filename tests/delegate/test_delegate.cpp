// The delegate's Hydra-style flow: prim creation, dirty bits driving exactly the work they name, and
// bad input reported by prim.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace hdeye;

namespace {

struct Fixture : test::RenderStack {
  Fixture() {
    delegate.Settings().samplesPerPixel = 1;
    scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(10));
    scene.AddRenderBuffer("/color", 8, 8, 4);
  }
  RenderStats Render() { return pass.Execute("/cam", {{"color", "/color"}}); }
  const MeshSyncStats& Stats(const PrimId& id) { return static_cast<Mesh*>(index.GetRprim(id))->Stats(); }
};

}  // namespace

TEST_CASE("the delegate creates the prim types it supports and refuses the others") {
  RenderDelegate delegate;
  for (const auto& t : RenderDelegate::SupportedRprimTypes()) CHECK(delegate.CreateRprim(t, "/a"));
  for (const auto& t : RenderDelegate::SupportedSprimTypes()) CHECK(delegate.CreateSprim(t, "/a"));
  for (const auto& t : RenderDelegate::SupportedBprimTypes()) CHECK(delegate.CreateBprim(t, "/a"));
  CHECK_FALSE(delegate.CreateRprim("nurbsCurves", "/a"));
  RenderIndex index(&delegate);
  InMemorySceneDelegate scene(&index);
  CHECK_THROWS_WITH(index.InsertRprim("volume", &scene, "/p"),
                    Catch::Contains("volume") && Catch::Contains("not supported"));
  scene.AddMaterial("/m", {});
  CHECK_THROWS_WITH(scene.AddMaterial("/m", {}), Catch::Contains("/m already exists"));
}

TEST_CASE("moving points re-evaluates stencils only, and unchanged prims are not touched") {
  Fixture f;
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(1, &cube, &points);
  cube.refineLevel = 2;
  f.scene.AddMesh("/eye", cube, points);
  f.scene.AddMesh("/other", cube, points);
  f.Render();
  const MeshSyncStats first = f.Stats("/eye");
  CHECK(first.refinements == 1);
  CHECK(first.topologyBuilds == 1);
  CHECK(first.stencilEvaluations == 1);
  CHECK(first.pointUploads == 1);

  for (Vec3f& p : points) p *= 1.1f;
  f.scene.SetPoints("/eye", points);
  f.Render();
  CHECK(f.Stats("/eye").refinements == 1);     // topology refined once
  CHECK(f.Stats("/eye").topologyBuilds == 1);  // Embree geometry updated, not rebuilt
  CHECK(f.Stats("/eye").stencilEvaluations == 2);
  CHECK(f.Stats("/eye").pointUploads == 2);
  CHECK(f.Stats("/eye").transformUpdates == 1);
  CHECK(f.Stats("/other").stencilEvaluations == 1);  // untouched
  CHECK(f.Stats("/other").pointUploads == 1);

  f.scene.SetTransform("/eye", test::LookDownZ(1));
  f.Render();
  CHECK(f.Stats("/eye").transformUpdates == 2);
  CHECK(f.Stats("/eye").stencilEvaluations == 2);  // a transform does not touch points

  cube.refineLevel = 1;
  f.scene.SetTopology("/eye", cube, points);
  f.Render();
  CHECK(f.Stats("/eye").refinements == 2);  // changing topology rebuilds
  CHECK(f.Stats("/eye").topologyBuilds == 2);

  f.Render();  // nothing dirty: no work
  CHECK(f.Stats("/eye").pointUploads == 3);
  CHECK(f.Stats("/other").pointUploads == 1);
}

TEST_CASE("bad meshes and a missing camera are reported with the prim's path") {
  Fixture f;
  MeshTopology quad;
  std::vector<Vec3f> points;
  test::Quad(1, &quad, &points);
  points[2].y = std::nanf("");
  f.scene.AddMesh("/bad", quad, points);
  CHECK_THROWS_WITH(f.Render(), Catch::Contains("mesh /bad") && Catch::Contains("point 2 is not finite"));
  points[2].y = 1;
  quad.faceVertexIndices[3] = 9;
  f.scene.SetTopology("/bad", quad, points);
  CHECK_THROWS_WITH(f.Render(), Catch::Contains("mesh /bad") && Catch::Contains("outside the 4 points"));
  quad.faceVertexIndices[3] = 3;
  f.scene.SetTopology("/bad", quad, points);
  CHECK_NOTHROW(f.Render());
  CHECK_THROWS_WITH(f.pass.Execute("/nocam", {{"color", "/color"}}), Catch::Contains("camera /nocam not found"));
  CHECK_THROWS_WITH(f.pass.Execute("/cam", {{"beauty", "/color"}}), Catch::Contains("unknown AOV 'beauty'"));
}
