// The render plan (renderPlan.h): what it measures of eyes and lights, what it decides on synthetic cases, that
// explicit settings and authored values win, its JSON, and the EXR header attribute that carries it.
#include "delegate/scene_helpers.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/plan/renderPlan.h"
#include "hdeye/prims/light.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/renderContext.h"
#include "hdeye/scene/inMemorySceneDelegate.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <unistd.h>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kIrisZ = -3.735;  // mm, the default iris plane

Matrix4d Translate(double x, double y, double z) {
  Matrix4d m(1.0);
  m[3] = glm::dvec4(x, y, z, 1);
  return m;
}

/// A millimetre scene: an eye (analytic, or on a 12 mm UV-sphere mesh) at the origin gazing +z, a 50 mm camera
/// (24 x 24 mm film) on the axis at `cameraDistance`, and whatever lights the test adds.
struct Scene : test::RenderStack {
  explicit Scene(double cameraDistance, bool mesh = false, const Matrix4d& cameraTransform = Matrix4d(0.0)) {
    CameraParams camera;
    camera.focalLength = 50, camera.horizontalAperture = 24, camera.verticalAperture = 24;
    scene.AddCamera("/cam", camera, cameraTransform[3][3] != 0 ? cameraTransform : test::LookDownZ(cameraDistance));
    if (mesh) {
      MeshTopology topology;
      std::vector<Vec3f> points;
      test::UvSphere(12, 24, 48, &topology, &points);
      EyeParams eye;
      eye.modelTransform = Translate(0, 0, 12 - 0.0);  // the apex on the sphere's front pole
      scene.AddEyeMesh("/Eye", topology, points, eye);
    } else {
      scene.AddAnalyticEye("/Eye", EyeParams{});
    }
  }
  void SphereLight(const PrimId& id, double radius, double angleDeg, double distance = 200) {
    LightParams p;
    p.radius = float(radius);
    const double a = angleDeg * kPi / 180;
    scene.AddLight(id, "sphereLight", p, Translate(distance * std::sin(a), 0, kIrisZ + distance * std::cos(a)));
  }
  void Dome() { scene.AddLight("/dome", "domeLight", LightParams{}); }
  RenderPlan Plan(int width, const PlanOverrides& overrides = {}) { return pass.Plan("/cam", width, width, overrides); }
};

/// The plan's summary lines and every eye's reasons, for failure messages.
std::string Describe(const RenderPlan& plan) {
  std::string out;
  for (const std::string& line : plan.SummaryLines()) out += line + "\n";
  for (const EyePlan& e : plan.eyes)
    for (const auto& [decision, why] : e.why) out += e.prim + " " + decision + ": " + why + "\n";
  return out;
}

/// A copy (callers often pass a temporary plan).
EyePlan OnlyEye(const RenderPlan& plan) {
  REQUIRE(plan.eyes.size() == 1);
  return plan.eyes[0];
}

}  // namespace

TEST_CASE("the plan measures the iris circle's projected diameter as the pinhole formula gives it", "[plan]") {
  for (double distance : {40.0, 100.0, 400.0}) {
    Scene s(distance);
    const EyePlan& e = OnlyEye(s.Plan(200));
    // A circle facing the camera: diameter on film = f D / depth; pixels = film / aperture * width.
    const double expected = 200.0 / 24 * 50 * 15.08 / (distance - kIrisZ);
    INFO("distance " << distance << " mm: " << e.pixels << " px, expected " << expected);
    CHECK(e.pixels == Approx(expected).epsilon(0.005));
    CHECK(e.inView);
    CHECK_FALSE(e.behindCamera);
    CHECK(e.viewAngleDeg < 1e-3);
  }
}

TEST_CASE("the plan measures a sphere light's solid angle and its angle off the gaze", "[plan]") {
  Scene s(40);
  s.SphereLight("/key", 5, 60, 100);
  const EyePlan& e = OnlyEye(s.Plan(64));
  REQUIRE(e.lights.size() == 1);
  const LightFacts& l = e.lights[0];
  const double sinA = 5.0 / 100;
  CHECK(l.solidAngleSr == Approx(2 * kPi * (1 - std::sqrt(1 - sinA * sinA))).epsilon(1e-6));
  CHECK(l.angleOffGazeDeg == Approx(60).margin(1e-6));
  CHECK(l.angularRadiusDeg == Approx(std::asin(sinA) * 180 / kPi).epsilon(1e-6));
  CHECK(l.reachesIris);
}

TEST_CASE("a small key light seen through the cornea gets MNEE", "[plan]") {
  Scene s(40);
  s.SphereLight("/key", 2, 45);
  const RenderPlan plan = s.Plan(64);
  const EyePlan& e = OnlyEye(plan);
  INFO(Describe(plan));
  CHECK(e.lights[0].strategy == LightStrategy::Mnee);
  CHECK(e.switches.mnee);
  CHECK(plan.switches.mnee);
  CHECK_FALSE(e.switches.mneeAllSolutions);  // 45 deg: no caustic fold worth a 7-seed search
}

TEST_CASE("the chamber walk is not cut (sweep chamber: a bound saves no time), and a flag sets it per eye", "[plan]") {
  Scene s(40);
  s.SphereLight("/key", 2, 75);
  const EyePlan planned = OnlyEye(s.Plan(64));
  INFO(planned.why.at("chamberEvents"));
  CHECK(planned.chamberEvents == 64);
  CHECK(planned.RenderOptions({"/key"}).maxChamberEvents == 64);
  CHECK(planned.why.at("chamberEvents").find("provisional") == std::string::npos);
  PlanOverrides flag;
  flag.chamberEvents = 4;
  const EyePlan cut = OnlyEye(s.Plan(64, flag));
  CHECK(cut.chamberEvents == 4);
  CHECK(cut.RenderOptions({"/key"}).maxChamberEvents == 4);
  CHECK(cut.why.at("chamberEvents").rfind("flag", 0) == 0);
  flag.chamberEvents = 0;
  CHECK_THROWS_AS(s.Plan(64, flag), std::invalid_argument);
}

TEST_CASE("the chamber cache's grid grows with the eye on screen: 12 rings small, the default 48 from 120 px",
          "[plan]") {
  Scene s(40);
  s.SphereLight("/key", 2, 60);
  int previous = 0;
  for (int width : {16, 32, 48, 64, 128, 2000}) {
    const EyePlan e = OnlyEye(s.Plan(width));
    INFO(width << " px wide image: " << e.resolvedPixels << " px eye, " << e.why.at("chamberCacheRings"));
    CHECK(e.chamberCacheRings % 4 == 0);
    CHECK(e.chamberCacheRings >= 12);
    CHECK(e.chamberCacheRings <= 48);
    CHECK(e.chamberCacheRings >= previous);
    CHECK(e.RenderOptions({"/key"}).chamberCacheRings == e.chamberCacheRings);
    if (e.resolvedPixels < 30) CHECK(e.chamberCacheRings == 12);
    if (e.resolvedPixels >= 120) CHECK(e.chamberCacheRings == 48);
    previous = e.chamberCacheRings;
  }
  CHECK(previous == 48);
}

TEST_CASE("a grazing key gets all solutions from 200 px, as sweep allsol-size measured, and one path below", "[plan]") {
  // 89 deg: one path's equal-time efficiency 1.22x all-solutions' at 100 px, 0.94x at 200 px.
  Scene s(40);
  s.SphereLight("/key", 2, 85);
  PlanRules rules;
  CHECK(rules.allSolutionsMinPixels == 200);
  const auto planFor = [&](int width) { return OnlyEye(s.pass.Plan("/cam", width, width, PlanOverrides{}, rules)); };
  const EyePlan small = planFor(96);   // ~66 px
  const EyePlan large = planFor(320);  // ~220 px
  INFO(small.pixels << " px: " << small.why.at("mneeAllSolutions"));
  INFO(large.pixels << " px: " << large.why.at("mneeAllSolutions"));
  REQUIRE(small.pixels < 200);
  REQUIRE(large.pixels >= 200);
  CHECK_FALSE(small.switches.mneeAllSolutions);
  CHECK(large.switches.mneeAllSolutions);
  CHECK(large.why.at("mneeAllSolutions").find("allsol-size") != std::string::npos);
}

TEST_CASE("a dome light alone is left to BSDF sampling with MIS: no MNEE", "[plan]") {
  Scene s(40);
  s.Dome();
  const RenderPlan plan = s.Plan(64);
  const EyePlan& e = OnlyEye(plan);
  INFO(Describe(plan));
  CHECK(e.lights[0].kind == LightType::Dome);
  CHECK(e.lights[0].solidAngleSr == Approx(4 * kPi));
  CHECK(e.lights[0].strategy == LightStrategy::Bsdf);
  CHECK_FALSE(e.switches.mnee);
  CHECK_FALSE(plan.switches.mnee);
  RenderSettings settings;
  REQUIRE(settings.eyeSwitches.mnee);
  ApplyRenderPlan(plan, &settings);
  CHECK_FALSE(settings.eyeSwitches.mnee);
}

TEST_CASE("a dome plus a small key: MNEE for the key, BSDF for the dome, applied per light", "[plan]") {
  Scene s(40);
  s.Dome();
  s.SphereLight("/key", 2, 30);
  const EyePlan& e = OnlyEye(s.Plan(64));
  REQUIRE(e.lights.size() == 2);
  CHECK(e.lights[0].light == "/dome");
  CHECK(e.lights[0].strategy == LightStrategy::Bsdf);
  CHECK(e.lights[1].strategy == LightStrategy::Mnee);
  CHECK(e.switches.mnee);
  CHECK(e.why.at("mnee").find("pending") == std::string::npos);
  CHECK(e.why.at("mnee").find("applied per light") != std::string::npos);
  // The renderer's mask follows the render's light order (the index's), whatever order it is given in.
  const EyeRenderOptions o = e.RenderOptions({"/key", "/dome", "/added-later"});
  CHECK(o.planned);
  CHECK(o.mneeLights == std::vector<bool>{true, false, true});  // an unmeasured light keeps MNEE
}

/// A lat-long dome image (UsdLux orientation: +z at its centre) of radiance 1, with a window `gain` times brighter
/// 30 degrees across around +z, the eye's gaze.
std::string WindowDomeImage(double gain) {
  const int w = 128, h = 64;
  std::vector<float> r(w * h), g(w * h), b(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double lat = kPi * (0.5 - (y + 0.5) / h), lon = kPi * (1 - 2 * (x + 0.5) / w);
      const bool window = std::abs(lat) < 15 * kPi / 180 && std::abs(lon) < 15 * kPi / 180;
      const std::size_t i = std::size_t(y) * w + x;
      r[i] = g[i] = b[i] = window ? float(gain) : 1.0f;
    }
  const std::string path = (std::filesystem::temp_directory_path() / ("hdeye_plan_dome_" + std::to_string(int(gain)) +
                                                                      "_" + std::to_string(::getpid()) + ".exr"))
                               .string();
  WriteExr(path, w, h, {{"R", r}, {"G", g}, {"B", b}});
  return path;
}

TEST_CASE("a dome goes to MNEE when its radiance contrast about the gaze is high, to BSDF when smooth", "[plan]") {
  for (double gain : {1.0, 20.0}) {
    Scene s(40);
    LightParams dome;
    dome.textureFile = WindowDomeImage(gain);
    s.scene.AddLight("/dome", "domeLight", dome);
    const RenderPlan plan = s.Plan(64);
    const EyePlan& e = OnlyEye(plan);
    std::filesystem::remove(dome.textureFile);
    INFO("gain " << gain << "\n" << Describe(plan));
    REQUIRE(e.lights.size() == 1);
    const LightFacts& l = e.lights[0];
    CHECK(l.why.find("dome-contrast") != std::string::npos);
    if (gain == 1) {
      CHECK(l.radianceContrast == Approx(1).margin(1e-9));
      CHECK(l.strategy == LightStrategy::Bsdf);
    } else {
      // The window covers f = 8.4 % of the cosine-weighted hemisphere: E[L^2] / E[L]^2 = (1 + f(g^2 - 1)) /
      // (1 + f(g - 1))^2 = 5.1 at g = 20 (the texels' bilinear edges and the 32 x 32 directions move it a little).
      CHECK(l.radianceContrast > 4);
      CHECK(l.radianceContrast < 6.5);
      CHECK(l.strategy == LightStrategy::Mnee);
      CHECK(e.switches.mnee);
    }
  }
}

TEST_CASE("an eye a few pixels wide gets the small-eye decisions of the rules", "[plan]") {
  Scene s(2000, /*mesh=*/true);
  s.SphereLight("/key", 2, 60);
  const PlanRules rules;
  const EyePlan& e = OnlyEye(s.pass.Plan("/cam", 64, 64, {}, rules));
  INFO("eye " << e.pixels << " px");
  REQUIRE(e.pixels < 3);
  CHECK(e.inView);
  CHECK(e.switches.mnee);  // sweep 1: MNEE stays ahead of path tracing down to 1.6 px for a small key
  PlanRules cut;
  cut.mneeMinPixels = 8;  // the rule, when set, does cut
  const EyePlan& c = OnlyEye(s.pass.Plan("/cam", 64, 64, {}, cut));
  CHECK_FALSE(c.switches.mnee);
  CHECK(c.lights[0].why.find("px <") != std::string::npos);
  CHECK(e.sss == ScleraModel::Diffuse);  // about 1 px: under PlanRules::sssMinPixels
  CHECK_FALSE(e.switches.limbalArc);
  CHECK(e.refineLevel == 0);
}

TEST_CASE("a side light on a visible limbus of an eye mesh gets the sclera walk and the limbal arc", "[plan]") {
  Scene s(60, /*mesh=*/true);
  s.SphereLight("/key", 2, 60);
  const RenderPlan plan = s.Plan(512);
  const EyePlan& e = OnlyEye(plan);
  INFO(Describe(plan));
  CHECK(e.limbusPixels > PlanRules{}.sssMinLimbusPixels);
  CHECK(e.sss == ScleraModel::RandomWalk);
  CHECK(e.switches.limbalArc);
  CHECK(plan.switches.scleraScattering);
  CHECK(e.refineLevel ==
        PlanRules{}.refineMaxLevel);  // large on screen: the planner's cap (sweep refine), under the ceiling 3
  CHECK(e.refineLevel == 2);

  Scene frontal(60, /*mesh=*/true);
  frontal.SphereLight("/key", 2, 5);
  const EyePlan& f = OnlyEye(frontal.Plan(512));
  CHECK(f.sss == ScleraModel::RandomWalk);
  CHECK(f.switches.limbalArc);  // sweep sclera: front-lit, dropping the cylinder still cost 2-17% of the eye's light
}

TEST_CASE("an analytic eye has no sclera volume to walk", "[plan]") {
  Scene s(40);
  s.SphereLight("/key", 2, 60);
  const EyePlan& e = OnlyEye(s.Plan(512));
  CHECK(e.sss == ScleraModel::None);
  CHECK_FALSE(e.switches.limbalArc);
  CHECK(e.refineLevel == -1);
}

TEST_CASE("an eye behind the camera or out of view gets neither MNEE nor sclera scattering", "[plan]") {
  // The camera at z = 40 looking down +z (turned around): the eye is behind it.
  Matrix4d turned(1.0);
  turned[0] = glm::dvec4(-1, 0, 0, 0), turned[2] = glm::dvec4(0, 0, -1, 0), turned[3] = glm::dvec4(0, 0, 40, 1);
  Scene behind(40, /*mesh=*/true, turned);
  behind.SphereLight("/key", 2, 30);
  const RenderPlan plan = behind.Plan(64);
  const EyePlan& b = OnlyEye(plan);
  INFO(Describe(plan));
  CHECK(b.behindCamera);
  CHECK_FALSE(b.inView);
  CHECK(b.pixels == 0);
  CHECK_FALSE(b.switches.mnee);
  CHECK(b.sss == ScleraModel::Diffuse);
  CHECK_FALSE(plan.switches.mnee);

  // The camera moved 200 mm to the side, still looking down -z: the eye is in front but outside the frame.
  Scene aside(40, /*mesh=*/false, Translate(200, 0, 40));
  aside.SphereLight("/key", 2, 30);
  const EyePlan& a = OnlyEye(aside.Plan(64));
  CHECK_FALSE(a.behindCamera);
  CHECK_FALSE(a.inView);
  CHECK_FALSE(a.switches.mnee);
  CHECK(a.lights[0].why.find("out of view") != std::string::npos);
}

TEST_CASE("a light below the rim plane cannot reach the iris", "[plan]") {
  Scene s(40);
  s.SphereLight("/behind", 2, 120);
  const EyePlan& e = OnlyEye(s.Plan(64));
  CHECK_FALSE(e.lights[0].reachesIris);
  CHECK(e.lights[0].strategy == LightStrategy::None);
  CHECK_FALSE(e.switches.mnee);
}

TEST_CASE("explicit flags and authored values win over the planner, and the reasons say so", "[plan]") {
  Scene s(40);
  s.Dome();
  PlanOverrides flags;
  flags.mnee = true;
  flags.mneeAllSolutions = true;
  const RenderPlan plan = s.Plan(64, flags);
  const EyePlan& e = OnlyEye(plan);
  CHECK(e.switches.mnee);  // the dome alone would get none
  CHECK(e.lights[0].why.rfind("flag", 0) == 0);
  CHECK(e.switches.mneeAllSolutions);
  CHECK(e.why.at("mneeAllSolutions").rfind("flag", 0) == 0);
  CHECK(plan.switches.mnee);
  CHECK(plan.switches.mneeAllSolutions);

  Scene off(40);
  off.SphereLight("/key", 2, 45);
  PlanOverrides noMnee;
  noMnee.mnee = false;
  CHECK_FALSE(OnlyEye(off.Plan(64, noMnee)).switches.mnee);
  CHECK_FALSE(off.Plan(64, noMnee).switches.mnee);

  Scene arc(60, /*mesh=*/true);
  arc.SphereLight("/key", 2, 60);
  PlanOverrides authored;
  authored.limbalArc = true;                    // a flag says on ...
  authored.authored["/Eye"].limbalArc = false;  // ... the artist authored off on this eye: the artist wins
  const EyePlan& a = OnlyEye(arc.Plan(512, authored));
  CHECK_FALSE(a.switches.limbalArc);
  CHECK(a.why.at("limbalArc").rfind("authored", 0) == 0);

  PlanOverrides noWalk;
  noWalk.scleraScattering = false;
  const RenderPlan flat = arc.Plan(512, noWalk);
  CHECK(OnlyEye(flat).sss == ScleraModel::Diffuse);
  CHECK_FALSE(flat.switches.scleraScattering);

  PlanOverrides ceiling;
  ceiling.refineLevelCeiling = 1;
  CHECK(OnlyEye(arc.Plan(512, ceiling)).refineLevel == 1);
}

TEST_CASE("the plan measures the lights the renderer gets, in its order (GatherLights)", "[plan]") {
  Scene s(200);
  s.SphereLight("/rim", 1, 80);  // added out of id order: the order is the index's, not the adds'
  s.Dome();
  s.SphereLight("/key", 2, 30);
  const RenderPlan plan = s.Plan(256);  // synced: the lights hold their params
  const std::vector<GatheredLight> lights = GatherLights(s.index);
  REQUIRE(lights.size() == 3);
  CHECK(RenderLightOrder(s.index) == std::vector<PrimId>{"/dome", "/key", "/rim"});
  REQUIRE(plan.eyes.size() == 1);
  REQUIRE(plan.eyes[0].lights.size() == 3);
  for (std::size_t k = 0; k < lights.size(); ++k) {
    CHECK(lights[k].id == RenderLightOrder(s.index)[k]);
    CHECK(lights[k].prim == s.index.GetSprim(lights[k].id));
    CHECK(plan.eyes[0].lights[k].light == lights[k].id);
    CHECK(plan.eyes[0].lights[k].kind == lights[k].light.type);
  }
  CHECK(lights[0].light.type == LightType::Dome);
  CHECK(lights[1].light.type == LightType::Sphere);
  CHECK(lights[1].light.motion == nullptr);  // static: no motion over the shutter
}

TEST_CASE("several eyes are each applied their own plan, and nothing says pending", "[plan]") {
  Scene s(200);
  s.scene.AddAnalyticEye("/Eye2", EyeParams{}, Translate(30, 0, 0));
  s.SphereLight("/key", 2, 30);
  const RenderPlan plan = s.Plan(256);
  REQUIRE(plan.eyes.size() == 2);
  CHECK(Describe(plan).find("pending") == std::string::npos);
  for (const EyePlan& e : plan.eyes) {
    CHECK(e.switches.mnee);
    CHECK(e.RenderOptions(RenderLightOrder(s.index)).mneeLights == std::vector<bool>{true});  // MNEE for /key
  }
  const auto lines = plan.SummaryLines();
  CHECK(lines.size() == 2);  // one per eye; no shared-switches line
  for (const auto& line : lines) CHECK(line.find("pending") == std::string::npos);
  // Applied: each eye rprim holds its own switches.
  RenderSettings settings;
  ApplyRenderPlan(plan, &s.index, &settings);
  for (const PrimId id : {"/Eye", "/Eye2"}) {
    const EyeRenderOptions& o = s.index.GetRprim(id)->Context()->eyeOptions;
    CHECK(o.planned);
    CHECK(o.mneeLights == std::vector<bool>{true});
  }
  ClearRenderPlan(&s.index);
  CHECK_FALSE(s.index.GetRprim("/Eye")->Context()->eyeOptions.planned);
}

TEST_CASE("a missing camera or an empty image is a one-line error", "[plan]") {
  Scene s(40);
  CHECK_THROWS_WITH(s.pass.Plan("/nope", 64, 64, {}), Catch::Contains("camera /nope not found"));
  CHECK_THROWS_WITH(s.pass.Plan("/cam", 0, 64, {}), Catch::Contains("not positive"));
}

TEST_CASE("EXR string header attributes round-trip, and required names are refused", "[plan][image]") {
  const auto dir = std::filesystem::temp_directory_path() / "hdeye_plan_attr";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "a.exr").string();
  const std::string json = "{\"eyes\": [{\"prim\": \"/Eye\", \"why\": {\"mnee\": \"0.003 sr\"}}]}";
  WriteExr(path, 2, 1, {{"R", {0.5f, 1.0f}}}, {{"eyerender:plan", json}});
  const auto attributes = ReadExrStringAttributes(path);
  REQUIRE(attributes.count("eyerender:plan"));
  CHECK(attributes.at("eyerender:plan") == json);
  CHECK_THROWS_WITH(WriteExr(path, 2, 1, {{"R", {0.5f, 1.0f}}}, {{"channels", "x"}}), Catch::Contains("required"));
  CHECK(ReadExrStringAttributes(path).at("eyerender:plan") == json);  // the failed write left the file alone
  std::filesystem::remove_all(dir);
}

TEST_CASE("a large light keeps MNEE near the gaze and loses it at grazing angles, as sweep 2 measured", "[plan]") {
  const PlanRules rules;
  Scene s(40);
  s.SphereLight("/near", 100, 30);       // 0.84 sr, 30 deg: MNEE measured ahead (x1.7)
  s.SphereLight("/grazing", 100, 75);    // 0.84 sr, 75 deg: MNEE measured behind (x0.78)
  s.SphereLight("/huge", 195, 30, 200);  // about 4.8 sr: behind (x0.74 at 4.3 sr)
  const EyePlan& e = OnlyEye(s.Plan(64));
  REQUIRE(e.lights.size() == 3);
  CHECK(e.lights[0].light == "/grazing");
  CHECK(e.lights[0].solidAngleSr > rules.mneeMaxSolidAngleSrGrazing);
  CHECK(e.lights[0].strategy == LightStrategy::Bsdf);
  CHECK(e.lights[1].light == "/huge");
  CHECK(e.lights[1].strategy == LightStrategy::Bsdf);
  CHECK(e.lights[2].light == "/near");
  CHECK(e.lights[2].solidAngleSr == Approx(2 * kPi * (1 - std::sqrt(1 - 0.25))).epsilon(1e-6));
  CHECK(e.lights[2].strategy == LightStrategy::Mnee);
}

TEST_CASE("the grazing solid-angle bound starts at 65 deg, as sweep 2 at 60-75 deg measured", "[plan]") {
  const PlanRules rules;
  CHECK(rules.grazingAngleDeg == 65);
  Scene s(40);
  s.SphereLight("/a60", 100, 60);  // 0.84 sr, 60 deg: MNEE measured ahead (x1.20; x1.01 at 1.38 sr)
  s.SphereLight("/b70", 100, 70);  // 0.84 sr, 70 deg: MNEE measured behind (x0.83)
  s.SphereLight("/c70", 50, 70);   // 0.2 sr, 70 deg: MNEE measured ahead (x1.31)
  const EyePlan& e = OnlyEye(s.Plan(64));
  REQUIRE(e.lights.size() == 3);
  INFO(e.lights[0].why << " | " << e.lights[1].why << " | " << e.lights[2].why);
  CHECK(e.lights[0].light == "/a60");
  CHECK(e.lights[0].strategy == LightStrategy::Mnee);
  CHECK(e.lights[1].light == "/b70");
  CHECK(e.lights[1].strategy == LightStrategy::Bsdf);
  CHECK(e.lights[1].why.find(">= 65 deg") != std::string::npos);
  CHECK(e.lights[2].light == "/c70");
  CHECK(e.lights[2].solidAngleSr <= rules.mneeMaxSolidAngleSrGrazing);
  CHECK(e.lights[2].strategy == LightStrategy::Mnee);
}

TEST_CASE("a small eye mesh keeps the sclera walk and the limbal arc even when its limbus band is under a pixel",
          "[plan]") {
  // Sweep sclera: the arc mattered on 8 px eyes (a 0.13 px band): it lights the shadowed sclera, not only the band.
  Scene s(300, /*mesh=*/true);
  s.SphereLight("/key", 2, 60);
  const EyePlan& e = OnlyEye(s.Plan(64));
  INFO(e.pixels << " px, limbus " << e.limbusPixels << " px");
  REQUIRE(e.pixels > PlanRules{}.sssMinPixels);
  REQUIRE(e.limbusPixels < 1);
  CHECK(e.sss == ScleraModel::RandomWalk);
  CHECK(e.switches.limbalArc);
  CHECK(e.why.at("limbalArc").find("sweep sclera") != std::string::npos);
  // The band rule still works when a user sets it.
  PlanRules band;
  band.sssMinLimbusPixels = 1.5;
  const EyePlan b = OnlyEye(s.pass.Plan("/cam", 64, 64, {}, band));
  CHECK_FALSE(b.switches.limbalArc);
  CHECK(b.why.at("limbalArc").find("limbus band") != std::string::npos);
}

// ---- Application: the renderer reads each eye's plan, per light for MNEE --------------------------------------

namespace {

const EyePlan& EyeNamed(const RenderPlan& plan, const PrimId& id) {
  for (const EyePlan& e : plan.eyes)
    if (e.prim == id) return e;
  FAIL("no eye " << id << " in the plan");
  return plan.eyes.front();
}

/// Means over the pixels of rprim `prim` (the primId AOV): colour (red) and irisMnee (red), and the pixel count.
struct EyeMeans {
  double color = 0, iris = 0;
  int pixels = 0;
};
EyeMeans MeansOver(test::RenderStack& s, const PrimId& prim, int size) {
  const int index = s.index.GetRprim(prim)->Context()->primIndex;
  EyeMeans m;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (int(std::lround(s.Buffer("/prim").Resolved(x, y, 0))) == index) {
        m.color += s.Buffer("/color").Resolved(x, y, 0), m.iris += s.Buffer("/iris").Resolved(x, y, 0), ++m.pixels;
      }
  if (m.pixels) m.color /= m.pixels, m.iris /= m.pixels;
  return m;
}

void AddBuffers(Scene& s, int size) {
  s.scene.AddRenderBuffer("/color", size, size, 4);
  s.scene.AddRenderBuffer("/iris", size, size, 3);
  s.scene.AddRenderBuffer("/prim", size, size, 1);
}

RenderStats RenderBuffers(Scene& s) {
  for (const char* b : {"/color", "/iris", "/prim"}) s.Buffer(b).Clear();
  return s.pass.Execute("/cam", {{"color", "/color"}, {"irisMnee", "/iris"}, {"primId", "/prim"}});
}

}  // namespace

TEST_CASE("two eyes in one frame render each with its own plan: MNEE on the near eye, off on the far one",
          "[plan][render]") {
  // A test rule cuts MNEE under 10 px: the near eye (about 19 px) keeps it, the far one (about 5 px) loses it.
  Scene s(100);
  s.scene.AddAnalyticEye("/Far", EyeParams{}, Translate(60, 0, -300));
  s.SphereLight("/key", 2, 30);
  constexpr int kSize = 64;
  AddBuffers(s, kSize);
  PlanRules rules;
  rules.mneeMinPixels = 10;
  const RenderPlan plan = s.pass.Plan("/cam", kSize, kSize, {}, rules);
  INFO(Describe(plan));
  REQUIRE(EyeNamed(plan, "/Eye").switches.mnee);
  REQUIRE_FALSE(EyeNamed(plan, "/Far").switches.mnee);
  RenderSettings& settings = s.delegate.Settings();
  settings.samplesPerPixel = 16;
  ApplyRenderPlan(plan, &s.index, &settings);
  REQUIRE(settings.eyeSwitches.mnee);  // the global default is on (one eye needs it): the far eye must not take it
  RenderStats stats = RenderBuffers(s);
  const EyeMeans near = MeansOver(s, "/Eye", kSize), far = MeansOver(s, "/Far", kSize);
  std::printf("two eyes, per eye: near %d px irisMnee %.4g, far %d px irisMnee %.4g\n", near.pixels, near.iris,
              far.pixels, far.iris);
  CHECK(stats.nonFiniteSamples == 0);
  REQUIRE(near.pixels > 100);
  REQUIRE(far.pixels > 4);
  CHECK(near.iris > 0);
  CHECK(far.iris == 0);  // no MNEE ran on the far eye
  CHECK(far.color > 0);  // it is still lit (paths leaving its iris count the key)

  // The control: the same plan through the global switches only -- the far eye gets MNEE again, so the
  // check above can fail.
  ClearRenderPlan(&s.index);
  ApplyRenderPlan(plan, &settings);
  stats = RenderBuffers(s);
  const EyeMeans farGlobal = MeansOver(s, "/Far", kSize);
  std::printf("two eyes, global only: far irisMnee %.4g\n", farGlobal.iris);
  CHECK(farGlobal.iris > 0);
}

TEST_CASE(
    "per-light furnace: a closed white eye in a uniform dome returns the dome whether MNEE or the exiting "
    "paths count the dome, never both",
    "[plan][render]") {
  // The dome is MNEE's (flag) or the exiting paths' (the plan's own choice). If the path leaving the iris
  // counted a light MNEE counted, the mean would rise by MNEE's share of it (S, printed); if neither counted
  // it, it would fall by S. Both must return the dome (1) and agree far inside S.
  EyeParams white;
  white.chamber.pupilDiameter = 0;  // closed: nothing leaves through the lens
  white.irisColor = glm::vec3(1);
  white.scleraColor = glm::vec3(1);
  constexpr int kSize = 20;
  EyeMeans means[2];
  for (int viaMnee = 0; viaMnee < 2; ++viaMnee) {
    Scene s(40);
    s.scene.SetEyeParams("/Eye", white);
    s.Dome();
    AddBuffers(s, kSize);
    PlanOverrides flags;
    if (viaMnee) flags.mnee = true;
    const RenderPlan plan = s.Plan(kSize, flags);
    REQUIRE(OnlyEye(plan).lights.at(0).strategy == (viaMnee ? LightStrategy::Mnee : LightStrategy::Bsdf));
    RenderSettings& settings = s.delegate.Settings();
    settings.samplesPerPixel = 256;
    settings.maxDepth = 16;
    ApplyRenderPlan(plan, &s.index, &settings);
    settings.eyeSwitches.mnee = !viaMnee;  // the global default says the opposite: the eye's own switch must win
    const RenderStats stats = RenderBuffers(s);
    means[viaMnee] = MeansOver(s, "/Eye", kSize);
    std::printf("per-light furnace, dome by %s: mean %.4f over %d eye pixels, irisMnee %.4f (%.1f s)\n",
                viaMnee ? "MNEE" : "BSDF paths", means[viaMnee].color, means[viaMnee].pixels, means[viaMnee].iris,
                stats.seconds);
    CHECK(stats.nonFiniteSamples == 0);
    REQUIRE(means[viaMnee].pixels > 100);
    CHECK(means[viaMnee].color == Approx(1.0).epsilon(0.02));
  }
  const double share = means[1].iris;  // S: the dome light MNEE brings to the iris, per eye pixel
  CHECK(means[0].iris == 0);
  REQUIRE(share > 0.05);
  CHECK(std::abs(means[1].color - means[0].color) < share / 4);
}

TEST_CASE("a small key and a dome split per light (key MNEE, dome BSDF) agree with MNEE for both", "[plan][render]") {
  // The mixed case the furnace cannot hold (a key breaks uniformity): the split and all-MNEE estimate the same
  // image. The dome's MNEE share S (all-MNEE's irisMnee minus the split's) is what a double count or a drop
  // would move the mean by; the two must agree far inside it.
  constexpr int kSize = 24;
  EyeMeans means[2];
  for (int allMnee = 0; allMnee < 2; ++allMnee) {
    Scene s(40);
    EyeParams eye;
    eye.irisColor = glm::vec3(0.6f);
    s.scene.SetEyeParams("/Eye", eye);
    s.Dome();
    LightParams key;
    key.radius = 10;  // 0.008 sr at 200 mm: MNEE's by the rules, and a corneal highlight that is not a firefly
    key.intensity = 40;
    const double a = 30 * kPi / 180;
    s.scene.AddLight("/key", "sphereLight", key, Translate(200 * std::sin(a), 0, kIrisZ + 200 * std::cos(a)));
    AddBuffers(s, kSize);
    PlanOverrides flags;
    if (allMnee) flags.mnee = true;
    const RenderPlan plan = s.Plan(kSize, flags);
    const EyePlan e = OnlyEye(plan);
    REQUIRE(e.lights.size() == 2);
    REQUIRE(e.lights[0].strategy == (allMnee ? LightStrategy::Mnee : LightStrategy::Bsdf));  // the dome
    REQUIRE(e.lights[1].strategy == LightStrategy::Mnee);                                    // the key
    RenderSettings& settings = s.delegate.Settings();
    settings.samplesPerPixel = 256;
    settings.maxDepth = 16;
    ApplyRenderPlan(plan, &s.index, &settings);
    const RenderStats stats = RenderBuffers(s);
    means[allMnee] = MeansOver(s, "/Eye", kSize);
    std::printf("key + dome, %s: mean %.4f over %d eye pixels, irisMnee %.4f (%.1f s)\n",
                allMnee ? "all MNEE" : "split (key MNEE, dome BSDF)", means[allMnee].color, means[allMnee].pixels,
                means[allMnee].iris, stats.seconds);
    CHECK(stats.nonFiniteSamples == 0);
    REQUIRE(means[allMnee].pixels > 100);
  }
  const double domeShare = means[1].iris - means[0].iris;
  std::printf("key + dome: dome's MNEE share %.4f, difference of means %.4f (%.2f%%)\n", domeShare,
              means[0].color - means[1].color, 100 * (means[0].color / means[1].color - 1));
  CHECK(means[0].iris > 0);  // the key is still MNEE's in the split
  REQUIRE(domeShare > 0.02 * means[1].color);
  CHECK(std::abs(means[0].color - means[1].color) < domeShare / 4);
  CHECK(means[0].color == Approx(means[1].color).epsilon(0.03));
}

TEST_CASE("an eye mesh walks its sclera by its own plan, whatever the global switch says", "[plan][render]") {
  Scene s(40, /*mesh=*/true);
  s.SphereLight("/key", 2, 60);
  AddBuffers(s, 16);
  RenderPlan plan = s.Plan(16);
  REQUIRE(plan.eyes.at(0).sss == ScleraModel::RandomWalk);
  RenderSettings& settings = s.delegate.Settings();
  settings.samplesPerPixel = 4;
  ApplyRenderPlan(plan, &s.index, &settings);
  settings.eyeSwitches.scleraScattering = false;
  const RenderStats walked = RenderBuffers(s);
  plan.eyes[0].sss = ScleraModel::Diffuse;
  plan.eyes[0].switches.scleraScattering = false;
  ApplyRenderPlan(plan, &s.index, &settings);
  settings.eyeSwitches.scleraScattering = true;
  const RenderStats flat = RenderBuffers(s);
  INFO("walks: plan randomWalk " << walked.scleraWalks << ", plan diffuse " << flat.scleraWalks);
  CHECK(walked.scleraWalks > 0);
  CHECK(flat.scleraWalks == 0);
}

// Sweeps "sclera" and "refine" (docs/render_plan.md): the measured rules on synthetic cases.

TEST_CASE("a tiny eye mesh gets a Lambertian sclera, no limbal arc and refine level 0", "[plan]") {
  Scene s(2000, /*mesh=*/true);
  s.SphereLight("/key", 2, 70);
  const PlanRules rules;
  const EyePlan e = OnlyEye(s.Plan(64));
  INFO("eye " << e.pixels << " px; sssMinPixels " << rules.sssMinPixels);
  REQUIRE(e.pixels < rules.sssMinPixels);
  CHECK(e.sss == ScleraModel::Diffuse);
  CHECK_FALSE(e.switches.limbalArc);
  CHECK(e.refineLevel == 0);
  CHECK(e.why.at("sss").find("sweep sclera") != std::string::npos);
  CHECK(e.why.at("refineLevel").find("sweep refine") != std::string::npos);
}

TEST_CASE(
    "a large side-lit eye mesh gets the walk, the limbal arc and the ceiling level, and a front light keeps the arc",
    "[plan]") {
  Scene s(60, /*mesh=*/true);
  s.SphereLight("/key", 2, 70);
  PlanOverrides overrides;
  overrides.refineLevelCeiling = 2;
  const EyePlan e = OnlyEye(s.Plan(1024, overrides));
  INFO(e.pixels << " px; why: " << e.why.at("refineLevel"));
  CHECK(e.sss == ScleraModel::RandomWalk);
  CHECK(e.switches.limbalArc);
  CHECK(e.refineLevel == 2);  // the planner's level would be higher: the ceiling holds it
  CHECK(e.why.at("refineLevel").find("ceiling") != std::string::npos);
  // Sweep sclera: without the cylinder a front-lit close-up loses 16% of the eye's light: the arc stays on.
  Scene frontal(60, /*mesh=*/true);
  frontal.SphereLight("/key", 2, 15);
  const EyePlan f = OnlyEye(frontal.Plan(512));
  CHECK(f.sss == ScleraModel::RandomWalk);
  CHECK(f.switches.limbalArc);
}

TEST_CASE("the refine ceiling wins over the planner at any size, down to level 0", "[plan]") {
  Scene s(60, /*mesh=*/true);
  s.SphereLight("/key", 2, 70);
  for (int ceiling : {0, 1, 2, 3}) {
    PlanOverrides o;
    o.refineLevelCeiling = ceiling;
    const EyePlan e = OnlyEye(s.Plan(2048, o));
    INFO("ceiling " << ceiling << ", " << e.pixels << " px -> " << e.refineLevel << ": " << e.why.at("refineLevel"));
    CHECK(e.refineLevel == std::min(ceiling, PlanRules{}.refineMaxLevel));
  }
}

TEST_CASE("the planner caps eye meshes at level 2: sweep refine found level 3 never differs from it", "[plan]") {
  Scene s(60, /*mesh=*/true);
  s.SphereLight("/key", 2, 70);
  PlanOverrides o;
  o.refineLevelCeiling = 3;
  const EyePlan e = OnlyEye(s.Plan(2048, o));  // thousands of px: one level per doubling would give 5
  INFO(e.pixels << " px: " << e.why.at("refineLevel"));
  REQUIRE(e.pixels >= 4 * PlanRules{}.refinePixelsLevel1);
  CHECK(PlanRules{}.refineMaxLevel == 2);
  CHECK(e.refineLevel == 2);
  CHECK(e.why.at("refineLevel").find("at most level 2") != std::string::npos);
  CHECK(e.why.at("refineLevel").find("provisional") == std::string::npos);
  PlanRules rules;
  rules.refineMaxLevel = 3;  // the cap is a rule: raising it gives level 3 back
  CHECK(OnlyEye(s.pass.Plan("/cam", 2048, 2048, o, rules)).refineLevel == 3);
}

TEST_CASE("an authored eye:limbalArc wins on a tiny eye and on a large one", "[plan]") {
  Scene tiny(2000, /*mesh=*/true);
  tiny.SphereLight("/key", 2, 70);
  PlanOverrides on;
  on.authored["/Eye"].limbalArc = true;
  const EyePlan t = OnlyEye(tiny.Plan(64, on));
  CHECK(t.sss == ScleraModel::Diffuse);
  CHECK(t.switches.limbalArc);  // the artist's value, even with no walk for it to change
  CHECK(t.why.at("limbalArc").rfind("authored", 0) == 0);
  Scene large(60, /*mesh=*/true);
  large.SphereLight("/key", 2, 70);
  PlanOverrides off;
  off.authored["/Eye"].limbalArc = false;
  const EyePlan l = OnlyEye(large.Plan(512, off));
  CHECK(l.sss == ScleraModel::RandomWalk);
  CHECK_FALSE(l.switches.limbalArc);
}

TEST_CASE("the precision decision states float's measured error against the eye's pixel footprint", "[plan]") {
  const PlanRules rules;
  for (double distance : {60.0, 2000.0}) {
    Scene s(distance, /*mesh=*/true);
    const EyePlan e = OnlyEye(s.Plan(256));
    INFO(e.pixels << " px: " << e.why.at("precision"));
    CHECK(e.why.at("precision").rfind("double (no float eye path)", 0) == 0);  // the eye is traced in double
    CHECK(e.pixelFootprintMm == Approx(15.08 / e.pixels).epsilon(1e-3));
    CHECK(e.floatWouldSuffice == (rules.floatHitErrorMm / e.pixelFootprintMm <= rules.floatMaxErrorPixels));
    CHECK(e.why.at("precision").find("intersection_benchmark") != std::string::npos);
  }
  // An extreme close-up (a 10 000 px iris): float's 0.3 um is then 0.2 px, and the plan says float would not do.
  Scene macro(60, /*mesh=*/true);
  const EyePlan m = OnlyEye(macro.Plan(20000));
  INFO(m.pixels << " px: " << m.why.at("precision"));
  CHECK_FALSE(m.floatWouldSuffice);
  CHECK(m.why.at("precision").find("would not be enough") != std::string::npos);
  CHECK(m.why.at("precision").rfind("double (no float eye path)", 0) == 0);
}

TEST_CASE("applying a plan that changes one eye mesh's refine level re-refines that mesh only", "[plan]") {
  test::RenderStack s;
  CameraParams camera;
  camera.focalLength = 50, camera.horizontalAperture = 24, camera.verticalAperture = 24;
  s.scene.AddCamera("/cam", camera, test::LookDownZ(60));
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::UvSphere(12, 12, 24, &topology, &points);
  topology.refineLevel = 2;  // the populate (--complexity) level
  EyeParams eye;
  eye.modelTransform = Translate(0, 0, 12);
  s.scene.AddEyeMesh("/Near", topology, points, eye);                           // a close-up
  s.scene.AddEyeMesh("/Far", topology, points, eye, Translate(30, 0, -20000));  // a few pixels wide
  PlanRules rules;
  rules.refinePixelsLevel1 = 16;  // the mechanics, not the thresholds: the near eye plans >= 2, the far one 0
  PlanOverrides overrides;
  overrides.refineLevelCeiling = 3;
  const RenderPlan plan = s.pass.Plan("/cam", 256, 256, overrides, rules);
  REQUIRE(plan.eyes.size() == 2);
  auto* near = dynamic_cast<Mesh*>(s.index.GetRprim("/Near"));
  auto* far = dynamic_cast<Mesh*>(s.index.GetRprim("/Far"));
  REQUIRE((near && far));
  const MeshSyncStats nearBefore = near->Stats(), farBefore = far->Stats();
  const int farTriangles = far->TriangleCount();
  REQUIRE(near->RefineLevel() == 2);
  REQUIRE(far->RefineLevel() == 2);

  RenderSettings& settings = s.delegate.Settings();
  ApplyRenderPlan(plan, &s.index, &settings);
  INFO(Describe(plan));
  CHECK((s.index.GetChangeTracker().GetDirtyBits("/Far") & dirty::DirtyTopology) != 0);
  CHECK(s.index.GetChangeTracker().GetDirtyBits("/Near") == dirty::Clean);  // planned >= 2, renders 2: unchanged
  s.index.SyncAll();
  CHECK(far->RefineLevel() == 0);
  CHECK(far->SceneRefineLevel() == 2);
  CHECK(far->TriangleCount() * 8 < farTriangles);  // two levels fewer: 16x fewer quads (minus the pole fans)
  CHECK(far->Stats().topologyBuilds == farBefore.topologyBuilds + 1);
  CHECK(far->Stats().refineLevelChanges == farBefore.refineLevelChanges + 1);
  CHECK(near->Stats().topologyBuilds == nearBefore.topologyBuilds);
  CHECK(near->Stats().refinements == nearBefore.refinements);
  CHECK(near->Stats().pointUploads == nearBefore.pointUploads);

  // The same plan again changes nothing; clearing it restores the scene's level on the far eye alone.
  ApplyRenderPlan(plan, &s.index, &settings);
  CHECK(s.index.GetChangeTracker().GetDirtyBits("/Far") == dirty::Clean);
  ClearRenderPlan(&s.index);
  CHECK((s.index.GetChangeTracker().GetDirtyBits("/Far") & dirty::DirtyTopology) != 0);
  CHECK(s.index.GetChangeTracker().GetDirtyBits("/Near") == dirty::Clean);
  s.index.SyncAll();
  CHECK(far->RefineLevel() == 2);
  CHECK(far->TriangleCount() == farTriangles);
  CHECK(far->Stats().refinements == farBefore.refinements + 1);
  CHECK(near->Stats().topologyBuilds == nearBefore.topologyBuilds);
}
