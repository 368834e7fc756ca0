// Radiometry of the path tracer against closed forms, and its determinism: the same image for any
// thread count, and sample ranges that merge into the single render.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/sampleStream.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

using namespace hdeye;

namespace {

struct Scene : test::RenderStack {
  RenderStats Render(const PrimId& buffer = "/color") { return pass.Execute("/cam", {{"color", buffer}}); }
};

/// A diffuse sphere of the given albedo in a constant dome of radiance 1, filling most of the view.
void FurnaceScene(Scene& s, float albedo, int size) {
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::UvSphere(1, 24, 48, &topology, &points);
  MaterialParams m;
  m.diffuseColor = glm::vec3(albedo);
  m.ior = 1;  // no specular coat (F0 = 0): pure Lambert, the closed form below
  s.scene.AddMaterial("/mat", m);
  s.scene.AddMesh("/ball", topology, points, Matrix4d(1.0), "/mat");
  LightParams dome;
  dome.type = LightType::Dome;
  s.scene.AddLight("/dome", primTypes::kDomeLight, dome);
  s.scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(4));
  s.scene.AddRenderBuffer("/color", size, size, 4);
}

/// Mean red channel over pixels whose alpha is exactly `alpha` (1: wholly on geometry).
double MeanWhereAlpha(const RenderBuffer& b, float alpha, int* count) {
  double sum = 0;
  *count = 0;
  for (int y = 0; y < b.Height(); ++y)
    for (int x = 0; x < b.Width(); ++x)
      if (b.Resolved(x, y, 3) == alpha) sum += b.Resolved(x, y, 0), ++*count;
  return *count ? sum / *count : 0;
}

}  // namespace

TEST_CASE("furnace: a convex diffuse object in a uniform dome returns albedo times the dome ", "[render]") {
  for (float albedo : {0.5f, 1.0f}) {
    Scene s;
    FurnaceScene(s, albedo, 24);
    s.delegate.Settings().samplesPerPixel = 64;
    s.Render();
    int onObject = 0, onDome = 0;
    const double object = MeanWhereAlpha(s.Buffer("/color"), 1, &onObject);
    const double dome = MeanWhereAlpha(s.Buffer("/color"), 0, &onDome);
    std::printf("furnace albedo %.2f: object %.6f over %d pixels, dome %.4f over %d pixels\n", albedo, object, onObject,
                dome, onDome);
    REQUIRE(onObject > 50);
    REQUIRE(onDome > 50);
    CHECK(object == Approx(albedo).epsilon(0.02));
    CHECK(dome == Approx(1.0).epsilon(1e-6));
  }
}

TEST_CASE("a diffuse plane under a sphere light matches the analytic irradiance, MIS on and off ", "[render]") {
  // E = pi L (R / d)^2 below the centre of a sphere of radius R at distance d; outgoing radiance rho E / pi.
  const double R = 1, d = 5, rho = 0.5, expected = rho * (R / d) * (R / d);
  double results[2];
  for (int mis = 0; mis < 2; ++mis) {
    Scene s;
    test::AddLambertPlane(s.scene, 10, rho);  // pure Lambert: the closed form has no specular coat
    LightParams light;
    light.type = LightType::Sphere;
    light.radius = float(R);
    s.scene.AddLight("/key", primTypes::kSphereLight, light, test::LookDownZ(d));
    CameraParams ortho;
    ortho.orthographic = true;
    ortho.horizontalAperture = ortho.verticalAperture = 0.2;  // a 0.2-unit patch below the light
    s.scene.AddCamera("/cam", ortho, test::LookDownZ(2));
    s.scene.AddRenderBuffer("/color", 8, 8, 4);
    s.delegate.Settings().samplesPerPixel = 256;
    s.delegate.Settings().mis = mis == 1;
    s.Render();
    int n = 0;
    results[mis] = MeanWhereAlpha(s.Buffer("/color"), 1, &n);
    std::printf("plane under sphere light, MIS %s: %.6f (analytic %.6f)\n", mis ? "on" : "off", results[mis], expected);
    CHECK(n == 64);
    CHECK(results[mis] == Approx(expected).epsilon(0.01));
  }
  CHECK(results[0] == Approx(results[1]).epsilon(0.015));
}

TEST_CASE("the image is the same for any thread count, and sample ranges merge into the whole ", "[render]") {
  // For both samplers: each sample is a pure function of (seed, pixel, sample index, dimension).
  for (const SamplerKind sampler : {SamplerKind::ZSobol, SamplerKind::Independent}) {
    Scene s;
    FurnaceScene(s, 0.7f, 16);
    s.scene.AddRenderBuffer("/two", 16, 16, 4);
    s.scene.AddRenderBuffer("/firstHalf", 16, 16, 4);
    s.scene.AddRenderBuffer("/secondHalf", 16, 16, 4);
    RenderSettings& settings = s.delegate.Settings();
    settings.sampler = sampler;
    settings.samplesPerPixel = 8;
    settings.threads = 1;
    s.Render("/color");
    settings.threads = 2;
    s.Render("/two");
    settings.samplesPerPixel = 4;
    s.Render("/firstHalf");
    settings.firstSample = 4;
    s.Render("/secondHalf");
    s.Buffer("/firstHalf").Merge(s.Buffer("/secondHalf"));
    int identical = 0, close = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        for (int c = 0; c < 4; ++c) {
          const float whole = s.Buffer("/color").Resolved(x, y, c);
          identical += whole == s.Buffer("/two").Resolved(x, y, c);
          close += std::abs(whole - s.Buffer("/firstHalf").Resolved(x, y, c)) <= 1e-6f * (1 + std::abs(whole));
        }
    INFO((sampler == SamplerKind::ZSobol ? "zsobol" : "independent")
         << ": " << identical << " identical across thread counts, " << close << " merged values close, of 1024");
    CHECK(identical == 16 * 16 * 4);
    CHECK(close == 16 * 16 * 4);
  }
}

TEST_CASE("a render under a time limit (one pass per sample) equals one without (each pixel's samples at once)",
          "[render]") {
  // Without a time limit the renderer takes every sample of a pixel before the next pixel; with one, it makes one
  // pass over the image per sample index so that the limit stops between passes. Both add a pixel's samples in
  // sample order, so the sums and counts are the same bit for bit (a limit far beyond the render's length never
  // stops it).
  Scene s;
  FurnaceScene(s, 0.7f, 16);
  s.scene.AddRenderBuffer("/limited", 16, 16, 4);
  RenderSettings& settings = s.delegate.Settings();
  settings.samplesPerPixel = 6;
  settings.firstSample = 3;
  settings.threads = 2;
  const RenderStats whole = s.Render("/color");
  settings.timeLimitSeconds = 1e6;
  const RenderStats limited = s.Render("/limited");
  CHECK(whole.passes == 6);
  CHECK(limited.passes == 6);
  CHECK(whole.samples == limited.samples);
  CHECK(whole.rays == limited.rays);
  CHECK_FALSE(limited.timeLimitReached);
  CHECK(s.Buffer("/color").Sums() == s.Buffer("/limited").Sums());
  CHECK(s.Buffer("/color").Counts() == s.Buffer("/limited").Counts());
}

TEST_CASE("a progressive render, its passes sized by the callback's loop, equals one pass bit for bit", "[render]") {
  // The callback is called after every pass on the calling thread, with the samples done growing to the total; pass
  // sizes follow NextPassSamples (1 first, then what fits passSeconds), and the buffers match a one-pass render. With
  // a first pass in stages (stride 4, then 2, then 1: each pixel once), too.
  for (const auto& [passSeconds, stride] : {std::pair{0.0, 1}, {1e-4, 1}, {10.0, 1}, {0.0, 4}, {10.0, 3}}) {
    Scene s;
    FurnaceScene(s, 0.7f, 16);
    s.scene.AddRenderBuffer("/passes", 16, 16, 4);
    RenderSettings& settings = s.delegate.Settings();
    settings.samplesPerPixel = 9;
    settings.firstSample = 2;
    settings.threads = 2;
    const RenderStats whole = s.Render("/color");
    std::vector<int> done, sizes, strides;
    ProgressiveControl control;
    control.passSeconds = passSeconds;
    control.firstPassStride = stride;
    control.onPass = [&](const PassProgress& p) {
      if (p.stride > 1) return strides.push_back(p.stride), true;  // a stage of the first pass
      done.push_back(p.samplesDone), sizes.push_back(p.passSamples);
      return true;
    };
    const RenderStats passes = s.pass.Execute("/cam", {{"color", "/passes"}}, control);
    INFO("pass seconds " << passSeconds << ", first pass stride " << stride << ", " << done.size() << " passes");
    CHECK(strides == (stride == 4 ? std::vector<int>{4, 2} : stride == 3 ? std::vector<int>{2} : std::vector<int>{}));
    REQUIRE_FALSE(done.empty());
    CHECK(sizes.front() == 1);
    CHECK(done.back() == 9);
    CHECK(std::is_sorted(done.begin(), done.end()));
    for (std::size_t i = 1; i < sizes.size(); ++i) CHECK(sizes[i] <= 2 * sizes[i - 1]);
    if (passSeconds == 0) CHECK(done.size() == 9);   // one sample per pass
    if (passSeconds == 10) CHECK(done.size() <= 5);  // 1, 2, 4, 2 (doubling, capped by the samples left)
    CHECK(passes.passes == 9);
    CHECK_FALSE(passes.stopped);
    CHECK(passes.firstPassSeconds > 0);
    CHECK(passes.firstPassSeconds <= passes.seconds);
    CHECK(whole.rays == passes.rays);
    CHECK(s.Buffer("/color").Sums() == s.Buffer("/passes").Sums());
    CHECK(s.Buffer("/color").Counts() == s.Buffer("/passes").Counts());
  }
}

TEST_CASE("a first pass in stages renders the coarse grid's pixels first, and ends the stages before it stops",
          "[render]") {
  Scene s;
  FurnaceScene(s, 0.7f, 10);
  s.delegate.Settings().samplesPerPixel = 20;
  const std::vector<double>& counts = s.Buffer("/color").Counts();
  std::vector<std::vector<double>> seen;
  ProgressiveControl control;
  control.firstPassStride = 4;
  control.onPass = [&](const PassProgress& p) {
    seen.push_back(counts);
    return p.stride > 1;  // asks to stop at every call: honoured only once the first pass is whole
  };
  const RenderStats stats = s.pass.Execute("/cam", {{"color", "/color"}}, control);
  REQUIRE(seen.size() == 3);  // stride 4, stride 2, the whole pass
  int wrong = 0;
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      const std::size_t i = std::size_t(y * 10 + x);
      wrong += seen[0][i] != double(x % 4 == 0 && y % 4 == 0);
      wrong += seen[1][i] != double(x % 2 == 0 && y % 2 == 0);
      wrong += seen[2][i] != 1.0;
    }
  CHECK(wrong == 0);
  CHECK(stats.passes == 1);
  CHECK(stats.stopped);
  CHECK(stats.previewSeconds > 0);
  CHECK(stats.previewSeconds <= stats.firstPassSeconds);
}

TEST_CASE("a stop request or a callback saying stop ends the render after a whole pass", "[render]") {
  Scene s;
  FurnaceScene(s, 0.7f, 8);
  RenderSettings& settings = s.delegate.Settings();
  settings.samplesPerPixel = 50;
  SECTION("the callback returns false after the second pass") {
    int calls = 0;
    ProgressiveControl control;
    control.passSeconds = 0;
    control.onPass = [&](const PassProgress&) { return ++calls < 2; };
    const RenderStats stats = s.pass.Execute("/cam", {{"color", "/color"}}, control);
    CHECK(calls == 2);
    CHECK(stats.passes == 2);
    CHECK(stats.stopped);
  }
  SECTION("the stop flag, already set, lets the first pass finish and no more") {
    std::atomic<bool> stop{true};
    ProgressiveControl control;
    control.stop = &stop;
    const RenderStats stats = s.pass.Execute("/cam", {{"color", "/color"}}, control);
    CHECK(stats.passes == 1);
    CHECK(stats.stopped);
  }
  // Every pixel has the samples the passes took, no more and no less.
  const std::vector<double>& counts = s.Buffer("/color").Counts();
  CHECK(*std::min_element(counts.begin(), counts.end()) == *std::max_element(counts.begin(), counts.end()));
  CHECK(counts.front() >= 1);
}

TEST_CASE("the pass schedule starts with one sample, grows at most twofold and respects the samples and time left",
          "[render]") {
  CHECK(NextPassSamples(100, 0, 0.0, 0.25, -1) == 1);       // the first image soonest
  CHECK(NextPassSamples(100, 1, 0.001, 0.25, -1) == 2);     // 250 fit, but at most twice the last
  CHECK(NextPassSamples(100, 64, 0.001, 0.25, -1) == 100);  // capped by the samples left
  CHECK(NextPassSamples(1000, 64, 0.01, 0.25, -1) == 25);   // what fits a quarter second
  CHECK(NextPassSamples(1000, 64, 0.01, 0.25, 0.05) == 5);  // what fits before the time limit
  CHECK(NextPassSamples(1000, 64, 0.01, 0.25, 0.0) == 1);   // the limit reached: one sample
  CHECK(NextPassSamples(1000, 8, 1.0, 0.25, -1) == 1);      // a slow sample: never below one
  CHECK(NextPassSamples(0, 8, 0.01, 0.25, -1) == 0);
}

TEST_CASE("a path's random numbers do not depend on whether the camera drew its lens and time", "[render][sampler]") {
  // The camera's dimensions sit at fixed indices (SampleStream): a pinhole camera, which draws none, and a lens
  // camera with a shutter, which draws three, give the path the same numbers. For both samplers.
  for (const SamplerKind kind : {SamplerKind::ZSobol, SamplerKind::Independent}) {
    for (std::uint64_t sample : {0ull, 1ull, 77ull}) {
      SampleStream pinhole(kind, 5, 12, 34, 256, sample), lens(kind, 5, 12, 34, 256, sample);
      double jx, jy, kx, ky;
      pinhole.PixelJitter(&jx, &jy);
      lens.PixelJitter(&kx, &ky);
      const double lensU = lens.FromTop(0), lensV = lens.FromTop(1), time = lens.FromTop(2);
      CHECK(jx == kx);
      CHECK(jy == ky);
      int same = 0, distinctFromCamera = 0;
      for (int d = 0; d < 300; ++d) {
        const double a = pinhole.Next(), b = lens.Next();
        same += a == b;
        distinctFromCamera += a != lensU && a != lensV && a != time;
      }
      INFO((kind == SamplerKind::ZSobol ? "zsobol" : "independent")
           << " sample " << sample << ": " << same << " of 300 path numbers equal");
      CHECK(same == 300);
      CHECK(distinctFromCamera == 300);
    }
  }
}
