// Motion blur through the whole delegate: a time per camera path, Embree's transform and deformation blur, moving
// lights, cameras and eyes. The exact check: for motion that is piecewise linear between its samples, a blurred
// render with N time strata sums the same samples as N sharp renders at the strata's centre times (each rendering the
// sample indices of its stratum, s mod N = k), to the rounding of a different summation order.
#include "saccade_helpers.h"
#include "scene_helpers.h"

#include "hdeye/render/eyeShading.h"
#include "hdeye/scene/sampleScenes.h"

#include <eyelib/iris_light_tracer.h>
#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

Matrix4d Translate(double x, double y, double z) { return glm::translate(Matrix4d(1.0), glm::dvec3(x, y, z)); }
Matrix4d RotateZ(double degrees) { return glm::rotate(Matrix4d(1.0), degrees * kPi / 180, glm::dvec3(0, 0, 1)); }
/// A camera at `eye` looking at `target` (z up), camera to world.
Matrix4d LookAt(const glm::dvec3& eye, const glm::dvec3& target) {
  return glm::inverse(glm::lookAt(eye, target, glm::dvec3(0, 0, 1)));
}

/// Builds a scene into a fresh stack: `build` adds the prims, then the camera's shutter is set.
using SceneBuilder = std::function<void(test::RenderStack&)>;

struct Frame {
  std::vector<double> color, iris;  ///< the buffers' raw sums
  RenderStats stats;
};

/// Renders samples [0, spp) of a scene built by `build` with the camera's shutter [open, close].
Frame Render(const SceneBuilder& build, double open, double close, int spp, int strata,
             const std::vector<int>* only = nullptr) {
  test::RenderStack s;
  build(s);
  CameraParams camera = s.scene.GetCameraParams("/cam");
  camera.shutterOpen = open, camera.shutterClose = close;
  s.scene.SetCameraParams("/cam", camera);
  s.delegate.Settings().timeStrata = strata;
  std::vector<AovBinding> aovs{{"color", "/color"}};
  if (s.index.GetBprim("/iris")) aovs.push_back({"irisMnee", "/iris"});
  Frame f;
  if (!only) {
    s.delegate.Settings().samplesPerPixel = spp;
    f.stats = s.pass.Execute("/cam", aovs);
  } else {
    s.delegate.Settings().samplesPerPixel = 1;
    for (int sample : *only) {
      s.delegate.Settings().firstSample = sample;
      f.stats = s.pass.Execute("/cam", aovs);
    }
  }
  f.color = s.Buffer("/color").Sums();
  if (s.index.GetBprim("/iris")) f.iris = s.Buffer("/iris").Sums();
  return f;
}

/// The N sharp renders at the strata's centres, each over its stratum's sample indices, summed.
Frame SharpStrata(const SceneBuilder& build, double open, double close, int spp, int strata) {
  Frame total;
  for (int k = 0; k < strata; ++k) {
    std::vector<int> samples;
    for (int s = k; s < spp; s += strata) samples.push_back(s);
    const double t = open + (close - open) * (k + 0.5) / strata;
    const Frame f = Render(build, t, t, spp, 0, &samples);
    if (total.color.empty()) total.color.assign(f.color.size(), 0), total.iris.assign(f.iris.size(), 0);
    for (std::size_t i = 0; i < f.color.size(); ++i) total.color[i] += f.color[i];
    for (std::size_t i = 0; i < f.iris.size(); ++i) total.iris[i] += f.iris[i];
  }
  return total;
}

/// A blurred render with N strata, the N sharp renders of its strata, and one sharp frame at time 0.
struct StrataRenders {
  Frame blurred, sharp, still;
};
StrataRenders RenderStrata(const SceneBuilder& build, int spp, int strata) {
  return {Render(build, -0.5, 0.5, spp, strata), SharpStrata(build, -0.5, 0.5, spp, strata),
          Render(build, 0, 0, spp, 0)};
}

/// The largest difference relative to the values' size, and the mean absolute difference.
struct Difference {
  double maxRelative = 0, meanAbsolute = 0, meanValue = 0;
};
Difference Compare(const std::vector<double>& a, const std::vector<double>& b) {
  Difference d;
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double diff = std::abs(a[i] - b[i]);
    d.maxRelative = std::max(d.maxRelative, diff / (std::abs(a[i]) + std::abs(b[i]) + 1e-12));
    d.meanAbsolute += diff / a.size();
    d.meanValue += std::abs(a[i]) / a.size();
  }
  return d;
}

/// A floor, a ball moving and turning, a sheet whose points move and tilt, two instances of a box (one turning
/// with its instancer's samples), two point spheres moving as one prim, a key light moving across, a camera drifting:
/// every kind of motion, piecewise linear between samples at -0.5, 0 and 0.5 frames.
void MovingScene(test::RenderStack& s) {
  test::AddLambertPlane(s.scene, 3, 0.5);
  MeshTopology sphere;
  std::vector<Vec3f> points;
  test::UvSphere(0.5, 10, 14, &sphere, &points);
  s.scene.AddMesh("/ball", sphere, points, Matrix4d(1.0), "/mat");
  s.scene.SetTransformSamples(
      "/ball", {-0.5f, 0.0f, 0.5f},
      {Translate(-1, 0, 0.6), Translate(0, 0.3, 0.6) * RotateZ(40), Translate(1, 0, 0.8) * RotateZ(90)});
  MeshTopology quad;
  std::vector<Vec3f> sheet;
  test::Quad(0.4, &quad, &sheet);
  for (Vec3f& p : sheet) p += Vec3f(0, -1.3f, 0.01f);
  std::vector<Vec3f> moved = sheet;
  // Moved and tilted 40 degrees about its x axis: its normals turn over the shutter (the blend of the two steps'
  // unit normals points where the normal of the blended points does, so shading follows the time exactly).
  const float c = float(std::cos(40 * kPi / 180)), sn = float(std::sin(40 * kPi / 180));
  for (Vec3f& p : moved) p = Vec3f(p.x + 0.6f, -1.3f + c * (p.y + 1.3f), p.z + sn * (p.y + 1.3f));
  s.scene.AddMesh("/sheet", quad, sheet);
  s.scene.SetPointsSamples("/sheet", {-0.5f, 0.5f}, {sheet, moved});
  s.scene.AddInstancer("/boxes", {Translate(-1.5, 1.2, 0.2), Translate(1.5, 1.2, 0.2)});
  s.scene.SetInstanceTransformSamples("/boxes", {-0.5f, 0.5f},
                                      {{Translate(-1.5, 1.2, 0.2), Translate(1.5, 1.2, 0.2)},
                                       {Translate(-1.5, 1.2, 0.2) * RotateZ(60), Translate(1.5, 1.2, 0.2)}});
  MeshTopology cube;
  std::vector<Vec3f> corners;
  test::Cube(0.2, &cube, &corners);
  s.scene.AddMesh("/box", cube, corners, Matrix4d(1.0), "", "/boxes");
  s.scene.AddPoints("/dots", {{0, 0, 0}, {0.5f, 0, 0}}, Translate(-2, -0.5, 0.3));
  s.scene.SetPrimvar("/dots", "widths", Primvar{Interpolation::Vertex, 1, {0.3f, 0.3f}});
  s.scene.SetTransformSamples("/dots", {-0.5f, 0.5f},
                              {Translate(-2, -0.5, 0.3), Translate(-2, 0.5, 0.5) * RotateZ(30)});
  LightParams key;
  key.radius = 0.3f;
  key.intensity = 40;
  s.scene.AddLight("/key", primTypes::kSphereLight, key, Translate(2, -2, 4));
  s.scene.SetTransformSamples("/key", {-0.5f, 0.5f}, {Translate(2, -2, 4), Translate(-2, -2, 4)});
  CameraParams lens;
  lens.focalLength = 35;
  s.scene.AddCamera("/cam", lens, LookAt({0, -6, 5}, {0, 0, 0}));
  s.scene.SetTransformSamples("/cam", {-0.5f, 0.5f}, {LookAt({0, -6, 5}, {0, 0, 0}), LookAt({0.3, -6, 5}, {0, 0, 0})});
  s.scene.AddRenderBuffer("/color", 32, 24, 4);
}

using test::EyeTurn;
Matrix4d KeyAt(double degrees) { return test::KeyAt(degrees, 100); }

/// An analytic eye (mm) turning 16 degrees about its eyeball's centre (13 mm behind the apex) in a saccade, a small
/// side key moving from 70 to 80 degrees off the gaze, a camera 40 mm away: its iris light comes through MNEE.
void SaccadeScene(test::RenderStack& s) {
  EyeParams eye;
  eye.irisColor = glm::vec3(0.5f);
  s.scene.AddAnalyticEye("/eye", eye);
  s.scene.SetTransformSamples("/eye", {-0.5f, 0.0f, 0.5f}, {EyeTurn(-8), EyeTurn(2), EyeTurn(8)});
  LightParams key;
  key.radius = 2;
  key.intensity = 400;
  s.scene.AddLight("/key", primTypes::kSphereLight, key, KeyAt(70));
  s.scene.SetTransformSamples("/key", {-0.5f, 0.5f}, {KeyAt(70), KeyAt(80)});
  test::AddEyeCamera(s.scene);
  s.scene.AddRenderBuffer("/color", 24, 24, 4);
  s.scene.AddRenderBuffer("/iris", 24, 24, 3);
}

}  // namespace

TEST_CASE(
    "motion blur with N time strata equals the average of N sharp renders at the strata's centres (meshes, "
    "deformation, instances, points, light, camera)",
    "[render][motion]") {
  const int strata = 4;
  const auto [blurred, sharp, still] = RenderStrata(MovingScene, 8, strata);
  const Difference d = Compare(blurred.color, sharp.color), moved = Compare(blurred.color, still.color);
  std::printf(
      "moving scene: blurred vs %d sharp strata: max relative difference %.2e; vs the sharp frame at 0: mean "
      "|difference| %.3g of mean %.3g\n",
      strata, d.maxRelative, moved.meanAbsolute, moved.meanValue);
  CHECK(blurred.stats.nonFiniteSamples == 0);
  CHECK(d.maxRelative < 1e-5);                         // rounding: float geometry, a different summation order
  CHECK(moved.meanAbsolute > 0.01 * moved.meanValue);  // and the motion shows (measured: 2.4%)
}

TEST_CASE(
    "a saccading analytic eye with a moving light: N time strata equal N sharp renders, MNEE's iris light "
    "included",
    "[render][motion]") {
  const int strata = 4;
  // The identity is the chamber walk's: the control variate's cache is one per render (built at the shutter's
  // opening), so a blurred render's differs from each sharp render's, though every one of them is unbiased. So are
  // the catchlight's sub-samples (found at the opening, each at a time of its own), and the still eye's entry tables
  // the sharp renders would use: off here.
  const auto walkOnly = [](test::RenderStack& s) {
    SaccadeScene(s);
    s.delegate.Settings().chamberEstimator = ChamberEstimator::Path;
    s.delegate.Settings().catchlightSamples = 1;
    s.delegate.Settings().mneeEntryTables = false;
  };
  const auto [blurred, sharp, still] = RenderStrata(walkOnly, 8, strata);
  const Difference color = Compare(blurred.color, sharp.color), iris = Compare(blurred.iris, sharp.iris);
  const Difference moved = Compare(blurred.iris, still.iris);
  std::printf(
      "saccade: blurred vs %d sharp strata: colour max relative difference %.2e, irisMnee %.2e (mean %.3g); "
      "vs the sharp frame at 0: irisMnee mean |difference| %.3g\n",
      strata, color.maxRelative, iris.maxRelative, iris.meanValue, moved.meanAbsolute);
  CHECK(blurred.stats.nonFiniteSamples == 0);
  CHECK(iris.meanValue > 0);  // the MNEE path is lit
  CHECK(color.maxRelative < 1e-5);
  CHECK(iris.maxRelative < 1e-5);
  CHECK(moved.meanAbsolute > 0.05 * moved.meanValue);
}

TEST_CASE("a static scene renders bit for bit the same with an open shutter as with a closed one", "[render][motion]") {
  for (const bool ball : {false, true}) {
    auto build = [ball](test::RenderStack& s) {
      if (ball)
        sampleScenes::AddBallOnFloor(s.scene);
      else
        sampleScenes::AddSideLitEye(s.scene);
      s.scene.AddRenderBuffer("/color", 24, 16, 4);
    };
    auto render = [&](double open, double close, int strata) {
      test::RenderStack s;
      build(s);
      CameraParams camera = s.scene.GetCameraParams(sampleScenes::kCamera);
      camera.shutterOpen = open, camera.shutterClose = close;
      s.scene.SetCameraParams(sampleScenes::kCamera, camera);
      s.delegate.Settings().samplesPerPixel = 8;
      s.delegate.Settings().timeStrata = strata;
      s.pass.Execute(sampleScenes::kCamera, {{"color", "/color"}});
      return s.Buffer("/color").Sums();
    };
    const std::vector<double> closed = render(0, 0, 0);
    INFO((ball ? "ball on floor" : "side-lit eye"));
    CHECK(render(-0.25, 0.25, 0) == closed);
    CHECK(render(0, 0.5, 3) == closed);
  }
}

TEST_CASE(
    "deformation blur: a mesh whose points sweep across covers the swept band, each point for the time the "
    "mesh is over it",
    "[render][motion]") {
  // An orthographic camera above a 0.5-wide square whose points move from x = -1 to x = +1 over the shutter: a point
  // of the band |x| < 0.75 is covered a quarter of the time (0.5 / 2), the band's ends ramp down to 0 at |x| = 1.25.
  auto build = [](test::RenderStack& s) {
    MeshTopology quad;
    std::vector<Vec3f> points;
    test::Quad(0.25, &quad, &points);
    std::vector<Vec3f> left = points, right = points;
    for (Vec3f& p : left) p.x -= 1;
    for (Vec3f& p : right) p.x += 1;
    s.scene.AddMesh("/square", quad, points);
    s.scene.SetPointsSamples("/square", {-0.5f, 0.5f}, {left, right});
    CameraParams ortho;
    ortho.orthographic = true;
    ortho.horizontalAperture = 4, ortho.verticalAperture = 1;
    s.scene.AddCamera("/cam", ortho, test::LookDownZ(5));
    s.scene.AddRenderBuffer("/color", 64, 16, 4);
  };
  auto alphaRow = [&](double open, double close) {
    test::RenderStack s;
    build(s);
    CameraParams camera = s.scene.GetCameraParams("/cam");
    camera.shutterOpen = open, camera.shutterClose = close;
    s.scene.SetCameraParams("/cam", camera);
    s.delegate.Settings().samplesPerPixel = 64;
    s.pass.Execute("/cam", {{"color", "/color"}});
    std::vector<double> alpha(64, 0);  // per column, over rows 5-10 (inside the square's |y| < 0.25)
    for (int x = 0; x < 64; ++x)
      for (int y = 5; y <= 10; ++y) alpha[std::size_t(x)] += s.Buffer("/color").Resolved(x, y, 3) / 6.0;
    return alpha;
  };
  const std::vector<double> blurred = alphaRow(-0.5, 0.5), sharp = alphaRow(0, 0);
  double plateau = 0, outside = 0, sharpOutside = 0;
  int plateauColumns = 0;
  for (int x = 0; x < 64; ++x) {
    const double cx = -2 + (x + 0.5) / 16;  // the column's centre, scene units
    if (std::abs(cx) < 0.7) plateau += blurred[std::size_t(x)], ++plateauColumns;
    if (std::abs(cx) > 1.3) outside = std::max(outside, blurred[std::size_t(x)]);
    if (std::abs(cx) > 0.3) sharpOutside = std::max(sharpOutside, sharp[std::size_t(x)]);
  }
  plateau /= plateauColumns;
  std::printf(
      "deformation blur: coverage %.3f over the band (expected 0.25), %.3f beyond it; sharp: %.3f off the "
      "square\n",
      plateau, outside, sharpOutside);
  CHECK(std::abs(plateau - 0.25) < 0.02);  // 64 spp x 6 rows x 22 columns: sigma 0.004
  CHECK(outside == 0);
  CHECK(sharpOutside == 0);
}

TEST_CASE("a saccade's time-averaged iris caustic matches eyelib's light tracer averaged over the same times",
          "[render][motion]") {
  // The eye turns 16 degrees about its eyeball's centre under a fixed point light 70 degrees off its gaze. The
  // delegate's irradiance at the iris (IrisIrradianceMnee on the eye at each time, EyeGeometry::AtTime) is averaged
  // over 8 times in the shutter, 3 x 3 points per cell of a 16 x 16 grid; the reference light-traces the chamber
  // with the light placed in the eye's frame by the closed-form rotation at the same times. Tolerances: the
  // reference's noise (its per-cell standard error over the 8 runs) and 2% for the 3 x 3 quadrature across the
  // caustic's edges (eyelib's own MNEE test measures 1% with 16 x 16 points).
  const double eyeTurnDegrees = 16, keyDegrees = 70;
  const auto motion =
      MakeTransformMotion({{-0.5f, 0.5f}, {EyeTurn(-eyeTurnDegrees / 2), EyeTurn(eyeTurnDegrees / 2)}}, "eye", nullptr);
  REQUIRE(motion);
  EyeGeometry eye{EyeParams{}, motion->At(-0.5)};
  eye.motion = std::make_shared<const EyeMotion>(
      EyeMotion{std::make_shared<const TransformMotion>(*motion), Matrix4d(1.0), Shutter{-0.5, 0.5}});
  LightParams point;
  point.radius = 1;
  point.intensity = 1;
  point.treatAsPoint = true;
  const std::vector<RenderLight> lights{RenderLight::FromParams(point, KeyAt(keyDegrees))};
  REQUIRE(lights[0].delta);
  EyeLighting lighting;
  lighting.lights = &lights;
  lighting.transmittance = [](std::size_t, const glm::dvec3&, const glm::dvec3&, double, const EyeGeometry*) {
    return 1.0;
  };
  const std::function<double()> random = [] { return 0.5; };  // one light, a point: nothing to sample

  const eyelib::IrisGrid grid{16, 7.54};
  const int times = 8, k = 3;
  std::vector<double> mnee(256, 0), reference(256, 0), variance(256, 0), sharp(256, 0);
  const glm::dvec3 keyWorld(KeyAt(keyDegrees)[3]);
  for (int n = 0; n < times; ++n) {
    const double t = -0.5 + (n + 0.5) / times;
    const EyeGeometry now = eye.AtTime(t);
    // The light in the eye's frame by the closed-form turn: R_y(-angle) about the centre.
    const glm::dvec3 keyInEye(glm::inverse(EyeTurn(eyeTurnDegrees * t)) * glm::dvec4(keyWorld, 1));
    eyelib::EyeLight light;
    light.shape = eyelib::LightShape::Point;
    light.position = keyInEye;
    light.power = lights[0].radiance.x;
    const eyelib::IrradianceMap lt = eyelib::LightTraceIris(eye.chamber, light, grid, 1000000, 31 + n);
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 16; ++i) {
        const std::size_t c = std::size_t(j * 16 + i);
        reference[c] += lt.At(i, j) / times;
        variance[c] += lt.ErrorAt(i, j) * lt.ErrorAt(i, j) / (times * times);
        const auto centre = grid.CellCenter(i, j);
        const double h = grid.CellSize();
        for (int a = 0; a < k; ++a)
          for (int b = 0; b < k; ++b) {
            const glm::dvec3 x(centre.x - h / 2 + (a + 0.5) * h / k, centre.y - h / 2 + (b + 0.5) * h / k,
                               eye.chamber.IrisZ());
            mnee[c] += IrisIrradianceMnee(now, x, lighting, random).x / (k * k * times);
          }
      }
    if (n == times / 2) {  // one sharp instant, to show what the blur changes
      for (std::size_t c = 0; c < 256; ++c) sharp[c] = lt.irradiance[c];
    }
  }
  const double eMax = *std::max_element(reference.begin(), reference.end());
  int cells = 0, outliers = 0;
  double bias = 0, rms = 0, sharpRms = 0;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      const std::size_t c = std::size_t(j * 16 + i);
      if (!eyelib::CellOnIris(eye.chamber, grid, i, j) || reference[c] < 0.1 * eMax) continue;
      ++cells;
      const double e = reference[c], rel = (mnee[c] - e) / e;
      bias += rel, rms += rel * rel, sharpRms += (sharp[c] - e) * (sharp[c] - e) / (e * e);
      if (std::abs(mnee[c] - e) > 4.5 * std::sqrt(variance[c] + 0.02 * 0.02 * e * e)) ++outliers;
    }
  bias /= cells, rms = std::sqrt(rms / cells), sharpRms = std::sqrt(sharpRms / cells);
  std::printf(
      "saccade caustic: %d cells, MNEE vs light tracing over time: bias %+.2f%%, RMS %.2f%%, %d outside "
      "4.5 sigma; one sharp instant vs the blurred reference: RMS %.1f%%\n",
      cells, 100 * bias, 100 * rms, outliers, 100 * sharpRms);
  CHECK(cells > 40);
  CHECK(std::abs(bias) < 0.01);
  CHECK(rms < 0.04);
  CHECK(outliers <= cells / 20);
  CHECK(sharpRms > 2 * rms);  // the blur is visible at this tolerance
}

TEST_CASE("the render plan sizes an eye by its widest pose over the shutter", "[plan][motion]") {
  // An eye that comes from 200 mm to 100 mm in front of the camera over the shutter: twice as wide at the close.
  auto build = [](double open, double close) {
    auto s = std::make_unique<test::RenderStack>();
    s->scene.AddAnalyticEye("/eye", EyeParams{});
    s->scene.SetTransformSamples("/eye", {-0.5f, 0.5f}, {Translate(0, 0, -200), Translate(0, 0, -100)});
    CameraParams lens;
    lens.focalLength = 50;
    lens.shutterOpen = open, lens.shutterClose = close;
    s->scene.AddCamera("/cam", lens, Matrix4d(1.0));
    return s;
  };
  auto pixels = [&](double open, double close) {
    auto s = build(open, close);
    const RenderPlan plan = s->pass.Plan("/cam", 200, 200, PlanOverrides{});
    REQUIRE(plan.eyes.size() == 1);
    return plan.eyes[0].pixels;
  };
  const double atOpen = pixels(-0.5, -0.5), atClose = pixels(0.5, 0.5), blurred = pixels(-0.5, 0.5);
  std::printf("plan over the shutter: %.1f px at the open, %.1f at the close, %.1f planned\n", atOpen, atClose,
              blurred);
  CHECK(std::abs(atClose / atOpen - 2) < 0.05);
  CHECK(blurred == atClose);
}

TEST_CASE("a moving eye's chamber-light cache is one per render: a blurred render is the same at 1 and 2 threads",
          "[render][motion]") {
  const auto at = [](int threads) {
    return Render(
        [threads](test::RenderStack& s) {
          SaccadeScene(s);
          s.delegate.Settings().chamberEstimator = ChamberEstimator::ControlVariate;
          s.delegate.Settings().threads = threads;
        },
        -0.5, 0.5, 4, 0);
  };
  const Frame one = at(1), two = at(2);
  const Difference color = Compare(one.color, two.color), iris = Compare(one.iris, two.iris);
  std::printf("saccade, control variate, 1 vs 2 threads: colour %.2e, irisMnee %.2e (mean %.3g)\n", color.maxRelative,
              iris.maxRelative, iris.meanValue);
  CHECK(iris.meanValue > 0);
  CHECK(color.maxRelative == 0);
  CHECK(iris.maxRelative == 0);
}
