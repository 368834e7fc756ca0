// bench_motion_blur: what motion blur costs per camera sample, on a saccading analytic eye whose iris is lit through
// MNEE. An eye saccading at 400 degrees per second turns 8.3 degrees while a 180-degree shutter at 24 frames per
// second is open; the rows add what moves: nothing (a static scene under an open shutter), the eye, the key light,
// then a head-sized mesh turning with the eye (Embree instance motion) and a lid whose points move (deformation).
//
//   bench_motion_blur [--size N] [--spp N] [--repeats N] [--threads N]
//
// Prints a table of microseconds per sample (the median of the repeats) and the ratio to the sharp render.
#include "../tests/delegate/saccade_helpers.h"
#include "bench_util.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Options {
  int size = 96, spp = 16, repeats = 3, threads = 0;
};

[[noreturn]] void Usage(const char* argv0, int exitCode) {
  std::fprintf(exitCode ? stderr : stdout, "usage: %s [--size N] [--spp N] [--repeats N] [--threads N]\n", argv0);
  std::exit(exitCode);
}

/// What moves over the shutter.
struct Motion {
  const char* name;
  bool shutterOpen, eye, light, meshes;
};

Matrix4d Translate(double x, double y, double z) { return glm::translate(Matrix4d(1.0), glm::dvec3(x, y, z)); }
using test::EyeTurn;
Matrix4d KeyAt(double degrees) { return test::KeyAt(degrees, 150); }

/// A UV sphere of radius r (mm) about the origin.
void Sphere(double r, int rings, int segments, MeshTopology* topology, std::vector<Vec3f>* points) {
  points->clear();
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double th = kPi * i / rings, ph = 2 * kPi * j / segments;
      points->push_back(Vec3f(float(r * std::sin(th) * std::cos(ph)), float(r * std::sin(th) * std::sin(ph)),
                              float(r * std::cos(th))));
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      topology->faceVertexCounts.push_back(4);
      topology->faceVertexIndices.insert(topology->faceVertexIndices.end(), {a, a + segments, b + segments, b});
    }
}

/// Microseconds per sample of one render of the saccade with `motion`.
double Render(const Motion& motion, const Options& o) {
  RenderDelegate delegate;
  RenderIndex index(&delegate);
  InMemorySceneDelegate scene(&index);
  EyeParams eye;
  eye.irisColor = glm::vec3(0.5f);
  scene.AddAnalyticEye("/eye", eye);
  if (motion.eye) scene.SetTransformSamples("/eye", {-0.25f, 0.25f}, {EyeTurn(-4.15), EyeTurn(4.15)});
  LightParams key;
  key.radius = 3;
  key.intensity = 300;
  scene.AddLight("/key", primTypes::kSphereLight, key, KeyAt(60));
  if (motion.light) scene.SetTransformSamples("/key", {-0.25f, 0.25f}, {KeyAt(58), KeyAt(62)});
  LightParams dome;
  dome.intensity = 0.05f;
  scene.AddLight("/dome", primTypes::kDomeLight, dome);
  MaterialParams skin;
  skin.diffuseColor = glm::vec3(0.6f, 0.45f, 0.4f);
  scene.AddMaterial("/skin", skin);
  // A head-sized sphere behind the eye and a lid above it: meshes that move in the last row, static otherwise.
  MeshTopology head, lid;
  std::vector<Vec3f> headPoints, lidPoints;
  Sphere(80, 24, 32, &head, &headPoints);
  Sphere(14, 12, 16, &lid, &lidPoints);
  scene.AddMesh("/head", head, headPoints, Translate(0, 0, -100), "/skin");
  scene.AddMesh("/lid", lid, lidPoints, Translate(0, 13, -6), "/skin");
  if (motion.meshes) {
    scene.SetTransformSamples("/head", {-0.25f, 0.25f}, {EyeTurn(-1) * Translate(0, 0, -100), Translate(0, 0, -100)});
    std::vector<Vec3f> closing = lidPoints;
    for (Vec3f& p : closing) p.y -= 0.1f * (p.y + 14);  // the lid's lower half sags 10%: a blink starting
    scene.SetPointsSamples("/lid", {-0.25f, 0.25f}, {lidPoints, closing});
  }
  CameraParams lens;
  lens.focalLength = 100;
  lens.shutterOpen = motion.shutterOpen ? -0.25 : 0;
  lens.shutterClose = motion.shutterOpen ? 0.25 : 0;
  Matrix4d camera(1.0);
  camera[3] = glm::dvec4(0, 0, 45, 1);
  scene.AddCamera("/cam", lens, camera);
  scene.AddRenderBuffer("/color", o.size, o.size, 4);
  delegate.Settings().samplesPerPixel = o.spp;
  delegate.Settings().threads = o.threads;
  RenderPass pass(&index);
  const RenderStats stats = pass.Execute("/cam", {{"color", "/color"}});
  return 1e6 * stats.seconds / double(stats.samples);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  bench::ParseArgs(argc, argv, Usage, [&](const std::string& arg, auto value) {
    if (arg == "--size") return o.size = std::stoi(value()), true;
    if (arg == "--spp") return o.spp = std::stoi(value()), true;
    if (arg == "--repeats") return o.repeats = std::stoi(value()), true;
    if (arg == "--threads") return o.threads = std::stoi(value()), true;
    return false;
  });
  if (o.size < 1 || o.spp < 1 || o.repeats < 1) Usage(argv[0], 2);
  const Motion rows[] = {
      {"sharp (shutter closed)", false, false, false, false},
      {"static scene, shutter open", true, false, false, false},
      {"saccade (eye turns 8.3 deg)", true, true, false, false},
      {"saccade + moving key light", true, true, true, false},
      {"+ head turning, lid deforming", true, true, true, true},
  };
  std::printf("motion blur on a saccading analytic eye with MNEE: %dx%d, %d spp, median of %d\n\n", o.size, o.size,
              o.spp, o.repeats);
  // Round robin over the rows, so a load that drifts on a shared machine lands on every row alike.
  constexpr std::size_t kRows = sizeof rows / sizeof rows[0];
  std::vector<std::vector<double>> times(kRows);
  for (int r = 0; r < o.repeats; ++r)
    for (std::size_t k = 0; k < kRows; ++k) times[k].push_back(Render(rows[k], o));
  std::printf("| what moves | us / sample | vs sharp |\n|---|---|---|\n");
  const double sharp = bench::Median(times[0]);
  for (std::size_t k = 0; k < kRows; ++k) {
    const double us = bench::Median(times[k]);
    std::printf("| %s | %.2f | %.2fx |\n", rows[k].name, us, us / sharp);
  }
  return 0;
}
