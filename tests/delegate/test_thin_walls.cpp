// Thin walls (render/thinWalls.h): an open mesh whose material has opacity < 1 lets light through straight, by
// (1 - opacity) (1 - R_sheet), for camera paths and shadow rays alike (an occlusion shell over an eye); closed
// meshes keep refracting. The closed forms are the diffuse plane under a sphere light of test_render.cpp.
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/meshBoundary.h"
#include "hdeye/render/previewSurface.h"
#include "scene_helpers.h"

#include <eyelib/optics.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

using namespace hdeye;

namespace {

constexpr double kLightRadius = 1, kLightHeight = 8, kRho = 0.5;

/// A diffuse plane (z = 0) under a sphere light, an open sheet of `opacity` (a quad, black, ior 1: no coat) at
/// z = 2 between them, seen by an orthographic camera at `cameraHeight` looking down.
struct SheetScene : test::RenderStack {
  SheetScene(float opacity, double cameraHeight, bool mis) {
    MeshTopology quad;
    std::vector<Vec3f> points;
    test::Quad(10, &quad, &points);
    MaterialParams floor;
    floor.diffuseColor = glm::vec3(float(kRho));
    floor.ior = 1;
    scene.AddMaterial("/floorMat", floor);
    scene.AddMesh("/floor", quad, points, Matrix4d(1.0), "/floorMat");
    MaterialParams sheet;
    sheet.diffuseColor = glm::vec3(0);
    sheet.opacity = opacity;
    sheet.ior = 1;
    scene.AddMaterial("/sheetMat", sheet);
    scene.AddMesh("/sheet", quad, points, test::LookDownZ(2), "/sheetMat");
    LightParams light;
    light.type = LightType::Sphere;
    light.radius = float(kLightRadius);
    scene.AddLight("/key", primTypes::kSphereLight, light, test::LookDownZ(kLightHeight));
    CameraParams ortho;
    ortho.orthographic = true;
    ortho.horizontalAperture = ortho.verticalAperture = 0.2;
    scene.AddCamera("/cam", ortho, test::LookDownZ(cameraHeight));
    scene.AddRenderBuffer("/color", 8, 8, 4);
    delegate.Settings().samplesPerPixel = 256;
    delegate.Settings().mis = mis;
  }
  double MeanRed() {
    pass.Execute("/cam", {{"color", "/color"}});
    const RenderBuffer& b = Buffer("/color");
    double sum = 0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) sum += b.Resolved(x, y, 0);
    return sum / 64;
  }
};

}  // namespace

TEST_CASE("an open mesh has boundary edges, and a closed one, also with duplicated seam points, has none", "[thin]") {
  MeshTopology quad, cube, sphere;
  std::vector<Vec3f> quadPoints, cubePoints, spherePoints;
  test::Quad(1, &quad, &quadPoints);
  test::Cube(1, &cube, &cubePoints);
  test::UvSphere(1, 8, 12, &sphere, &spherePoints);
  CHECK(HasBoundaryEdges(quad.faceVertexCounts, quad.faceVertexIndices, quadPoints));
  CHECK_FALSE(HasBoundaryEdges(cube.faceVertexCounts, cube.faceVertexIndices, cubePoints));
  CHECK_FALSE(HasBoundaryEdges(sphere.faceVertexCounts, sphere.faceVertexIndices, spherePoints));
  // A UV seam as DCC exports write it: the cube's point 0 duplicated for the faces that use it last.
  cubePoints.push_back(cubePoints[0]);
  cube.faceVertexIndices[8] = int(cubePoints.size()) - 1;  // the third face's first corner
  CHECK_FALSE(HasBoundaryEdges(cube.faceVertexCounts, cube.faceVertexIndices, cubePoints));
  // Removing a face opens the cube.
  cube.faceVertexCounts.pop_back();
  cube.faceVertexIndices.resize(cube.faceVertexIndices.size() - 4);
  CHECK(HasBoundaryEdges(cube.faceVertexCounts, cube.faceVertexIndices, cubePoints));
}

TEST_CASE("a thin sheet reflects 2R / (1 + R) and passes the rest straight through", "[thin][bsdf]") {
  const double r = eyelib::FresnelDielectric(1.0, 1.5);  // 0.04
  CHECK(ThinSheetReflectance(1.0, 1.5) == Approx(2 * r / (1 + r)).epsilon(1e-12));
  CHECK(ThinSheetReflectance(0.5, 1.0) == 0);
  PreviewSurface s;
  s.opacity = 0, s.ior = 1.5, s.roughness = 0, s.thinWalled = true;
  const glm::dvec3 n(0, 0, 1), wo = glm::normalize(glm::dvec3(0.3, 0.1, 1));
  BsdfSample sample;
  REQUIRE(SamplePreviewSurface(s, n, wo, false, 0.5, 0.9, 0.5, &sample));  // u1 = 0.9 > R: transmitted
  CHECK(sample.transmitted);
  CHECK(glm::length(sample.wi + wo) < 1e-12);  // straight on: no bending
  CHECK(sample.weight.x == Approx(1.0));       // not divided by eta^2: nothing was entered
}

TEST_CASE("a sheet of opacity a between a sphere light and a plane passes 1 - a of the light, MIS on and off",
          "[thin][render]") {
  const double unshadowed = kRho * (kLightRadius / kLightHeight) * (kLightRadius / kLightHeight);
  for (bool mis : {false, true}) {
    for (float opacity : {0.0f, 0.5f, 0.8f}) {
      SheetScene below(opacity, 1, mis);  // the camera under the sheet: only the light passes it
      const double got = below.MeanRed(), expected = (1 - opacity) * unshadowed;
      std::printf("sheet opacity %.1f, MIS %s: plane %.6f (closed form %.6f)\n", opacity, mis ? "on" : "off", got,
                  expected);
      CHECK(got == Approx(expected).epsilon(0.015));
    }
  }
}

TEST_CASE("seen through a sheet of opacity a, the lit plane is (1 - a)^2 as bright: view and light both cross it",
          "[thin][render]") {
  const double unshadowed = kRho * (kLightRadius / kLightHeight) * (kLightRadius / kLightHeight);
  SheetScene above(0.5f, 3, true);
  const double got = above.MeanRed(), expected = 0.25 * unshadowed;
  std::printf("plane seen through a 0.5 sheet: %.6f (closed form %.6f)\n", got, expected);
  CHECK(got == Approx(expected).epsilon(0.03));
}

TEST_CASE("shadow linking and thin walls in one shadow ray: an ignored card passes all, the sheet 1 - a, else dark",
          "[thin][linking][render]") {
  // An opaque 4 x 4 card at z = 4, between the sheet (opacity 0.5, z = 2) and the light (z = 8), hides the light
  // from the patch. Shadow-unlinking the card leaves the sheet's attenuation; unlinking the sheet too, none.
  const double unshadowed = kRho * (kLightRadius / kLightHeight) * (kLightRadius / kLightHeight);
  auto render = [](std::vector<PrimId> unshadowed) {
    // Light sampling alone (the card still blocks BSDF rays, which see no links), direct light only (no bounce
    // off the card's underside).
    SheetScene s(0.5f, 1, false);
    s.delegate.Settings().maxDepth = 0;
    MeshTopology quad;
    std::vector<Vec3f> points;
    test::Quad(2, &quad, &points);
    s.scene.AddMesh("/card", quad, points, test::LookDownZ(4));
    LightParams key = s.scene.GetLightParams("/key");
    key.shadowLinkExcludes = std::move(unshadowed);
    s.scene.SetLightParams("/key", key);
    return s.MeanRed();
  };
  const double blocked = render({}), cardIgnored = render({"/card"}), bothIgnored = render({"/card", "/sheet"});
  std::printf(
      "plane under card and 0.5 sheet: %.6f, card shadow-unlinked %.6f (closed form %.6f), both %.6f "
      "(closed form %.6f)\n",
      blocked, cardIgnored, 0.5 * unshadowed, bothIgnored, unshadowed);
  CHECK(blocked == 0);
  CHECK(cardIgnored == Approx(0.5 * unshadowed).epsilon(0.015));
  CHECK(bothIgnored == Approx(unshadowed).epsilon(0.015));
}

TEST_CASE("a mesh is a thin wall while it is open, and closing it makes it glass again", "[thin]") {
  SheetScene s(0.5f, 1, true);
  s.MeanRed();
  auto* sheet = static_cast<Mesh*>(s.index.GetRprim("/sheet"));
  REQUIRE(sheet);
  CHECK(sheet->Context()->thinWalled);
  MeshTopology cube;
  std::vector<Vec3f> points;
  test::Cube(10, &cube, &points);
  for (Vec3f& p : points) p.z = p.z > 0 ? 2.5f : 1.5f;  // a closed 1-unit slab replacing the sheet
  s.scene.SetTopology("/sheet", cube, points);
  s.MeanRed();
  CHECK_FALSE(sheet->Context()->thinWalled);
}

TEST_CASE("MNEE's shadow rays cross a thin wall over the cornea: the iris light falls to (1 - a)^2, not to black",
          "[thin][render]") {
  // An analytic eye (mm, apex at the origin, gazing at the camera) under a sheet of opacity 0.5 2 mm in front of
  // it: the camera's view crosses the sheet once (1 - a) and MNEE's light crosses it once more (1 - a).
  double irisLight[2];
  for (int withSheet = 0; withSheet < 2; ++withSheet) {
    test::RenderStack s;
    s.scene.AddAnalyticEye("/eye", EyeParams{});
    if (withSheet) {
      MeshTopology quad;
      std::vector<Vec3f> points;
      test::Quad(15, &quad, &points);
      MaterialParams sheet;
      sheet.diffuseColor = glm::vec3(0);
      sheet.opacity = 0.5f;
      sheet.ior = 1;
      s.scene.AddMaterial("/sheetMat", sheet);
      s.scene.AddMesh("/sheet", quad, points, test::LookDownZ(2), "/sheetMat");
    }
    test::AddSphereLight(s.scene, "/key", 3, 100, {0, 30, 80});
    test::AddEyeCamera(s.scene);
    s.scene.AddRenderBuffer("/color", 24, 24, 4);
    s.scene.AddRenderBuffer("/iris", 24, 24, 3);
    s.delegate.Settings().samplesPerPixel = 64;
    s.pass.Execute("/cam", {{"color", "/color"}, {"irisMnee", "/iris"}});
    double sum = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) sum += s.Buffer("/iris").Resolved(x, y, 0);
    irisLight[withSheet] = sum;
  }
  const double ratio = irisLight[1] / irisLight[0];
  std::printf("iris MNEE light under a 0.5 sheet: %.4f of the bare eye's (closed form 0.25)\n", ratio);
  REQUIRE(irisLight[0] > 0);
  CHECK(ratio == Approx(0.25).margin(0.03));
}
