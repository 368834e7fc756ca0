// Deformed, animated eyes on meshes: the re-projection of hits through the iris projection from
// rest-pose positions (eyeMeshMapping.h), against the undeformed eye and against the affine-frame
// baseline; the mapping's invariants; degenerate and inverted deformations; tiny and huge eyes; a
// projection that does not cover the hits. Numbers in docs/deformed_eyes.md.
#include "deformed_eye_helpers.h"
#include "hdeye/prims/eyeMesh.h"
#include "hdeye/render/eyeMeshMapping.h"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <random>

using namespace hdeye;
using test::DeformedEyeScene;
using test::Eyeball;

namespace {

using Deformation = std::function<glm::dvec3(const glm::dvec3&)>;

EyeParams UvIris() {
  EyeParams eye;
  eye.irisColor = glm::vec3(1);
  eye.irisTexture = test::UvIrisTexture();
  return eye;
}

/// A deformation case: the mesh's points, its prim transform, and the camera that frames its iris
/// (distance along the gaze from the undeformed apex, sideways offset), so the iris fills the image.
struct Case {
  const char* name;
  Deformation deform;       ///< object space (canonical mm), applied to the points; rest = undeformed
  Matrix4d transform{1.0};  ///< the prim transform (non-uniform scale lives here)
  double distance = 42.3;   ///< mm; 42.3 frames the undeformed iris at 1.1x its radius
  glm::dvec2 offset{0};     ///< mm
};

std::vector<Case> Cases(double zc) {
  const glm::dvec3 c(0, 0, zc);
  const eyelib::AnteriorSurface<double> cornea;
  const glm::dvec3 bump(3, 0, cornea.Sag(3));
  // Camera distances: the deformed iris plane's z plus 1.1 x its half-width / 0.18 (the lens's half field).
  return {
      {"stretch 2x along the gaze (1/sqrt2 across)",
       [=](const glm::dvec3& p) { return c + glm::dvec3(0.7071, 0.7071, 2.0) * (p - c); }, Matrix4d(1.0), 38.2},
      {"squash 0.5x along the gaze (sqrt2 across)",
       [=](const glm::dvec3& p) { return c + glm::dvec3(1.4142, 1.4142, 0.5) * (p - c); }, Matrix4d(1.0), 56.7},
      {"shear x += 0.5 (z - centre)", [=](const glm::dvec3& p) { return p + glm::dvec3(0.5 * (p.z - zc), 0, 0); },
       Matrix4d(1.0), 42.3, glm::dvec2(0.5 * (-3.735 - zc), 0)},
      {"local bulge 1.5 mm at r = 3 mm",
       [=](const glm::dvec3& p) {
         const double w = 1.5 * std::exp(-glm::dot(p - bump, p - bump) / (2 * 2.5 * 2.5));
         return p + w * glm::normalize(p - c);
       },
       Matrix4d(1.0), 42.3},
      {"non-uniform scale (1.6, 1, 1) in the prim transform", [](const glm::dvec3& p) { return p; },
       glm::scale(Matrix4d(1.0), glm::dvec3(1.6, 1, 1)), 70},
  };
}

struct Rendered {
  test::IrisMap map{12};
  RenderStats stats;
  std::vector<float> rgb;
  int coverage = 0;
};

Rendered RenderEye(const Eyeball& ball, const std::vector<Vec3f>& points, const Matrix4d& transform, double distance,
                   bool reprojection, bool withRest, unsigned seed, int size, int spp, EyeParams eye = UvIris(),
                   glm::dvec2 offset = glm::dvec2(0), SamplerKind sampler = SamplerKind::ZSobol) {
  DeformedEyeScene s(size, distance, Matrix4d(1.0), offset);
  s.delegate.Settings().sampler = sampler;
  eye.reprojection = reprojection;
  s.scene.AddEyeMesh("/eye", ball.topology, points, eye, transform);
  if (withRest) s.scene.SetPrimvar("/eye", "rest", ball.Rest());
  Rendered out;
  out.stats = s.Render(spp, seed);
  out.map = test::ReadIris(s, 12);
  out.rgb = s.CausticRgb();
  out.coverage = s.Coverage();
  return out;
}

/// Where previews go when HDEYE_DEFORMED_EYE_PNG is set (docs/deformed_eyes.md's contact sheet).
void MaybeWritePng(const std::string& name, int size, const std::vector<float>& rgb) {
  const char* dir = std::getenv("HDEYE_DEFORMED_EYE_PNG");
  if (dir && *dir) WritePngPreview(std::string(dir) + "/" + name + ".png", size, size, rgb, 1);
}

std::string Slug(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == ' ') break;
    out += ch == '-' ? '_' : ch;
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// The mapping itself (no rendering).

TEST_CASE("re-projection keeps the angle to the local normal and maps leaving rays back by the same rotation",
          "[deformed]") {
  // A level-1 eyeball sheared and squashed; the mapping of many random hits and directions.
  Eyeball ball(24, 12, 24, 1);
  const double zc = ball.zCentre;
  const auto deformed = ball.Deformed(
      [&](const glm::dvec3& p) { return glm::dvec3(1.3 * p.x + 0.4 * (p.z - zc), 0.9 * p.y, zc + 0.6 * (p.z - zc)); });
  RenderDelegate delegate;
  RenderIndex index{&delegate};
  InMemorySceneDelegate scene{&index};
  scene.AddEyeMesh("/eye", ball.topology, deformed, EyeParams());
  scene.SetPrimvar("/eye", "rest", ball.Rest());
  index.SyncAll();
  auto* mesh = static_cast<EyeMesh*>(index.GetRprim("/eye"));
  const GeometryContext& ctx = *mesh->Context();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(0, 1);
  int onCornea = 0;
  double worstAngle = 0, worstRoundTrip = 0;
  for (int k = 0; k < 20000; ++k) {
    const unsigned tri = unsigned(uni(rng) * mesh->TriangleCount()) % unsigned(mesh->TriangleCount());
    double u = uni(rng), v = uni(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const glm::dvec3 d = glm::normalize(glm::dvec3(uni(rng) - 0.5, uni(rng) - 0.5, -uni(rng)));
    const EyeMeshHit hit = EyeMeshHitToCanonical(ctx, mesh->Eye(), tri, u, v, d);
    REQUIRE(std::isfinite(hit.canonicalDir.x + hit.canonicalDir.y + hit.canonicalDir.z));
    if (!hit.onCornea || !hit.fromOutside) continue;
    ++onCornea;
    // The deformed shading normal at the hit, world (the mesh's transform is the identity).
    const int* t = &(*ctx.triangleVertices)[3 * tri];
    const glm::dvec3 ns =
        glm::normalize((1 - u - v) * glm::dvec3((*ctx.vertexNormals)[t[0]]) +
                       u * glm::dvec3((*ctx.vertexNormals)[t[1]]) + v * glm::dvec3((*ctx.vertexNormals)[t[2]]));
    const double cosWorld = glm::dot(d, ns), cosCanonical = glm::dot(hit.canonicalDir, hit.analyticNormal);
    if (cosWorld < -1e-3) worstAngle = std::max(worstAngle, std::abs(std::acos(cosWorld) - std::acos(cosCanonical)));
    // A leaving ray: the canonical reflection maps back to the world reflection about the shading normal.
    const glm::dvec3 reflectedCanonical =
        hit.canonicalDir - 2 * glm::dot(hit.canonicalDir, hit.analyticNormal) * hit.analyticNormal;
    const glm::dvec3 back = EyeMeshLeavingDirection(hit, reflectedCanonical);
    const glm::dvec3 reflectedWorld = d - 2 * glm::dot(d, ns) * ns;
    if (cosWorld < -1e-3 && glm::dot(reflectedWorld, hit.worldNormal) > 1e-3)
      worstRoundTrip = std::max(worstRoundTrip, glm::length(back - reflectedWorld));
  }
  std::printf(
      "re-projection invariants over %d cornea hits: worst |angle to normal change| %.2e rad, worst reflection "
      "round trip %.2e\n",
      onCornea, worstAngle, worstRoundTrip);
  CHECK(onCornea > 1000);
  CHECK(worstAngle < 1e-6);
  CHECK(worstRoundTrip < 1e-6);
}

TEST_CASE("on an undeformed eye the re-projection is the rigid mapping, and the default projection is the model frame",
          "[deformed]") {
  // The eye rotated and in centimetres: the local rotation must reduce to the rigid one (a fine mesh's
  // normals are within a fraction of a degree of the analytic ones), and an explicit irisProjection equal
  // to modelTransform x scale(7.54) must map exactly as the default.
  Eyeball ball(48, 24, 48, 2);
  EyeParams eye;
  eye.modelTransform =
      glm::rotate(Matrix4d(1.0), 0.7, glm::dvec3(1, 0, 0)) * glm::scale(Matrix4d(1.0), glm::dvec3(0.1));
  const Matrix4d prim =
      glm::translate(Matrix4d(1.0), glm::dvec3(3, -2, 5)) * glm::rotate(Matrix4d(1.0), 1.2, glm::dvec3(0, 1, 0));
  std::vector<Vec3f> local;
  for (const Vec3f& p : ball.points) local.push_back(Vec3f(eye.modelTransform * glm::dvec4(p, 1)));
  EyeParams explicitFrame = eye;
  explicitFrame.irisProjection = eye.modelTransform * glm::scale(Matrix4d(1.0), glm::dvec3(15.08 / 2));
  explicitFrame.hasIrisProjection = true;
  RenderDelegate delegate;
  RenderIndex index{&delegate};
  InMemorySceneDelegate scene{&index};
  scene.AddEyeMesh("/a", ball.topology, local, eye, prim);
  scene.AddEyeMesh("/b", ball.topology, local, explicitFrame, prim);
  index.SyncAll();
  auto* a = static_cast<EyeMesh*>(index.GetRprim("/a"));
  auto* b = static_cast<EyeMesh*>(index.GetRprim("/b"));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(0, 1);
  double worstDir = 0, worstPoint = 0;
  int n = 0;
  for (int k = 0; k < 5000; ++k) {
    const unsigned tri = unsigned(uni(rng) * a->TriangleCount()) % unsigned(a->TriangleCount());
    const double u = 0.3 * uni(rng), v = 0.3 * uni(rng);
    const glm::dvec3 d = a->Eye().DirToWorld(glm::normalize(glm::dvec3(uni(rng) - 0.5, uni(rng) - 0.5, -1)));
    const EyeMeshHit ha = EyeMeshHitToCanonical(*a->Context(), a->Eye(), tri, u, v, d);
    const EyeMeshHit hb = EyeMeshHitToCanonical(*b->Context(), b->Eye(), tri, u, v, d);
    worstPoint = std::max(worstPoint, glm::length(ha.canonicalPoint - hb.canonicalPoint));
    if (!ha.onCornea || !ha.fromOutside) continue;
    ++n;
    worstDir = std::max(worstDir, glm::length(ha.canonicalDir - a->Eye().DirToCanonical(d)));
  }
  std::printf(
      "undeformed eye: re-projected vs rigid direction worst %.2e (%d hits); default vs explicit projection "
      "worst %.2e mm\n",
      worstDir, n, worstPoint);
  CHECK(n > 500);
  // The limit normals depart from the analytic ones by up to 0.6 degrees (0.0107 measured), worst where
  // the limit surface rounds the cornea-sclera kink near the rim; the rotation follows them, as it should.
  CHECK(worstDir < 0.02);
  CHECK(worstPoint < 1e-9);
}

// ---------------------------------------------------------------------------------------------------------
// The measured demonstration: the caustic read back in iris texture space.

TEST_CASE("re-projected deformed eyes keep the undeformed iris caustic, and the affine-frame baseline departs",
          "[render][deformed]") {
  const int size = 64, spp = 16;
  Eyeball ball(32, 16, 32, 1);
  const auto cases = Cases(ball.zCentre);
  // The noise model below (one seed pair gives each render's noise) needs noise independent from sample to sample:
  // with the stratified sampler, MNEE's heavy tails near the folds made one seed pair in about 15 read 3-4 times
  // noisier than the others (measured over seeds 0-21 at 16 and 32 spp), which one pair cannot tell from a change.
  const SamplerKind independent = SamplerKind::Independent;
  // The undeformed eye, framed alike, at two seeds (the noise); rendered once for every section.
  static const Rendered ref0 =
      RenderEye(ball, ball.points, Matrix4d(1.0), 42.3, true, false, 0, size, spp, UvIris(), {}, independent);
  static const Rendered ref1 =
      RenderEye(ball, ball.points, Matrix4d(1.0), 42.3, true, false, 1, size, spp, UvIris(), {}, independent);
  // One case per section keeps each under the test budget; Catch runs the test case once per section.
  for (const Case& c : cases) {
    SECTION(c.name) {
      const auto points = ball.Deformed(c.deform);
      const Rendered on =
          RenderEye(ball, points, c.transform, c.distance, true, true, 0, size, spp, UvIris(), c.offset, independent);
      const Rendered off =
          RenderEye(ball, points, c.transform, c.distance, false, true, 0, size, spp, UvIris(), c.offset, independent);
      const Rendered on1 =
          RenderEye(ball, points, c.transform, c.distance, true, true, 1, size, spp, UvIris(), c.offset, independent);
      // Noise-aware: relRms(a, b) of two independent renders of the same caustic is sqrt(s_a^2 + s_b^2)
      // (s: one render's relative noise per bin). Seed pairs give sqrt(2) s_ref and sqrt(2) s_on; what
      // noise alone would make of |on - ref| is sqrt((n_ref^2 + n_on^2) / 2).
      const double nRef = test::Compare(ref1.map, ref0.map).relativeRms,
                   nOn = test::Compare(on1.map, on.map).relativeRms;
      const double expected = std::sqrt((nRef * nRef + nOn * nOn) / 2);
      const test::CausticDifference dOn = test::Compare(on.map, ref0.map);
      const test::CausticDifference dOff = test::Compare(off.map, ref0.map);
      // The outer iris (to 5.8 mm), seen through the cornea near the limbus: reported, not claimed.
      const double outerOn = test::Compare(on.map, ref0.map, 2.6, 5.8).relativeRms;
      const double outerNoise = test::Compare(ref1.map, ref0.map, 2.6, 5.8).relativeRms;
      std::printf(
          "%-52s noise-only %.3f (ref %.3f, deformed %.3f) | to 5.8 mm: re-projection %.3f, seeds %.3f | re-projection "
          "%.3f (centroid %.2f mm, %d bins) | baseline %.3f (centroid "
          "%.2f mm, %d bins) | %.2f s\n",
          c.name, expected, nRef, nOn, outerOn, outerNoise, dOn.relativeRms, dOn.centroidShift, dOn.bins,
          dOff.relativeRms, dOff.centroidShift, dOff.bins, on.stats.seconds);
      MaybeWritePng("undeformed", size, ref0.rgb);
      MaybeWritePng(Slug(c.name) + "_reprojection", size, on.rgb);
      MaybeWritePng(Slug(c.name) + "_baseline", size, off.rgb);
      CHECK(on.stats.nonFiniteSamples == 0);
      CHECK(off.stats.nonFiniteSamples == 0);
      REQUIRE(dOn.bins >= 12);
      // Re-projection: within 1.5x what noise alone gives, plus 0.05 for what the view legitimately
      // changes (the entry Fresnel follows the deformed surface's angles; pixels straddling a bin edge
      // average differently under another magnification: 0.04 for the squash at 64 spp, with the chamber cache
      // and the control variate alike).
      CHECK(dOn.relativeRms < 1.5 * expected + 0.05);
      // The baseline: wherever the fitted deformation is not a similarity, its pulled-back light direction
      // moves the caustic, well past the noise and the re-projection. (A local bulge barely moves the fit: no claim
      // there.)
      if (std::string(c.name).find("bulge") == std::string::npos)
        CHECK(dOff.relativeRms > std::max(2 * expected, 2 * dOn.relativeRms));
    }
  }
}

// ---------------------------------------------------------------------------------------------------------
// Robustness.

TEST_CASE("degenerate and inverted deformations render without NaN or holes", "[render][deformed]") {
  Eyeball ball(24, 12, 24, 1);
  const double zc = ball.zCentre;
  const int size = 32, spp = 4;
  const Rendered ref = RenderEye(ball, ball.points, Matrix4d(1.0), 70, true, false, 0, size, spp);
  struct Bad {
    const char* name;
    Deformation deform;
    bool sameSilhouette;  ///< covers the undeformed eye's pixels exactly (seen along the gaze)
  };
  const std::vector<Bad> bad = {
      // Flattened to a 1e-6 thin disk along the gaze: front and back coincide, normals turn +-z.
      {"flattened along the gaze", [&](const glm::dvec3& p) { return glm::dvec3(p.x, p.y, zc + 1e-6 * (p.z - zc)); },
       true},
      // A mirror: the mesh inside out relative to its rest pose (its winding normals point in).
      {"mirrored (inside out)", [&](const glm::dvec3& p) { return glm::dvec3(-p.x, p.y, p.z); }, true},
      // A cap of the cornea collapsed onto one point: zero-area triangles around it.
      {"cornea cap collapsed to a point",
       [&](const glm::dvec3& p) { return std::hypot(p.x, p.y) < 2.5 && p.z > -1 ? glm::dvec3(0, 0, 0) : p; }, false},
      // Folded: the front pushed through the back (the front half reflected through the centre plane).
      {"front folded through the centre",
       [&](const glm::dvec3& p) { return p.z > zc ? glm::dvec3(p.x, p.y, 2 * zc - p.z) : p; }, false},
  };
  for (const Bad& b : bad) {
    INFO(b.name);
    const Rendered r = RenderEye(ball, ball.Deformed(b.deform), Matrix4d(1.0), 70, true, true, 0, size, spp);
    double iris = 0;
    iris = r.map.Total();
    std::printf("%-36s coverage %d px (undeformed %d), non-finite %d, iris light sum %.3f\n", b.name, r.coverage,
                ref.coverage, int(r.stats.nonFiniteSamples), iris);
    CHECK(r.stats.nonFiniteSamples == 0);
    if (b.sameSilhouette)
      CHECK(std::abs(r.coverage - ref.coverage) <= ref.coverage / 50);
    else
      CHECK(r.coverage > ref.coverage / 2);
  }
}

TEST_CASE("eyes of 1 mm and of 1 km render the same caustic as the 24 mm eye", "[render][deformed]") {
  // The eyeball is 24 mm across; scale 1/24 makes it 1 mm, 1e6/24 makes it 1 km (world units are mm).
  // Camera and lights scale with it (the same picture), and the eye is stretched 1.5x along its gaze so
  // the re-projection's local frames are exercised at every scale.
  Eyeball ball(24, 12, 24, 1);
  const double zc = ball.zCentre;
  const auto stretched = ball.Deformed([&](const glm::dvec3& p) {
    return glm::dvec3(0, 0, zc) + glm::dvec3(0.8165, 0.8165, 1.5) * (p - glm::dvec3(0, 0, zc));
  });
  const int size = 40, spp = 8;
  std::map<double, double> mean;
  std::map<double, int> coverage;
  double noise = 0;
  for (double scale : {1.0, 1.0 / 24, 1e6 / 24}) {
    const Matrix4d frame = glm::scale(Matrix4d(1.0), glm::dvec3(scale));
    DeformedEyeScene s(size, 70, frame);
    EyeParams eye;
    eye.irisColor = glm::vec3(0.5f);
    eye.modelTransform = frame;
    std::vector<Vec3f> local;
    for (const Vec3f& p : stretched) local.push_back(Vec3f(frame * glm::dvec4(p, 1)));
    std::vector<float> rest;
    for (const Vec3f& p : ball.points) {
      const glm::dvec3 q(frame * glm::dvec4(p, 1));
      rest.insert(rest.end(), {float(q.x), float(q.y), float(q.z)});
    }
    s.scene.AddEyeMesh("/eye", ball.topology, local, eye);
    s.scene.SetPrimvar("/eye", "rest", Primvar{Interpolation::Vertex, 3, rest});
    const RenderStats st = s.Render(spp, 0);
    double sum = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) sum += s.Buffer("/iris").Resolved(x, y, 0);
    mean[scale] = sum / (size * size);
    coverage[scale] = s.Coverage();
    CHECK(st.nonFiniteSamples == 0);
    if (scale == 1.0) {
      s.Render(spp, 1);
      double sum1 = 0;
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) sum1 += s.Buffer("/iris").Resolved(x, y, 0);
      noise = std::abs(sum1 / (size * size) - mean[scale]);
    }
  }
  std::printf(
      "stretched eye at 24 mm / 1 mm / 1 km: mean iris light %.5f / %.5f / %.5f (seed noise %.5f); coverage "
      "%d / %d / %d px\n",
      mean[1.0], mean[1.0 / 24], mean[1e6 / 24], noise, coverage[1.0], coverage[1.0 / 24], coverage[1e6 / 24]);
  const double tolerance = 4 * noise + 0.02 * mean[1.0];
  CHECK(mean[1.0] > 0);
  CHECK(std::abs(mean[1.0 / 24] - mean[1.0]) < tolerance);
  CHECK(std::abs(mean[1e6 / 24] - mean[1.0]) < tolerance);
  CHECK(std::abs(coverage[1.0 / 24] - coverage[1.0]) <= 8);
  CHECK(std::abs(coverage[1e6 / 24] - coverage[1.0]) <= 8);
}

TEST_CASE("an iris projection that does not cover the hits shades them as sclera: no NaN, no holes",
          "[render][deformed]") {
  Eyeball ball(24, 12, 24, 1);
  const int size = 32, spp = 4;
  const Rendered ref = RenderEye(ball, ball.points, Matrix4d(1.0), 70, true, false, 0, size, spp);
  double refIris = 0;
  refIris = ref.map.Total();
  struct Frame {
    const char* name;
    Matrix4d projection;
    bool irisExpected;
  };
  const double half = 15.08 / 2;
  const std::vector<Frame> frames = {
      // Shifted 20 mm sideways: every hit projects past the rim.
      {"shifted off the eye",
       glm::translate(Matrix4d(1.0), glm::dvec3(20, 0, 0)) * glm::scale(Matrix4d(1.0), glm::dvec3(half)), false},
      // Projecting along x: the front maps to a band; most of it past the rim, the rest cornea.
      {"turned 90 degrees (projecting along x)",
       glm::rotate(Matrix4d(1.0), test::kEyePi / 2, glm::dvec3(0, 1, 0)) * glm::scale(Matrix4d(1.0), glm::dvec3(half)),
       true},
      // A frame 4x too small: only the central quarter of the eye projects inside the limbus; the rest
      // is sclera. Less iris light, no holes.
      {"4x too small", glm::scale(Matrix4d(1.0), glm::dvec3(0.25 * half)), false},
  };
  for (const Frame& f : frames) {
    INFO(f.name);
    EyeParams eye = UvIris();
    eye.irisProjection = f.projection;
    eye.hasIrisProjection = true;
    const Rendered r = RenderEye(ball, ball.points, Matrix4d(1.0), 70, true, false, 0, size, spp, eye);
    double iris = 0;
    iris = r.map.Total();
    std::printf("projection %-40s coverage %d px (reference %d), iris light %.3f (reference %.3f)\n", f.name,
                r.coverage, ref.coverage, iris, refIris);
    CHECK(r.stats.nonFiniteSamples == 0);
    CHECK(r.coverage == ref.coverage);  // sclera or cornea, every pixel of the eye is shaded
    if (!f.irisExpected) CHECK(iris < 0.5 * refIris);
  }
  // A singular projection is an error naming the eye.
  EyeParams singular;
  singular.irisProjection = glm::scale(Matrix4d(1.0), glm::dvec3(1, 1, 0));
  singular.hasIrisProjection = true;
  DeformedEyeScene s(4, 70);
  s.scene.AddEyeMesh("/eye", ball.topology, ball.points, singular);
  CHECK_THROWS_WITH(s.Render(1), Catch::Contains("/eye") && Catch::Contains("irisProjection"));
}

TEST_CASE("an animated eye mesh refines once and re-evaluates stencils per frame, and the eye frames follow",
          "[deformed]") {
  // Frame after frame of squash and stretch through SetPoints: DirtyPoints only. Topology is refined
  // once; each frame costs one stencil evaluation and one Embree upload; the mapping sees the new pose.
  Eyeball ball(24, 12, 24, 2);
  const double zc = ball.zCentre;
  RenderDelegate delegate;
  RenderIndex index{&delegate};
  InMemorySceneDelegate scene{&index};
  EyeParams baseline;
  baseline.reprojection = false;
  scene.AddEyeMesh("/eye", ball.topology, ball.points, baseline);
  scene.SetPrimvar("/eye", "rest", ball.Rest());
  index.SyncAll();
  auto* mesh = static_cast<EyeMesh*>(index.GetRprim("/eye"));
  for (int frame = 1; frame <= 6; ++frame) {
    const double s = 1 + 0.1 * frame;
    scene.SetPoints("/eye", ball.Deformed([&](const glm::dvec3& p) {
      return glm::dvec3(0, 0, zc) + glm::dvec3(1 / std::sqrt(s), 1 / std::sqrt(s), s) * (p - glm::dvec3(0, 0, zc));
    }));
    index.SyncAll();
    // The baseline's affine frame is the fitted deformation: its z scale is s.
    const double fitted = glm::length(glm::dvec3(mesh->Eye().canonicalToWorld[2]));
    CHECK(fitted == Approx(s).epsilon(1e-4));
  }
  const MeshSyncStats& st = mesh->Stats();
  std::printf("6 animated frames: refinements %d, stencil evaluations %d, uploads %d, topology builds %d\n",
              st.refinements, st.stencilEvaluations, st.pointUploads, st.topologyBuilds);
  CHECK(st.refinements == 1);
  CHECK(st.topologyBuilds == 1);
  CHECK(st.stencilEvaluations == 7);
  CHECK(st.pointUploads == 7);
}

TEST_CASE("deformed eye furnace: a white, stretched and sheared eye mesh in a uniform dome returns the dome",
          "[render][deformed]") {
  // Energy through the re-projection: per-hit rotations, exits from the deformed hit point bent above its
  // tangent plane, the walk in the rigid frame. Closed white eye (pupil 0, iris and sclera albedo 1).
  Eyeball ball(32, 16, 32, 1);
  const double zc = ball.zCentre;
  const auto deformed = ball.Deformed([&](const glm::dvec3& p) {
    return glm::dvec3(0, 0, zc) + glm::dvec3(0.8 * (p.x + 0.3 * (p.z - zc)), 0.8 * p.y, 1.5 * (p.z - zc));
  });
  for (bool reprojection : {true, false}) {
    INFO((reprojection ? "re-projection" : "baseline"));
    DeformedEyeScene s(20, 60);
    s.scene.RemovePrim("/key");
    LightParams dome;
    dome.type = LightType::Dome;
    s.scene.AddLight("/dome", primTypes::kDomeLight, dome);
    EyeParams white;
    white.chamber.pupilDiameter = 0;
    white.irisColor = glm::vec3(1);
    white.scleraColor = glm::vec3(1);
    white.reprojection = reprojection;
    s.scene.AddEyeMesh("/eye", ball.topology, deformed, white);
    s.scene.SetPrimvar("/eye", "rest", ball.Rest());
    s.delegate.Settings().maxDepth = 16;
    s.delegate.Settings().eyeSwitches.mneeAllSolutions = true;
    const RenderStats stats = s.Render(96);
    double sum = 0;
    int n = 0;
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x)
        if (s.Buffer("/color").Resolved(x, y, 3) > 0.999) sum += s.Buffer("/color").Resolved(x, y, 0), ++n;
    const double mean = sum / n;
    std::printf("deformed eye furnace (%s): mean %.4f over %d eye pixels (%.1f s)\n",
                reprojection ? "re-projection" : "baseline", mean, n, stats.seconds);
    CHECK(stats.nonFiniteSamples == 0);
    REQUIRE(n > 100);
    // Re-projection: as the undeformed eye-mesh furnace (1.0008), 1.5% for the smooth-normal Lambert sclera
    // and the noise. The baseline is not held to it: MNEE converts its per-mm^2 transfer to world area with
    // the affine frame's mean scale, which a non-uniform frame gets wrong (measured 0.937 here).
    if (reprojection) CHECK(mean == Approx(1.0).epsilon(0.015));
  }
}
