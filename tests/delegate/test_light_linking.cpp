// Light and shadow linking (UsdLuxLightAPI's collections, resolved to rprim ids by the scene delegate): a light
// linked away from a surface gives it nothing, MNEE's caustic on an eye included; shadow-unlinked geometry casts
// no shadow for that light and still casts it for the others.
#include "hdeye/scene/sampleScenes.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <utility>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// A floor (albedo 0.5) under a 1 x 1 blocker card at height 2, a parallel beam of 2 lux straight down, and an
/// orthographic camera between them (at height 1) over a 0.2-unit patch of the floor under the blocker's middle.
/// Returns the patch's mean red radiance.
double FloorUnderBlocker(const LightParams& beam) {
  test::RenderStack s;
  test::AddLambertPlane(s.scene, 10, 0.5);
  MeshTopology card;
  std::vector<Vec3f> points;
  test::Quad(0.5, &card, &points);
  s.scene.AddMesh("/blocker", card, points, test::LookDownZ(2), "/mat");
  s.scene.AddLight("/beam", primTypes::kDistantLight, beam, test::LookDownZ(5));
  CameraParams ortho;
  ortho.orthographic = true;
  ortho.horizontalAperture = ortho.verticalAperture = 0.2;
  s.scene.AddCamera("/cam", ortho, test::LookDownZ(1));
  s.scene.AddRenderBuffer("/color", 4, 4, 4);
  s.delegate.Settings().samplesPerPixel = 4;
  s.delegate.Settings().maxDepth = 0;  // direct light only: the closed form has no interreflection
  s.pass.Execute("/cam", {{"color", "/color"}});
  double sum = 0;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) sum += s.Buffer("/color").Resolved(x, y, 0);
  return sum / 16;
}

/// Renders the side-lit eye scene in `s` (24 x 24, 8 spp); returns the sums of the red irisMnee and beauty AOVs.
std::pair<double, double> RenderIrisAndBeauty(test::RenderStack& s) {
  s.scene.AddRenderBuffer("/color", 24, 24, 4);
  s.scene.AddRenderBuffer("/iris", 24, 24, 3);
  s.delegate.Settings().samplesPerPixel = 8;
  s.pass.Execute(sampleScenes::kCamera, {{"color", "/color"}, {"irisMnee", "/iris"}});
  double iris = 0, color = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x)
      iris += s.Buffer("/iris").Resolved(x, y, 0), color += s.Buffer("/color").Resolved(x, y, 0);
  return {iris, color};
}

}  // namespace

TEST_CASE("shadow linking: a blocker the light ignores casts no shadow, light linking: an unlinked floor is dark ",
          "[linking]") {
  LightParams beam;
  beam.angle = 0;
  beam.intensity = 2;
  const double shadowed = FloorUnderBlocker(beam);
  beam.shadowLinkExcludes = {"/blocker"};
  const double through = FloorUnderBlocker(beam);
  beam.shadowLinkExcludes = {"/not/in/the/scene"};  // names the index does not hold are ignored
  const double unknown = FloorUnderBlocker(beam);
  beam.shadowLinkExcludes = {};
  beam.lightLinkExcludes = {"/floor"};
  const double unlit = FloorUnderBlocker(beam);
  std::printf(
      "floor under the blocker: %.6f shadowed, %.6f with the blocker shadow-unlinked (closed form %.6f), "
      "%.6f light-unlinked\n",
      shadowed, through, 0.5 * 2 / kPi, unlit);
  CHECK(shadowed == 0);
  CHECK(through == Approx(0.5 * 2 / kPi).epsilon(1e-6));
  CHECK(unknown == 0);
  CHECK(unlit == 0);
}

TEST_CASE("a key light linked away from an eye gives it nothing, no caustic either ", "[linking]") {
  // The side-lit eye: an analytic eye, a key 60 degrees off its gaze, a dim dome. With the key linked away from
  // the eye, the image is bit for bit the image with the key switched off (the same random numbers: a light
  // linked away is passed over before its radiance is read, in next event estimation, MNEE and BSDF hits).
  auto render = [](float keyScale, bool unlinkKey) {
    test::RenderStack s;
    sampleScenes::AddSideLitEye(s.scene, 60, keyScale);
    if (unlinkKey) {
      LightParams key = s.scene.GetLightParams("/World/key");
      key.lightLinkExcludes = {"/World/eye"};
      s.scene.SetLightParams("/World/key", key);
    }
    return RenderIrisAndBeauty(s);
  };
  const auto [linkedIris, linkedColor] = render(1, false);
  const auto [unlinkedIris, unlinkedColor] = render(1, true);
  const auto [offIris, offColor] = render(0, true);
  std::printf(
      "iris MNEE light: %.5f with the key, %.5f with it linked away, %.5f with it off; beauty %.4f / %.4f / "
      "%.4f\n",
      linkedIris, unlinkedIris, offIris, linkedColor, unlinkedColor, offColor);
  CHECK(unlinkedIris == offIris);
  CHECK(unlinkedColor == offColor);
  CHECK(linkedIris > 1.5 * unlinkedIris);  // the key's caustic was there before
}

TEST_CASE("lashes shadow-unlinked from the key cast no shadow on the iris caustic ", "[linking]") {
  // A 30 mm card halfway to the key (out of the camera's view) hides the key from the eye; with the card in the
  // key's shadow-link excludes, MNEE's shadow rays pass through it and the caustic comes back (the card still
  // shades the dome a little, so the match is to a few percent, not exact).
  auto render = [](bool card, bool unlinkCard) {
    test::RenderStack s;
    sampleScenes::AddSideLitEye(s.scene, 60);
    if (card) {
      MeshTopology quad;
      std::vector<Vec3f> points;
      test::Quad(15, &quad, &points);
      const double a = 60 * kPi / 180;
      Matrix4d m(1.0);  // the card's normal (its local z) towards the key
      m[0] = glm::dvec4(std::cos(a), 0, -std::sin(a), 0);
      m[2] = glm::dvec4(std::sin(a), 0, std::cos(a), 0);
      m[3] = glm::dvec4(75 * std::sin(a), 0, 75 * std::cos(a), 1);
      s.scene.AddMesh("/World/lashes", quad, points, m);
    }
    if (unlinkCard) {
      LightParams key = s.scene.GetLightParams("/World/key");
      key.shadowLinkExcludes = {"/World/lashes"};
      s.scene.SetLightParams("/World/key", key);
    }
    return RenderIrisAndBeauty(s).first;
  };
  const double open = render(false, false), shadowed = render(true, false), unlinked = render(true, true);
  std::printf("iris MNEE light: %.5f without the card, %.5f with it, %.5f with it shadow-unlinked from the key\n", open,
              shadowed, unlinked);
  CHECK(shadowed < 0.7 * open);
  CHECK(unlinked == Approx(open).epsilon(0.05));
}
