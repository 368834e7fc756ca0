// Eyes on meshes: a subdivided eyeball whose front follows the analytic cornea, rendered against the
// analytic eye; its sclera; a rotated, centimetre-scaled copy; rays that start inside it.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/eyeMesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <eyelib/anterior_surface.h>
#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>

using namespace hdeye;

namespace {

/// An eye (analytic, or on a mesh) at the origin gazing at a camera 40 mm away that it fills, lit by a
/// small sphere light 30 degrees off the gaze; everything in one frame `frame` (world = frame * canonical,
/// a similarity: the camera and light are placed through it too, the light's radius scaled with it).
struct EyeScene : test::RenderStack {
  int size;

  EyeScene(int size, const Matrix4d& frame = Matrix4d(1.0)) : size(size) {
    const double scale = std::cbrt(glm::determinant(glm::dmat3(frame)));
    Matrix4d rotation = frame;
    for (int c = 0; c < 3; ++c) rotation[c] /= scale;
    CameraParams lens;
    lens.focalLength = 100;
    Matrix4d camera = rotation;
    camera[3] = frame * glm::dvec4(0, 0, 40, 1);
    scene.AddCamera("/cam", lens, camera);
    test::AddSphereLight(scene, "/key", float(2 * scale), 400,
                         glm::dvec3(frame * glm::dvec4(100 * std::sin(0.5), 0, 100 * std::cos(0.5), 1)));
    for (const char* b : {"/color", "/iris", "/albedo"}) scene.AddRenderBuffer(b, size, size, b[1] == 'c' ? 4 : 3);
  }
  /// Swaps the key light for a constant dome of radiance 1 (a white furnace).
  void LightByDome() {
    scene.RemovePrim("/key");
    LightParams dome;
    dome.type = LightType::Dome;
    scene.AddLight("/dome", primTypes::kDomeLight, dome);
  }
  RenderStats Render(int spp, unsigned seed = 0) {
    delegate.Settings().samplesPerPixel = spp;
    delegate.Settings().seed = seed;
    for (const char* b : {"/color", "/iris", "/albedo"}) Buffer(b).Clear();
    return pass.Execute("/cam", {{"color", "/color"}, {"irisMnee", "/iris"}, {"albedo", "/albedo"}});
  }
  /// The light MNEE brought to the iris (red channel), per pixel.
  std::vector<double> IrisImage() {
    std::vector<double> image;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) image.push_back(Buffer("/iris").Resolved(x, y, 0));
    return image;
  }
  /// Mean over the image of the light MNEE brought to the iris (red channel).
  double MeanIris() {
    double sum = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) sum += Buffer("/iris").Resolved(x, y, 0);
    return sum / (size * size);
  }
};

double Rmse(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum / double(a.size()));
}

EyeParams GreyIris() {
  EyeParams eye;
  eye.irisColor = glm::vec3(0.5f);
  return eye;
}

}  // namespace

TEST_CASE("an eye mesh whose front follows the analytic cornea renders the iris as the analytic eye does", "[render]") {
  const int size = 32, spp = 24;
  EyeScene analytic(size);
  analytic.scene.AddAnalyticEye("/eye", GreyIris());
  const RenderStats a0 = analytic.Render(spp, 0);
  const double iris0 = analytic.MeanIris();
  const std::vector<double> image0 = analytic.IrisImage();
  analytic.Render(spp, 1);
  const double iris1 = analytic.MeanIris();
  const double noiseRmse = Rmse(image0, analytic.IrisImage());

  EyeScene mesh(size);
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::EyeballMesh(48, 24, 48, 2, &topology, &points);
  mesh.scene.AddEyeMesh("/eye", topology, points, GreyIris());
  const RenderStats m0 = mesh.Render(spp, 0);
  const double irisMesh = mesh.MeanIris();
  // Per pixel too, so the iris must also be where the analytic eye shows it: the image differs from
  // the analytic one (same seed) by no more than one analytic image differs from another seed's.
  const double meshRmse = Rmse(image0, mesh.IrisImage());
  std::printf("eye mesh vs analytic eye per pixel: RMSE %.5f (analytic seed 0 vs 1: %.5f)\n", meshRmse, noiseRmse);
  CHECK(meshRmse < noiseRmse);

  // Noise-aware: the tolerance is four times the seed-to-seed difference of the analytic eye, plus 2%
  // for what legitimately differs (the mesh's limit surface is within microns of the analytic one, not
  // on it, and its sclera reflects a little light into the cornea that the analytic eye has no sclera for).
  const double noise = std::abs(iris0 - iris1);
  const double tolerance = 4 * noise + 0.02 * iris0;
  std::printf(
      "eye mesh vs analytic eye: mean iris MNEE light %.5f vs %.5f (seed 1: %.5f; noise %.5f, tol %.5f); "
      "%.2f s vs %.2f s\n",
      irisMesh, iris0, iris1, noise, tolerance, m0.seconds, a0.seconds);
  CHECK(a0.nonFiniteSamples == 0);
  CHECK(m0.nonFiniteSamples == 0);
  CHECK(iris0 > 0);
  CHECK(std::abs(irisMesh - iris0) < tolerance);
}

TEST_CASE("eye mesh sclera shades as sclera: scleraColor, or the bound material's colour", "[render]") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::EyeballMesh(24, 12, 24, 1, &topology, &points);
  // Seen from 40 mm the image spans +-7.2 mm; pixels beyond the outer limbus (6.45 mm) but on the ball
  // are sclera. Under a white dome the convex sclera returns its albedo (a Lambertian furnace).
  for (bool material : {false, true}) {
    EyeScene s(24);
    s.LightByDome();
    EyeParams eye = GreyIris();
    eye.scleraColor = glm::vec3(0.8f, 0.6f, 0.4f);
    MaterialParams m;
    m.diffuseColor = glm::vec3(0.3f, 0.5f, 0.7f);
    if (material) s.scene.AddMaterial("/scleraMaterial", m);
    s.scene.AddEyeMesh("/eye", topology, points, eye, Matrix4d(1.0), material ? "/scleraMaterial" : "");
    // The Lambertian sclera (the random-walk sclera's furnace is in test_limbal_arc.cpp).
    s.delegate.Settings().eyeSwitches.scleraScattering = false;
    const RenderStats stats = s.Render(64);
    const glm::dvec3 expected = material ? glm::dvec3(m.diffuseColor) : glm::dvec3(eye.scleraColor);
    glm::dvec3 sum(0), albedoWorst(0);
    int n = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        // Image corners: radius > 6.45 mm from the axis, inside the 7.54 mm rim's silhouette or beyond.
        const double px = (x + 0.5 - 12) * 0.6, py = (y + 0.5 - 12) * 0.6;
        if (std::hypot(px, py) < 6.8 || s.Buffer("/color").Resolved(x, y, 3) != 1) continue;
        const glm::dvec3 c(s.Buffer("/color").Resolved(x, y, 0), s.Buffer("/color").Resolved(x, y, 1),
                           s.Buffer("/color").Resolved(x, y, 2));
        const glm::dvec3 a(s.Buffer("/albedo").Resolved(x, y, 0), s.Buffer("/albedo").Resolved(x, y, 1),
                           s.Buffer("/albedo").Resolved(x, y, 2));
        sum += c, ++n;
        albedoWorst = glm::max(albedoWorst, glm::abs(a - expected));
      }
    const glm::dvec3 mean = sum / double(n);
    std::printf("eye mesh sclera (%s): %d pixels, mean radiance (%.4f %.4f %.4f) vs albedo (%.2f %.2f %.2f)\n",
                material ? "bound material" : "scleraColor", n, mean.x, mean.y, mean.z, expected.x, expected.y,
                expected.z);
    CHECK(stats.nonFiniteSamples == 0);
    REQUIRE(n > 20);
    CHECK(albedoWorst.x < 1e-6);
    CHECK(albedoWorst.z < 1e-6);
    for (int c = 0; c < 3; ++c) CHECK(mean[c] == Approx(expected[c]).epsilon(0.03));
  }
}

TEST_CASE("a rotated eye mesh in a centimetre scene renders as the same eye in millimetres", "[render]") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::EyeballMesh(32, 16, 32, 1, &topology, &points);
  const int size = 24, spp = 24;

  EyeScene mm(size);
  mm.scene.AddEyeMesh("/eye", topology, points, GreyIris());
  const RenderStats s0 = mm.Render(spp, 0);
  const double irisMm = mm.MeanIris();
  mm.Render(spp, 1);
  const double irisMmSeed1 = mm.MeanIris();

  // The eye's model transform: canonical mm -> the prim's local cm, turned 40 degrees about x; the prim
  // turned 70 degrees about y and moved. The mesh's points are authored in the prim's local space.
  EyeParams eye = GreyIris();
  eye.modelTransform =
      glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(1, 0, 0)) * glm::scale(glm::dmat4(1.0), glm::dvec3(0.1));
  const Matrix4d prim =
      glm::translate(glm::dmat4(1.0), glm::dvec3(3, -2, 5)) * glm::rotate(glm::dmat4(1.0), 1.2, glm::dvec3(0, 1, 0));
  std::vector<Vec3f> local;
  for (const Vec3f& p : points) local.push_back(Vec3f(eye.modelTransform * glm::dvec4(p, 1)));
  EyeScene cm(size, prim * eye.modelTransform);
  cm.scene.AddEyeMesh("/eye", topology, local, eye, prim);
  const RenderStats s1 = cm.Render(spp, 0);
  const double irisCm = cm.MeanIris();

  const double noise = std::abs(irisMm - irisMmSeed1), tolerance = 4 * noise + 0.01 * irisMm;
  std::printf("eye mesh in cm, rotated: mean iris light %.5f vs %.5f in mm (noise %.5f, tol %.5f)\n", irisCm, irisMm,
              noise, tolerance);
  CHECK(s0.nonFiniteSamples == 0);
  CHECK(s1.nonFiniteSamples == 0);
  CHECK(irisMm > 0);
  CHECK(std::abs(irisCm - irisMm) < tolerance);
}

TEST_CASE("an eye mesh is invisible from inside: rays leaving the cornea do not re-enter it") {
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::EyeballMesh(24, 12, 24, 1, &topology, &points);
  // Turned 2.5 rad about y, so a filter that mixed world directions with object-space normals would
  // get every answer backwards (Embree hands instanced filters object-space rays).
  const Matrix4d prim = glm::rotate(glm::dmat4(1.0), 2.5, glm::dvec3(0, 1, 0));
  EyeScene s(8, prim);
  s.scene.AddEyeMesh("/eye", topology, points, GreyIris(), prim);
  s.Render(1);
  RTCScene root = s.delegate.RootScene();
  // Closest hits and shadow rays, from the eyeball's centre outwards (inside) and from outside inwards.
  auto cast = [&](glm::dvec3 o, glm::dvec3 d, bool occluded) {
    o = glm::dvec3(prim * glm::dvec4(o, 1)), d = glm::dvec3(prim * glm::dvec4(d, 0));
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = test::UnboundedRayHit(o, d);
    if (occluded) {
      rtcOccluded1(root, &context, &rh.ray);
      return rh.ray.tfar < 0;
    }
    rtcIntersect1(root, &context, &rh);
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  };
  for (bool occluded : {false, true}) {
    INFO((occluded ? "shadow rays" : "closest-hit rays"));
    // Just under the cornea (an analytic exit point inside an inflated mesh) and from the centre.
    CHECK_FALSE(cast({0, 0, -0.05}, {0, 0, 1}, occluded));
    CHECK_FALSE(cast({1, 0.5, -0.3}, glm::normalize(glm::dvec3(0.3, 0.2, 1)), occluded));
    CHECK_FALSE(cast({0, 0, -13}, glm::normalize(glm::dvec3(1, 1, 0.2)), occluded));
    CHECK(cast({0, 0, 20}, {0, 0, -1}, occluded));
    CHECK(cast({30, 0, -13}, {-1, 0, 0}, occluded));
  }
}

TEST_CASE("an inflated eye mesh still lets the iris see its light: exits and MNEE shadow rays pass its inside",
          "[render]") {
  // The mesh 2% larger than the eyeball: its front lies about 0.26 mm outside the analytic cornea, so
  // every path leaving the analytic cornea, and every MNEE shadow ray from the iris, starts inside the
  // mesh. Were the mesh opaque from inside the iris would go dark; were the re-hit shaded as an entry,
  // the light would be refracted in again and the iris would change. Its rest positions are the fitted
  // eyeball's, so hits map to the same canonical points as on the fitted mesh.
  const int size = 24, spp = 24;
  MeshTopology topology;
  std::vector<Vec3f> points, inflated;
  const glm::dvec3 centre(0, 0, test::EyeballMesh(32, 16, 32, 1, &topology, &points));
  for (const Vec3f& p : points) inflated.push_back(Vec3f(centre + 1.02 * (glm::dvec3(p) - centre)));
  EyeScene exact(size), puffy(size);
  exact.scene.AddEyeMesh("/eye", topology, points, GreyIris());
  puffy.scene.AddEyeMesh("/eye", topology, inflated, GreyIris());
  std::vector<float> rest;
  for (const Vec3f& p : points) rest.insert(rest.end(), {p.x, p.y, p.z});
  puffy.scene.SetPrimvar("/eye", "rest", Primvar{Interpolation::Vertex, 3, rest});
  const RenderStats se = exact.Render(spp, 0);
  const double irisExact = exact.MeanIris();
  exact.Render(spp, 1);
  const double noise = std::abs(exact.MeanIris() - irisExact);
  const RenderStats sp = puffy.Render(spp, 0);
  const double irisPuffy = puffy.MeanIris();
  // The rest pose defines the mapping: a hit on the inflated mesh maps to the rest point 2% nearer the
  // eyeball's centre, so the cornea (and the iris seen through it) is magnified by 2% in radius, and
  // its area, which the mean iris light follows, by 1.02^2.
  const double expected = 1.02 * 1.02 * irisExact, tolerance = 4 * noise + 0.02 * irisExact;
  std::printf(
      "inflated eye mesh: mean iris light %.5f vs %.5f expected (1.02^2 x the fitted mesh's %.5f; noise %.5f, "
      "tol %.5f)\n",
      irisPuffy, expected, irisExact, noise, tolerance);
  CHECK(se.nonFiniteSamples == 0);
  CHECK(sp.nonFiniteSamples == 0);
  CHECK(irisExact > 0);
  CHECK(std::abs(irisPuffy - expected) < tolerance);
}

TEST_CASE("eye mesh furnace: a closed white eye mesh in a uniform dome returns the dome", "[render]") {
  // Energy through the mesh door: the mapping, the rotation onto the analytic normal, the walk, the
  // exits that start inside the mesh and pass through it.
  EyeParams white;
  white.chamber.pupilDiameter = 0;
  white.irisColor = glm::vec3(1);
  white.scleraColor = glm::vec3(1);
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::EyeballMesh(32, 16, 32, 1, &topology, &points);
  EyeScene s(20);
  s.LightByDome();
  s.scene.AddEyeMesh("/eye", topology, points, white);
  s.delegate.Settings().maxDepth = 16;
  s.delegate.Settings().eyeSwitches.mneeAllSolutions = true;
  // A Lambertian sclera of albedo 1 conserves exactly; the random walk's albedo-1 medium absorbs a little
  // (single-scattering albedo 0.9989: 0.9857 here), audited in test_limbal_arc.cpp.
  s.delegate.Settings().eyeSwitches.scleraScattering = false;
  const RenderStats stats = s.Render(128);
  double sum = 0;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) sum += s.Buffer("/color").Resolved(x, y, 0);
  const double mean = sum / 400;
  std::printf("eye mesh furnace: mean %.4f over 400 pixels (%.1f s)\n", mean, stats.seconds);
  CHECK(stats.nonFiniteSamples == 0);
  // As the analytic eye furnace (1.0001 with all MNEE solutions), plus the smooth-normal Lambert
  // furnace's +0.4% on the sclera pixels.
  CHECK(mean == Approx(1.0).epsilon(0.01));
}

TEST_CASE("the iris texture, tinted by irisColor, u along +x over the 15.08 mm disk", "[render]") {
  const std::string flat = "/tmp/hdeye_test_iris_flat.exr", split = "/tmp/hdeye_test_iris_split.exr";
  WriteExr(
      flat, 2, 2,
      {{"R", std::vector<float>(4, 0.5f)}, {"G", std::vector<float>(4, 0.5f)}, {"B", std::vector<float>(4, 0.5f)}});
  // Left half (u < 0.5, canonical x < 0) red, right half blue.
  std::vector<float> r(64 * 8), g(64 * 8, 0.0f), b(64 * 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 64; ++x) r[y * 64 + x] = x < 32 ? 1.0f : 0.0f, b[y * 64 + x] = x < 32 ? 0.0f : 1.0f;
  WriteExr(split, 64, 8, {{"R", r}, {"G", g}, {"B", b}});

  MeshTopology topology;
  std::vector<Vec3f> points;
  test::EyeballMesh(24, 12, 24, 1, &topology, &points);
  for (bool onMesh : {false, true}) {
    INFO((onMesh ? "eye mesh" : "analytic eye"));
    auto add = [&](EyeScene& s, const EyeParams& e) {
      if (onMesh)
        s.scene.AddEyeMesh("/eye", topology, points, e);
      else
        s.scene.AddAnalyticEye("/eye", e);
    };
    // A flat 0.5 texture under a white irisColor renders exactly as irisColor 0.5 (same seed: the same
    // paths, the same numbers).
    EyeScene colour(16), textured(16);
    add(colour, GreyIris());
    EyeParams withTexture = GreyIris();
    withTexture.irisColor = glm::vec3(1);  // the multiplier
    withTexture.irisTexture = flat;
    add(textured, withTexture);
    colour.Render(4);
    textured.Render(4);
    CHECK(colour.IrisImage() == textured.IrisImage());

    EyeScene halves(16);
    withTexture.irisTexture = split;
    add(halves, withTexture);
    CHECK(halves.Render(8).nonFiniteSamples == 0);
    glm::dvec3 left(0), right(0);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const glm::dvec3 c(halves.Buffer("/iris").Resolved(x, y, 0), halves.Buffer("/iris").Resolved(x, y, 1),
                           halves.Buffer("/iris").Resolved(x, y, 2));
        (x < 8 ? left : right) += c;
      }
    std::printf("split iris texture (%s): left half R %.4f B %.4f, right half R %.4f B %.4f\n",
                onMesh ? "eye mesh" : "analytic eye", left.x, left.z, right.x, right.z);
    CHECK(left.x > 10 * left.z);
    CHECK(right.z > 10 * right.x);
    CHECK(left.y == 0);
  }
  // A missing file is one warning naming the eye and the file; the iris renders magenta (no green).
  EyeScene missing(16);
  EyeParams e = GreyIris();
  e.irisColor = glm::vec3(1);
  e.irisTexture = "/tmp/hdeye_no_such_iris.exr";
  missing.scene.AddEyeMesh("/eye", topology, points, e);
  CHECK_NOTHROW(missing.Render(4));
  const std::vector<std::string> warnings = missing.delegate.GetRenderParam()->Warnings();
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("/eye") && Catch::Contains("hdeye_no_such_iris.exr"));
  glm::dvec3 iris(0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) iris[c] += missing.Buffer("/iris").Resolved(x, y, c);
  std::printf("iris of a missing texture: R %.4f G %.4f B %.4f\n", iris.x, iris.y, iris.z);
  CHECK(iris.x > 0);
  CHECK(iris.y == 0);
  CHECK(iris.z > 0);
}

TEST_CASE("an eye mesh's corneal glint is the analytic eye's, Fresnel-weighted at every camera sample",
          "[render][glint]") {
  // Black iris and sclera: the glint is the key's reflection off the cornea (the 17 x 17 pixels around the brightest;
  // the mesh's limbus shows a few faint others). The mesh eye's reflection leaves from the mesh point (the baseline
  // mapping), the analytic eye's from the analytic cornea; both split the Fresnel choice at the camera's cornea vertex,
  // so at 16 spp the glint already agrees to a few per cent (a coin toss by F would put the key's full radiance in
  // about 1 sample in 40).
  EyeParams black = GreyIris();
  black.irisColor = glm::vec3(0);
  black.scleraColor = glm::vec3(0);
  const int size = 64, spp = 16;
  const double glint = std::pow((1.376 - 1) / (1.376 + 1), 2) * 40;  // F L at near-normal incidence
  auto glintTotal = [&](bool mesh) {
    EyeScene s(size);
    s.scene.RemovePrim("/key");  // a large key, its reflection many pixels wide
    test::AddSphereLight(s.scene, "/key", 20, 40, {100 * std::sin(0.3), 0, 100 * std::cos(0.3)});
    if (mesh) {
      MeshTopology topology;
      std::vector<Vec3f> points;
      test::EyeballMesh(48, 24, 48, 2, &topology, &points);
      s.scene.AddEyeMesh("/eye", topology, points, black);
    } else {
      s.scene.AddAnalyticEye("/eye", black);
    }
    s.Render(spp);
    const RenderBuffer& color = s.Buffer("/color");
    int bx = 0, by = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        if (color.Resolved(x, y, 0) > color.Resolved(bx, by, 0)) bx = x, by = y;
    double total = 0;
    int lit = 0;
    for (int y = std::max(0, by - 8); y < std::min(size, by + 9); ++y)
      for (int x = std::max(0, bx - 8); x < std::min(size, bx + 9); ++x) total += color.Resolved(x, y, 0), ++lit;
    return std::make_tuple(total, lit, color.Resolved(bx, by, 0));
  };
  const auto [analytic, analyticPixels, analyticPeak] = glintTotal(false);
  const auto [mesh, meshPixels, meshPeak] = glintTotal(true);
  std::printf(
      "corneal glint at %d spp: analytic eye %.4f over %d pixels (peak %.4f), eye mesh %.4f (peak %.4f); F L %.4f\n",
      spp, analytic, analyticPixels, analyticPeak, mesh, meshPeak, glint);
  CHECK(analytic > 10 * glint);
  CHECK(mesh == Approx(analytic).epsilon(0.02));  // the edge pixels differ by their coverage noise
  // Inside the reflection every sample brings F L: the peak pixel is F L (the coin toss: 0 or L / spp).
  CHECK(meshPeak == Approx(glint).epsilon(0.02));
  CHECK(analyticPeak == Approx(glint).epsilon(0.02));
}
