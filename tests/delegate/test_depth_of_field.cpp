// Thin-lens depth of field (UsdGeomCamera fStop, focusDistance): a small emitting sphere off the plane in focus
// blurs into a disk whose diameter is the thin-lens circle of confusion; a pinhole stays sharp.
#include "hdeye/plan/renderPlan.h"
#include "hdeye/scene/sampleScenes.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Lens {
  double fStop, focus;  ///< f-number, focus distance (scene units)
};

constexpr double kBead = 0.25;  ///< the emitting sphere's radius, scene units

/// Renders a kBead-radius emitting sphere on the axis `depth` units in front of a 50 mm (5-unit, USD's tenths),
/// 36 mm-wide camera, `size` pixels square, and returns the blur's diameter in pixels from the image's radial
/// second moment: a uniform disk of diameter c has <r^2> = c^2 / 8, the sphere's own image (a disk of diameter
/// `beadPixels`) and the pixels' area (1/6 px^2) add theirs, so c = sqrt(8 (<r^2> - 1/6) - beadPixels^2).
/// Moments of the light are unbiased under noise, unlike thresholds.
/// sampler: this optics test measures the camera model on the independent sampler; with zsobol the measured blur of
/// the f/4 case scattered 2.7 % from seed to seed (5.43 to 5.73 px over seeds 0-3, independent 5.48 to 5.55), an
/// open problem of the stratified pixel jitter with a tiny bright source, which the test prints.
double BlurDiameterPixels(const Lens& lens, double depth, int size, int spp, double beadPixels,
                          SamplerKind sampler = SamplerKind::Independent) {
  test::RenderStack s;
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::UvSphere(kBead, 16, 32, &topology, &points);
  MaterialParams glow;
  glow.diffuseColor = glm::vec3(0);
  glow.emissiveColor = glm::vec3(1);
  s.scene.AddMaterial("/glow", glow);
  s.scene.AddMesh("/bead", topology, points, Matrix4d(1.0), "/glow");
  CameraParams cam;
  cam.focalLength = 50;
  cam.horizontalAperture = cam.verticalAperture = 36;
  cam.fStop = lens.fStop;
  cam.focusDistance = lens.focus;
  s.scene.AddCamera("/cam", cam, test::LookDownZ(depth));
  s.scene.AddRenderBuffer("/color", size, size, 4);
  s.delegate.Settings().samplesPerPixel = spp;
  s.delegate.Settings().sampler = sampler;
  s.pass.Execute("/cam", {{"color", "/color"}});
  const RenderBuffer& b = s.Buffer("/color");
  double m0 = 0, mx = 0, my = 0, mr2 = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double w = b.Resolved(x, y, 0), cx = x + 0.5 - size / 2.0, cy = y + 0.5 - size / 2.0;
      m0 += w, mx += w * cx, my += w * cy, mr2 += w * (cx * cx + cy * cy);
    }
  if (!(m0 > 0)) return 0;
  const double r2 = mr2 / m0 - (mx * mx + my * my) / (m0 * m0) - 1.0 / 6;
  return std::sqrt(std::max(0.0, 8 * r2 - beadPixels * beadPixels));
}

/// The sphere's image diameter, pixels (pinhole projection of its 2 kBead width).
double BeadPixels(double depth, int size) { return 2 * kBead * 5 / depth / 3.6 * size; }

}  // namespace

TEST_CASE("a defocused point blurs into the thin-lens circle of confusion A f |D - F| / (D F) ", "[camera]") {
  const int size = 96;
  const double f = 5, film = 3.6;  // focal length and film width in scene units (50 mm, 36 mm at 0.1)
  for (const auto& [lens, depth] : {std::pair{Lens{2, 100}, 30.0}, std::pair{Lens{4, 20}, 60.0}}) {
    const double A = f / lens.fStop;
    const double coc = A * f * std::abs(depth - lens.focus) / (depth * lens.focus) / film * size;
    const double measured = BlurDiameterPixels(lens, depth, size, 256, BeadPixels(depth, size));
    std::printf("f/%g focused at %g, bead at %g: blur %.3f px (thin lens %.3f px)\n", lens.fStop, lens.focus, depth,
                measured, coc);
    CHECK(coc > 5);
    CHECK(measured == Approx(coc).epsilon(0.03));
    const double stratified = BlurDiameterPixels(lens, depth, size, 256, BeadPixels(depth, size), SamplerKind::ZSobol);
    std::printf("  with the zsobol sampler: blur %.3f px (%+.1f %%; reported, not claimed)\n", stratified,
                100 * (stratified / coc - 1));
  }
}

TEST_CASE("an object in the plane of focus stays as sharp as through a pinhole ", "[camera]") {
  const double sharp = BlurDiameterPixels({0, 0}, 30, 96, 64, BeadPixels(30, 96));
  const double focused = BlurDiameterPixels({2, 30}, 30, 96, 64, BeadPixels(30, 96));
  std::printf("bead at the focus distance: blur %.3f px, through a pinhole %.3f px\n", focused, sharp);
  CHECK(focused < 1);
  CHECK(sharp < 1);
}

TEST_CASE("the render plan sizes a defocused eye by its blur: resolved pixels = pixels / circle of confusion ",
          "[camera]") {
  // The side-lit eye 45 mm from a 100 mm lens (the scene is in mm: focalLengthUnit 1) at f/16, focused 6 mm
  // behind the iris: macro depth of field is that shallow.
  test::RenderStack s;
  hdeye::sampleScenes::AddSideLitEye(s.scene);
  const int width = 256;
  const RenderPlan sharp = s.pass.Plan(hdeye::sampleScenes::kCamera, width, width, PlanOverrides{});
  CameraParams lens = s.scene.GetCameraParams(hdeye::sampleScenes::kCamera);
  lens.fStop = 16;
  lens.focusDistance = 55;
  lens.focalLengthUnit = 1;
  s.scene.SetCameraParams(hdeye::sampleScenes::kCamera, lens);
  const RenderPlan blurred = s.pass.Plan(hdeye::sampleScenes::kCamera, width, width, PlanOverrides{});
  REQUIRE(sharp.eyes.size() == 1);
  REQUIRE(blurred.eyes.size() == 1);
  const EyePlan &a = sharp.eyes[0], &b = blurred.eyes[0];
  // The iris plane is 3.735 mm behind the apex, 45 mm from the camera: D = 48.735 mm.
  const double A = 100.0 / 16, D = 48.735, F = 55;
  const double coc = A * 100 * std::abs(D - F) / (D * F) / lens.horizontalAperture * width;
  std::printf("eye %.1f px; f/16 focused at 55 mm: blur %.2f px (thin lens %.2f), resolved %.2f px, refine %d -> %d\n",
              b.pixels, b.blurPixels, coc, b.resolvedPixels, a.refineLevel, b.refineLevel);
  CHECK(a.blurPixels == 0);
  CHECK(a.resolvedPixels == a.pixels);
  CHECK(b.pixels == Approx(a.pixels));
  CHECK(b.blurPixels == Approx(coc).epsilon(1e-3));
  CHECK(b.resolvedPixels == Approx(b.pixels / coc).epsilon(1e-3));
  CHECK(b.pixelFootprintMm > a.pixelFootprintMm);
}
