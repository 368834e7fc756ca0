// hdeye_render_scene: builds a small scene in code and renders it through the Hydra-style flow:
// scene delegate -> render index -> render pass -> render buffers -> EXR (all AOVs) and a PNG preview.
// The default scene is an analytic eye (the paper's ellipsoid-cone anterior segment) under a side
// light, framed on the iris; --ball renders a subdivided ball on a floor instead.
//
//   hdeye_render_scene OUTPUT_PREFIX [--ball] [--light-angle DEG] [--exposure STOPS] [--spp N] [--size WxH]
//                      [--threads N] [--seed N]
//
// Writes OUTPUT_PREFIX.exr and OUTPUT_PREFIX.png atomically; exits 1 with a one-line message on error.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "hdeye/scene/sampleScenes.h"

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
  unsigned seed = 0;  ///< the sampler's (two seeds give two independent images, for noise estimates)
};

Options Parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
      return argv[++i];
    };
    if (a == "--spp")
      o.spp = std::stoi(next());
    else if (a == "--ball")
      o.ball = true;
    else if (a == "--light-angle")
      o.lightAngle = std::stod(next());
    else if (a == "--exposure")
      o.exposure = std::stof(next());
    else if (a == "--threads")
      o.threads = std::stoi(next());
    else if (a == "--seed")
      o.seed = unsigned(std::stoul(next()));
    else if (a == "--size") {
      const std::string s = next();
      const auto x = s.find('x');
      if (x == std::string::npos) throw std::runtime_error("--size wants WxH, got " + s);
      o.width = std::stoi(s.substr(0, x)), o.height = std::stoi(s.substr(x + 1));
    } else if (!a.empty() && a[0] == '-')
      throw std::runtime_error("unknown option " + a);
    else
      o.prefix = a;
  }
  if (o.prefix.empty())
    throw std::runtime_error(
        "usage: hdeye_render_scene OUTPUT_PREFIX [--ball] [--light-angle DEG] [--exposure STOPS] [--spp N] [--size "
        "WxH] [--threads N] [--seed N]");
  if (o.spp < 1 || o.width < 1 || o.height < 1) throw std::runtime_error("--spp and --size must be positive");
  return o;
}

void AddBuffers(InMemorySceneDelegate& scene, const Options& o) {
  for (const auto& [id, components] : {std::pair{"/Render/color", 4},
                                       {"/Render/albedo", 3},
                                       {"/Render/normal", 3},
                                       {"/Render/depth", 1},
                                       {"/Render/primId", 1},
                                       {"/Render/irisMnee", 3}})
    scene.AddRenderBuffer(id, o.width, o.height, components);
}

void WriteOutputs(const RenderIndex& index, const Options& o) {
  auto buffer = [&](const char* id) { return static_cast<const RenderBuffer*>(index.GetBprim(id))->ResolvedPlanes(); };
  const auto color = buffer("/Render/color"), albedo = buffer("/Render/albedo"), normal = buffer("/Render/normal");
  const auto depth = buffer("/Render/depth"), primId = buffer("/Render/primId"), iris = buffer("/Render/irisMnee");
  WriteExr(o.prefix + ".exr", o.width, o.height,
           {{"R", color[0]},
            {"G", color[1]},
            {"B", color[2]},
            {"A", color[3]},
            {"albedo.R", albedo[0]},
            {"albedo.G", albedo[1]},
            {"albedo.B", albedo[2]},
            {"N.X", normal[0]},
            {"N.Y", normal[1]},
            {"N.Z", normal[2]},
            {"depth.Z", depth[0]},
            {"primId", primId[0]},
            {"irisMnee.R", iris[0]},
            {"irisMnee.G", iris[1]},
            {"irisMnee.B", iris[2]}});
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
    if (o.ball)
      sampleScenes::AddBallOnFloor(scene);
    else
      sampleScenes::AddSideLitEye(scene, o.lightAngle);
    AddBuffers(scene, o);
    delegate.Settings().samplesPerPixel = o.spp;
    delegate.Settings().threads = o.threads;
    delegate.Settings().seed = o.seed;
    RenderPass pass(&index);
    const RenderStats stats = pass.Execute(sampleScenes::kCamera, {{"color", "/Render/color"},
                                                                   {"albedo", "/Render/albedo"},
                                                                   {"normal", "/Render/normal"},
                                                                   {"depth", "/Render/depth"},
                                                                   {"primId", "/Render/primId"},
                                                                   {"irisMnee", "/Render/irisMnee"}});
    WriteOutputs(index, o);
    std::printf("rendered %dx%d at %d spp in %.2f s (%.2f Mrays/s); wrote %s.exr and %s.png\n", o.width, o.height,
                stats.passes, stats.seconds, stats.rays / stats.seconds * 1e-6, o.prefix.c_str(), o.prefix.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hdeye_render_scene: %s\n", e.what());
    return 1;
  }
}
