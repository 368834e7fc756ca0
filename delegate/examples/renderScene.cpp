// hdeye_render_scene: builds a small scene in code and renders it through the Hydra-style flow:
// scene delegate -> render index -> render pass -> render buffers -> EXR (all AOVs) and a PNG preview.
// The default scene is an analytic eye (the paper's ellipsoid-cone anterior segment) under a side
// light, framed on the iris; --ball renders a subdivided ball on a floor instead.
//
//   hdeye_render_scene OUTPUT_PREFIX [--ball] [--light-angle DEG] [--exposure STOPS] [--spp N] [--size WxH]
//                      [--threads N]
//
// Writes OUTPUT_PREFIX.exr and OUTPUT_PREFIX.png atomically; exits 1 with a one-line message on error.
#include "hdeye/imageWriter.h"
#include "hdeye/inMemorySceneDelegate.h"
#include "hdeye/renderBuffer.h"
#include "hdeye/renderDelegate.h"
#include "hdeye/renderIndex.h"
#include "hdeye/renderPass.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>

using namespace hdeye;

namespace {

struct Options {
  std::string prefix;
  bool ball = false;
  double lightAngle = 60;  ///< degrees off the eye's gaze
  float exposure = 0;      ///< stops, for the PNG preview only
  int spp = 64, width = 320, height = 240, threads = 0;
};

Options Parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
      return argv[++i];
    };
    if (a == "--spp") o.spp = std::stoi(next());
    else if (a == "--ball") o.ball = true;
    else if (a == "--light-angle") o.lightAngle = std::stod(next());
    else if (a == "--exposure") o.exposure = std::stof(next());
    else if (a == "--threads") o.threads = std::stoi(next());
    else if (a == "--size") {
      const std::string s = next();
      const auto x = s.find('x');
      if (x == std::string::npos) throw std::runtime_error("--size wants WxH, got " + s);
      o.width = std::stoi(s.substr(0, x)), o.height = std::stoi(s.substr(x + 1));
    } else if (!a.empty() && a[0] == '-') throw std::runtime_error("unknown option " + a);
    else o.prefix = a;
  }
  if (o.prefix.empty())
    throw std::runtime_error("usage: hdeye_render_scene OUTPUT_PREFIX [--ball] [--light-angle DEG] [--exposure STOPS] [--spp N] [--size WxH] [--threads N]");
  if (o.spp < 1 || o.width < 1 || o.height < 1) throw std::runtime_error("--spp and --size must be positive");
  return o;
}

Matrix4d Translate(double x, double y, double z) {
  Matrix4d m(1.0);
  m[3] = glm::dvec4(x, y, z, 1);
  return m;
}

void AddBuffers(InMemorySceneDelegate& scene, const Options& o) {
  for (const auto& [id, components] : {std::pair{"/Render/color", 4}, {"/Render/albedo", 3}, {"/Render/normal", 3},
                                       {"/Render/depth", 1}, {"/Render/primId", 1}, {"/Render/irisMnee", 3}})
    scene.AddRenderBuffer(id, o.width, o.height, components);
}

/// An analytic eye in millimetres, gazing at the camera, with a small key light `lightAngle` off its
/// gaze towards +x and a dim dome.
void BuildEyeScene(InMemorySceneDelegate& scene, const Options& o) {
  EyeParams eye;
  eye.irisColor = {0.35f, 0.22f, 0.12f};
  scene.AddAnalyticEye("/World/eye", eye);
  LightParams key;
  key.type = LightType::Sphere;
  key.radius = 3;
  key.intensity = 300;
  const double a = o.lightAngle * 3.14159265358979323846 / 180;
  scene.AddLight("/World/key", primTypes::kSphereLight, key, Translate(150 * std::sin(a), 0, 150 * std::cos(a)));
  LightParams sky;
  sky.type = LightType::Dome;
  sky.intensity = 0.05f;
  scene.AddLight("/World/sky", primTypes::kDomeLight, sky);
  CameraParams lens;
  lens.focalLength = 100;
  scene.AddCamera("/World/cam", lens, Translate(0, 0, 45));
  AddBuffers(scene, o);
}

void BuildBallScene(InMemorySceneDelegate& scene, const Options& o) {
  // A cube refined twice by OpenSubdiv: a rounded ball.
  MeshTopology cube{{4, 4, 4, 4, 4, 4}, {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3}, 3};
  const std::vector<Vec3f> corners = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                      {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  MaterialParams red, grey;
  red.diffuseColor = {0.7f, 0.15f, 0.1f};
  grey.diffuseColor = {0.5f, 0.5f, 0.5f};
  scene.AddMaterial("/Looks/red", red);
  scene.AddMaterial("/Looks/grey", grey);
  scene.AddMesh("/World/ball", cube, corners, Translate(0, 0, 1), "/Looks/red");
  MeshTopology floor{{4}, {0, 1, 2, 3}, 0};
  scene.AddMesh("/World/floor", floor, {{-8, -8, 0}, {8, -8, 0}, {8, 8, 0}, {-8, 8, 0}}, Matrix4d(1.0), "/Looks/grey");

  LightParams key;
  key.type = LightType::Sphere;
  key.radius = 0.5f;
  key.intensity = 30;
  scene.AddLight("/World/key", primTypes::kSphereLight, key, Translate(2, -2, 4));
  LightParams sky;
  sky.type = LightType::Dome;
  sky.color = {0.6f, 0.7f, 0.9f};
  sky.intensity = 0.3f;
  scene.AddLight("/World/sky", primTypes::kDomeLight, sky);

  // Camera at (0, -7, 3) looking at (0, 0, 1): rotate the default -z view down onto the scene.
  const glm::dvec3 eye(0, -7, 3), target(0, 0, 1), up(0, 0, 1);
  const glm::dvec3 back = glm::normalize(eye - target), right = glm::normalize(glm::cross(up, back));
  Matrix4d cam(1.0);
  cam[0] = glm::dvec4(right, 0);
  cam[1] = glm::dvec4(glm::cross(back, right), 0);
  cam[2] = glm::dvec4(back, 0);
  cam[3] = glm::dvec4(eye, 1);
  scene.AddCamera("/World/cam", CameraParams{}, cam);
  AddBuffers(scene, o);
}

void WriteOutputs(const RenderIndex& index, const Options& o) {
  auto buffer = [&](const char* id) { return static_cast<const RenderBuffer*>(index.GetBprim(id))->ResolvedPlanes(); };
  const auto color = buffer("/Render/color"), albedo = buffer("/Render/albedo"), normal = buffer("/Render/normal");
  const auto depth = buffer("/Render/depth"), primId = buffer("/Render/primId"), iris = buffer("/Render/irisMnee");
  WriteExr(o.prefix + ".exr", o.width, o.height,
           {{"R", color[0]}, {"G", color[1]}, {"B", color[2]}, {"A", color[3]}, {"albedo.R", albedo[0]},
            {"albedo.G", albedo[1]}, {"albedo.B", albedo[2]}, {"N.X", normal[0]}, {"N.Y", normal[1]},
            {"N.Z", normal[2]}, {"depth.Z", depth[0]}, {"primId", primId[0]}, {"irisMnee.R", iris[0]},
            {"irisMnee.G", iris[1]}, {"irisMnee.B", iris[2]}});
  std::vector<float> rgb(std::size_t(o.width) * o.height * 3);
  for (std::size_t p = 0; p < rgb.size() / 3; ++p)
    for (int c = 0; c < 3; ++c) rgb[3 * p + c] = color[c][p];
  WritePngPreview(o.prefix + ".png", o.width, o.height, rgb, o.exposure);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = Parse(argc, argv);
    RenderDelegate delegate;
    RenderIndex index(&delegate);
    InMemorySceneDelegate scene(&index);
    if (o.ball) BuildBallScene(scene, o);
    else BuildEyeScene(scene, o);
    delegate.Settings().samplesPerPixel = o.spp;
    delegate.Settings().threads = o.threads;
    RenderPass pass(&index);
    const RenderStats stats = pass.Execute("/World/cam", {{"color", "/Render/color"}, {"albedo", "/Render/albedo"},
                                                          {"normal", "/Render/normal"}, {"depth", "/Render/depth"},
                                                          {"primId", "/Render/primId"}, {"irisMnee", "/Render/irisMnee"}});
    WriteOutputs(index, o);
    std::printf("rendered %dx%d at %d spp in %.2f s (%.2f Mrays/s); wrote %s.exr and %s.png\n", o.width, o.height,
                stats.passes, stats.seconds, stats.rays / stats.seconds * 1e-6, o.prefix.c_str(), o.prefix.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hdeye_render_scene: %s\n", e.what());
    return 1;
  }
}
