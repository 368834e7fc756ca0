// The limbal arc in the renderer (docs/limbal_arc.md): eye-mesh sclera as a random-walk volume
// bounded by the mesh itself, the teleportation cylinder, the limbalArc AOV, energy audits.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/eyeMesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/scleraScattering.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <eyelib/anterior_surface.h>
#include <eyelib/random.h>
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// An eye mesh gazing at a camera 40 mm away (the image spans +-7.2 mm at the apex), lit by a dome
/// or by a small sphere light at `lightAngle` radians off the gaze towards +x.
struct ArcScene : test::RenderStack {
  int size;

  ArcScene(int size, const EyeParams& eye, bool dome, double lightAngle = 0) : size(size) {
    test::AddEyeCamera(scene);
    if (dome) {
      LightParams d;
      d.type = LightType::Dome;
      scene.AddLight("/light", primTypes::kDomeLight, d);
    } else {
      test::AddSphereLight(scene, "/light", 2, 400, {100 * std::sin(lightAngle), 0, 100 * std::cos(lightAngle)});
    }
    MeshTopology topology;
    std::vector<Vec3f> points;
    test::EyeballMesh(32, 16, 32, 1, &topology, &points);
    scene.AddEyeMesh("/eye", topology, points, eye);
    scene.AddRenderBuffer("/color", size, size, 4);
    scene.AddRenderBuffer("/arc", size, size, 3);
    scene.AddRenderBuffer("/depth", size, size, 1);
  }
  RenderStats Render(int spp, unsigned seed = 0) {
    delegate.Settings().samplesPerPixel = spp;
    delegate.Settings().seed = seed;
    for (const char* b : {"/color", "/arc", "/depth"}) Buffer(b).Clear();
    return pass.Execute("/cam", {{"color", "/color"}, {"limbalArc", "/arc"}, {"depth", "/depth"}});
  }
  /// Pixel centre (x, y) in mm on the apex plane (the camera looks down -z from 40 mm, 100 mm lens).
  glm::dvec2 Film(int x, int y) const {
    const double half = 40 * 18.0 / 100;  // 36 mm aperture / 2 over the focal length, at 40 mm
    return {(2 * (x + 0.5) / size - 1) * half, (1 - 2 * (y + 0.5) / size) * half};
  }
  /// Mean of a buffer's channels 0..2 over the pixels `inside` accepts (by film position).
  template <class F> glm::dvec3 Mean(const PrimId& id, F inside, int* count = nullptr) {
    glm::dvec3 sum(0);
    int n = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        if (Buffer("/color").Resolved(x, y, 3) == 1 && inside(Film(x, y))) {
          sum += glm::dvec3(Buffer(id).Resolved(x, y, 0), Buffer(id).Resolved(x, y, 1), Buffer(id).Resolved(x, y, 2));
          ++n;
        }
    if (count) *count = n;
    return n ? sum / double(n) : sum;
  }
};

}  // namespace

namespace {

/// The eye mesh prim of a synced scene, and its world-space boundary (the scene's world is the canonical
/// frame: identity transforms).
const EyeMesh& SyncedEye(ArcScene& s) {
  s.index.SyncAll();
  const auto* mesh = dynamic_cast<const EyeMesh*>(s.index.GetRprim("/eye"));
  REQUIRE(mesh);
  REQUIRE(mesh->PrototypeScene());
  return *mesh;
}

/// The walk's boundary in eyelib's terms, from the eye mesh (canonical = world here).
eyelib::SssBoundary Canonical(const WorldBoundary& world) {
  return [world](const glm::dvec3& o, const glm::dvec3& d, double tMax, double* t, glm::dvec3* n) {
    return world(o, d, tMax, t, n);
  };
}

struct Audit {
  glm::dvec3 escaped{0}, absorbed{0}, dropped{0};
  double worstBalance = 0, worstWeight = 0;  // |escaped + absorbed + dropped - 1| per path; largest channel weight
  int paths = 0, teleported = 0, capped = 0, invalid = 0;
};

/// `paths` walks entering the eye mesh's sclera at random points of the band 6.6-8 mm from the axis,
/// straight in along -z (refracted entry is the renderer's; here the direction into the medium is given).
Audit RunWalks(const WorldBoundary& boundary, const eyelib::SssMedium& medium, bool teleport, int paths) {
  eyelib::RandomWalkSettings settings;
  settings.teleport = teleport;
  settings.rouletteWeight = 0;  // per-path balance holds exactly only without roulette
  settings.maxSteps = 4096;
  const eyelib::AnteriorSurface<double> cornea;
  const double rim = cornea.RimRadius(), R = 12, zCentre = cornea.Sag(rim) - std::sqrt(R * R - rim * rim);
  Audit a;
  for (int i = 0; i < paths; ++i) {
    std::uint64_t dim = 0;
    auto random = [&] { return eyelib::UniformAt(7, std::uint64_t(i), dim++); };
    const double r = 6.6 + 1.4 * random(), phi = 2 * kPi * random();
    glm::dvec3 entry(r * std::cos(phi), r * std::sin(phi), 0);
    // On the mesh: the first crossing straight down from above (outside hits: the forward direction).
    entry.z = r < rim ? cornea.Sag(r) : zCentre + std::sqrt(R * R - r * r);
    const eyelib::WalkResult w =
        eyelib::RandomWalkSss(medium, settings, entry, glm::dvec3(0, 0, -1), Canonical(boundary), random);
    ++a.paths;
    if (w.status == eyelib::WalkStatus::Invalid) {
      ++a.invalid;
      continue;
    }
    const glm::dvec3 out = w.status == eyelib::WalkStatus::Exited ? w.weight : glm::dvec3(0);
    const glm::dvec3 drop = w.status == eyelib::WalkStatus::Capped ? w.weight : glm::dvec3(0);
    a.escaped += out, a.absorbed += w.absorbed, a.dropped += drop;
    a.worstBalance = std::max(a.worstBalance, glm::length(out + w.absorbed + drop - glm::dvec3(1)));
    a.worstWeight = std::max({a.worstWeight, w.weight.x, w.weight.y, w.weight.z});
    a.teleported += w.Teleported();
    a.capped += w.status == eyelib::WalkStatus::Capped;
  }
  return a;
}

/// The closest crossing of o + t d with the mesh's triangles, t > tMin, by brute force (Moller-Trumbore
/// in double over every triangle): the reference the Embree boundary is checked against.
double BruteForceCrossing(const EyeMesh& mesh, const glm::dvec3& o, const glm::dvec3& d, double tMin) {
  const std::vector<int>& tri = mesh.Layout().vertices;
  const std::vector<Vec3f>& p = mesh.Points();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 2 < tri.size(); i += 3) {
    const glm::dvec3 a(p[tri[i]]), b(p[tri[i + 1]]), c(p[tri[i + 2]]);
    const glm::dvec3 e1 = b - a, e2 = c - a, q = glm::cross(d, e2);
    const double det = glm::dot(e1, q);
    if (det == 0) continue;
    const glm::dvec3 s = o - a;
    const double u = glm::dot(s, q) / det;
    const glm::dvec3 r = glm::cross(s, e1);
    const double v = glm::dot(d, r) / det, t = glm::dot(e2, r) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && t > tMin) best = std::min(best, t);
  }
  return best;
}

bool InSclera(glm::dvec2 film) { return glm::length(film) > 6.8; }  // past the 6.445 mm outer limbus, with a margin

}  // namespace

TEST_CASE("eye mesh boundary: a walk's query from inside finds the eyeball, never the surface it starts on",
          "[limbal]") {
  ArcScene s(8, EyeParams{}, true);
  const EyeMesh& mesh = SyncedEye(s);
  std::int64_t queries = 0;
  MeshCrossing last;
  const WorldBoundary boundary = EyeMeshBoundary(mesh.PrototypeScene(), glm::dmat4(1.0), &queries, &last);
  const eyelib::AnteriorSurface<double> cornea;
  const double rim = cornea.RimRadius(), R = 12, zCentre = cornea.Sag(rim) - std::sqrt(R * R - rim * rim);
  const glm::dvec3 centre(0, 0, zCentre);
  double worstRadius = 0, shortestChord = 1e9, worstVsBrute = 0;
  int backHits = 0, misses = 0, nearZero = 0;
  for (int i = 0; i < 400; ++i) {
    const double u = eyelib::UniformAt(3, std::uint64_t(i), 0), v = eyelib::UniformAt(3, std::uint64_t(i), 1);
    const double z = 1 - 2 * u, sxy = std::sqrt(std::max(0.0, 1 - z * z));
    const glm::dvec3 d(sxy * std::cos(2 * kPi * v), sxy * std::sin(2 * kPi * v), z);
    double t = 0;
    glm::dvec3 n;
    if (!boundary(centre, d, 1e3, &t, &n)) {
      ++misses;
      continue;
    }
    const glm::dvec3 p = centre + t * d;
    worstVsBrute = std::max(worstVsBrute, std::abs(t - BruteForceCrossing(mesh, centre, d, 0)));
    if (p.z < zCentre) {  // the back half: 12 mm from the centre, the normal radial (the rim's crease is smoothed)
      ++backHits;
      worstRadius = std::max(worstRadius, std::abs(t - R));
      CHECK(std::abs(glm::dot(glm::normalize(n), d)) > 0.99);
    }
    // From the crossing, mirrored back inside: the next crossing is across the ball, never the start.
    const glm::dvec3 nIn = glm::dot(n, d) > 0 ? -glm::normalize(n) : glm::normalize(n);
    const glm::dvec3 back = d - 2 * glm::dot(d, -nIn) * (-nIn);
    double t2 = 0;
    glm::dvec3 n2;
    if (boundary(p, back, 1e3, &t2, &n2)) {
      shortestChord = std::min(shortestChord, t2);
      // The reference skips the start's own triangle by a micrometre; chords here are > 10 mm.
      worstVsBrute = std::max(worstVsBrute, std::abs(t2 - BruteForceCrossing(mesh, p, back, 1e-3)));
      nearZero += t2 < 1e-3;
    } else {
      ++misses;
    }
    // A segment that ends before the surface reports nothing.
    double t3 = 0;
    glm::dvec3 n3;
    CHECK_FALSE(boundary(centre, d, 0.9 * t, &t3, &n3));
  }
  std::printf(
      "eye mesh boundary: worst |t - brute force| %.2e mm; %d back hits, worst |t - 12 mm| %.4f mm (the "
      "level-1 limit surface, not the query); shortest chord from a crossing %.3f mm, %d near zero, %d misses, "
      "%lld queries for 1200 segments\n",
      worstVsBrute, backHits, worstRadius, shortestChord, nearZero, misses, (long long)queries);
  CHECK(worstVsBrute < 1e-4);
  CHECK(misses == 0);
  CHECK(backHits > 150);
  CHECK(worstRadius < 0.2);
  CHECK(nearZero == 0);
  CHECK(last.triangle != RTC_INVALID_GEOMETRY_ID);
}

TEST_CASE("no sclera path gains weight: per-path energy balance inside the eye mesh, cylinder on and off", "[limbal]") {
  ArcScene s(8, EyeParams{}, true);
  const EyeMesh& mesh = SyncedEye(s);
  const WorldBoundary boundary = EyeMeshBoundary(mesh.PrototypeScene(), glm::dmat4(1.0));
  // No absorption (single-scattering albedo exactly 1, 1/mm): every path leaves, with or without the
  // cylinder, and escaped + absorbed + dropped = 1 on each. With absorption (sclera-like 0.99): the
  // balance still holds per path, and no path's weight exceeds 1.
  eyelib::SssMedium clear;
  clear.sigmaT = glm::dvec3(1.0);
  clear.albedo = glm::dvec3(1.0);
  eyelib::SssMedium sclera = clear;
  sclera.albedo = glm::dvec3(0.99);
  const auto t0 = std::chrono::steady_clock::now();
  const Audit clearOn = RunWalks(boundary, clear, true, 600), clearOff = RunWalks(boundary, clear, false, 600);
  const Audit onA = RunWalks(boundary, sclera, true, 600), offA = RunWalks(boundary, sclera, false, 600);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& [name, a] : {std::pair<const char*, const Audit&>{"clear, on", clearOn},
                                {"clear, off", clearOff},
                                {"absorbing, on", onA},
                                {"absorbing, off", offA}})
    std::printf(
        "per-path audit (%s): %d paths, %d teleported, escaped %.5f absorbed %.5f dropped %.5f per path, "
        "worst |balance - 1| %.2e, largest weight %.6f, %d capped, %d invalid\n",
        name, a.paths, a.teleported, a.escaped.x / a.paths, a.absorbed.x / a.paths, a.dropped.x / a.paths,
        a.worstBalance, a.worstWeight, a.capped, a.invalid);
  std::printf("per-path audit: %.2f s\n", seconds);
  for (const Audit* a : {&clearOn, &clearOff, &onA, &offA}) {
    CHECK(a->invalid == 0);
    CHECK(a->worstBalance < 1e-9);
    CHECK(a->worstWeight <= 1 + 1e-12);
  }
  CHECK(clearOn.teleported > clearOn.paths / 4);
  CHECK(onA.teleported > onA.paths / 4);
  CHECK(clearOff.teleported == 0);
  // Without absorption, whatever the cylinder does, what enters leaves (up to capped walks, reported).
  CHECK(clearOn.escaped.x + clearOn.dropped.x == Approx(clearOn.paths).epsilon(1e-9));
  CHECK(clearOn.capped <= clearOn.paths / 100);
}

TEST_CASE("energy audit: a closed sclera under a uniform dome, limbal arc on and off", "[limbal][render]") {
  // The furnace on the sclera pixels of an eye mesh. Nothing may come back brighter than the dome (1).
  // With (almost) no absorption (scleraColor 1: single-scattering albedo 0.9989) the cylinder changes
  // nothing measurable; with a sclera's absorption it measurably brightens the sclera near the limbus:
  // walkers that would wander into the eye's interior are sent back along the far side's surface, so
  // less is absorbed (docs/limbal_arc.md). That is a real property of the model, bounded here, not noise.
  struct Row {
    double on, off, lambert;
    std::int64_t walks = 0, capped = 0;
  };
  auto run = [](float albedo) {
    Row row{};
    for (int variant = 0; variant < 3; ++variant) {
      EyeParams eye;
      eye.scleraColor = glm::vec3(albedo);
      eye.scleraMeanFreePath = glm::vec3(1.0f);
      eye.limbalArc = variant == 0;
      ArcScene s(24, eye, true);
      s.delegate.Settings().eyeSwitches.scleraScattering = variant != 2;
      s.delegate.Settings().maxDepth = 16;
      const RenderStats st = s.Render(48);
      CHECK(st.nonFiniteSamples == 0);
      CHECK(st.invalidWalks == 0);
      row.walks += st.scleraWalks, row.capped += st.cappedWalks;
      CHECK((variant == 2) == (st.scleraWalks == 0));
      int n = 0;
      const double m = s.Mean("/color", InSclera, &n).x;
      CHECK(n > 100);
      (variant == 0 ? row.on : variant == 1 ? row.off : row.lambert) = m;
    }
    return row;
  };
  const Row white = run(1.0f), sclera = run(0.8f);
  for (const auto& [albedo, r] : {std::pair<double, const Row&>{1.0, white}, {0.8, sclera}})
    std::printf(
        "sclera furnace, albedo %.1f: arc on %.4f, off %.4f (on/off %.4f), Lambert %.4f; %lld walks, %lld capped\n",
        albedo, r.on, r.off, r.on / r.off, r.lambert, (long long)r.walks, (long long)r.capped);
  // Capped walks are dropped energy, reported: rare even for a white sclera (long walks), none at 0.8.
  CHECK(white.capped * 1000 < white.walks);
  CHECK(sclera.capped == 0);
  // 48 spp over ~170 pixels: the noise of these means is below 0.3% (seed to seed).
  CHECK(white.on < 1.005);
  CHECK(white.off < 1.005);
  // With a white sclera the cylinder still brightens a little: on / off was 1.004 to 1.014 over seeds 0-3 with
  // either sampler (zsobol and independent), a mean of about +0.9 %; 2 % bounds that, where 1 % failed at 3 of 8.
  CHECK(white.on / white.off == Approx(1.0).epsilon(0.02));
  CHECK(sclera.on < 1.0);
  CHECK(sclera.on >= sclera.off);        // the cylinder only ever reduces absorption here
  CHECK(sclera.on / sclera.off < 1.10);  // measured +6% (the limbus-adjacent band)
}

TEST_CASE("the limbal arc: under a side light the shadowed limbus is lit only through the cylinder",
          "[limbal][render]") {
  // The sample scene's geometry: a small light 75 degrees off the gaze on +x; the cornea shadows the
  // limbus on -x. Bands of sclera just outside the outer limbus (6.5-7.2 mm), within 45 degrees of -x
  // (shadowed) and of +x (lit).
  auto band = [](double side) {
    return [side](glm::dvec2 f) {
      const double r = glm::length(f);
      return r > 6.5 && r < 7.2 && side * f.x > std::abs(f.y);
    };
  };
  struct Row {
    glm::dvec3 shadow, lit, arcShadow, arcLit;
    RenderStats stats;
  };
  auto run = [&](bool arc, bool scattering) {
    EyeParams eye;
    eye.limbalArc = arc;
    ArcScene s(40, eye, false, 75 * kPi / 180);
    s.delegate.Settings().eyeSwitches.scleraScattering = scattering;
    Row row;
    row.stats = s.Render(24);
    int n = 0;
    row.shadow = s.Mean("/color", band(-1), &n);
    CHECK(n > 30);
    row.lit = s.Mean("/color", band(+1));
    row.arcShadow = s.Mean("/arc", band(-1));
    row.arcLit = s.Mean("/arc", band(+1));
    CHECK(row.stats.nonFiniteSamples == 0);
    CHECK(row.stats.invalidWalks == 0);
    return row;
  };
  const Row on = run(true, true), off = run(false, true), lambert = run(false, false);
  for (const auto& [name, r] :
       {std::pair<const char*, const Row&>{"arc on", on}, {"arc off", off}, {"Lambert", lambert}})
    std::printf(
        "side-lit eye mesh (%s): shadowed limbus %.4f %.4f %.4f, lit limbus %.4f %.4f %.4f, limbalArc AOV "
        "shadowed %.4f lit %.4f; %lld walks (%lld teleported, %lld capped), %.2f s\n",
        name, r.shadow.x, r.shadow.y, r.shadow.z, r.lit.x, r.lit.y, r.lit.z, r.arcShadow.x, r.arcLit.x,
        (long long)r.stats.scleraWalks, (long long)r.stats.teleportedWalks, (long long)r.stats.cappedWalks,
        r.stats.seconds);
  std::printf("shadowed limbus, arc on / off: %.1f (red); shadowed / lit with the arc: %.3f, without: %.3f\n",
              on.shadow.x / off.shadow.x, on.shadow.x / on.lit.x, off.shadow.x / off.lit.x);
  // The arc: the shadowed limbus is several times brighter with the cylinder (measured ~10x), and
  // nearly all of its light is the limbalArc AOV's.
  CHECK(on.shadow.x > 4 * off.shadow.x);
  CHECK(on.arcShadow.x > 0.8 * on.shadow.x);
  CHECK(on.arcShadow.x <= on.shadow.x + 1e-6);
  // Off: no teleported path, an empty AOV; a Lambert sclera in the cornea's shadow is black (no fill light).
  CHECK(off.stats.teleportedWalks == 0);
  CHECK(off.arcShadow == glm::dvec3(0));
  CHECK(off.arcLit == glm::dvec3(0));
  CHECK(lambert.shadow == glm::dvec3(0));
  CHECK(lambert.stats.scleraWalks == 0);
  // The arc's light comes from the lit side: no energy is added, the lit limbus gives some up.
  CHECK(on.lit.x < off.lit.x);
}

TEST_CASE("sclera walks run only for eye meshes with scattering on, and bad mean free paths are reported", "[limbal]") {
  // An analytic eye has no sclera volume: no walk, whatever the settings.
  RenderDelegate delegate;
  RenderIndex index(&delegate);
  InMemorySceneDelegate scene(&index);
  RenderPass pass(&index);
  test::AddEyeCamera(scene);
  LightParams d;
  d.type = LightType::Dome;
  scene.AddLight("/dome", primTypes::kDomeLight, d);
  scene.AddAnalyticEye("/eye", EyeParams{});
  scene.AddRenderBuffer("/color", 16, 16, 4);
  delegate.Settings().samplesPerPixel = 4;
  const RenderStats st = pass.Execute("/cam", {{"color", "/color"}});
  CHECK(st.scleraWalks == 0);

  // ScatterInSclera refuses what it cannot map to a medium.
  ArcScene s(8, EyeParams{}, true);
  const EyeMesh& mesh = SyncedEye(s);
  const WorldBoundary boundary = EyeMeshBoundary(mesh.PrototypeScene(), glm::dmat4(1.0));
  std::uint64_t dim = 0;
  auto random = [&] { return eyelib::UniformAt(1, 0, dim++); };
  const glm::dvec3 entry(7, 0, -1.5);
  for (const glm::dvec3 mfp : {glm::dvec3(0, 1, 1), glm::dvec3(1, -1, 1), glm::dvec3(1, 1, NAN)}) {
    const ScleraExit e =
        ScatterInSclera(mesh.Eye(), entry, glm::dvec3(0, 0, -1), glm::dvec3(0.8), mfp, boundary, random);
    CHECK(e.status == eyelib::WalkStatus::Invalid);
    CHECK(e.weight == glm::dvec3(0));
  }
  const ScleraExit ok =
      ScatterInSclera(mesh.Eye(), entry, glm::dvec3(0, 0, -1), glm::dvec3(0.8), glm::dvec3(1), boundary, random);
  CHECK(ok.status != eyelib::WalkStatus::Invalid);
}

TEST_CASE("the eye AOVs sum to the beauty: nonEye, glint, iris, sclera and limbalArc, each present", "[limbal][aov]") {
  // A side-lit eye mesh (its shadowed limbus lit through the cylinder) before a Lambert wall the light also reaches:
  // every part has light somewhere, and per pixel the five parts add up to the colour to float precision.
  ArcScene s(40, EyeParams{}, false, 75 * kPi / 180);
  MeshTopology wall;
  std::vector<Vec3f> points;
  test::Quad(40, &wall, &points);
  MaterialParams grey;
  grey.diffuseColor = glm::vec3(0.5f);
  s.scene.AddMaterial("/wall_material", grey);
  Matrix4d behind(1.0);
  behind[3] = glm::dvec4(0, 0, -30, 1);
  s.scene.AddMesh("/wall", wall, points, behind, "/wall_material");
  const char* parts[] = {"nonEye", "glint", "iris", "sclera", "limbalArc"};
  std::vector<AovBinding> bindings = {{"color", "/color"}};
  for (const char* part : parts) {
    s.scene.AddRenderBuffer(std::string("/") + part, s.size, s.size, 3);
    bindings.push_back({part, std::string("/") + part});
  }
  s.delegate.Settings().samplesPerPixel = 8;
  const RenderStats stats = s.pass.Execute("/cam", bindings);
  double totals[5] = {0, 0, 0, 0, 0}, worst = 0;
  for (int y = 0; y < s.size; ++y)
    for (int x = 0; x < s.size; ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        for (int k = 0; k < 5; ++k) {
          const double v = s.Buffer(std::string("/") + parts[k]).Resolved(x, y, c);
          sum += v, totals[k] += v;
        }
        const double color = s.Buffer("/color").Resolved(x, y, c);
        worst = std::max(worst, std::abs(sum - color) / std::max(1e-3, std::abs(color)));
      }
  std::printf(
      "eye AOVs: totals nonEye %.4f glint %.4f iris %.4f sclera %.4f limbalArc %.4f; worst |sum - color| "
      "/ color %.2g\n",
      totals[0], totals[1], totals[2], totals[3], totals[4], worst);
  CHECK(stats.nonFiniteSamples == 0);
  CHECK(worst < 1e-5);
  for (double total : totals) CHECK(total > 0);
}
