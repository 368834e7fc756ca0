// The catchlight's edge pixels (catchlightPixels.h): found where a cornea mirrors a light, sampled with reflection-only
// sub-samples that keep the image's mean, cut the glint's noise, and keep samples a pure function of their index.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace hdeye;

namespace {

constexpr int kSize = 64;
constexpr int kLarge = 1024;  // past 512 x 512: the probe's corners every 2 pixels

/// A dark analytic eye 40 mm from the camera, which it fills, under a large sphere light near the camera (its
/// reflection a few pixels across) and, if asked, a dim dome.
struct CatchlightScene : test::RenderStack {
  explicit CatchlightScene(bool sphere, bool dome = false, int size = kSize) {
    EyeParams eye;
    eye.irisColor = glm::vec3(0.1f);
    eye.scleraColor = glm::vec3(0.1f);
    scene.AddAnalyticEye("/eye", eye);
    test::AddEyeCamera(scene);
    scene.AddRenderBuffer("/color", size, size, 4);
    scene.AddRenderBuffer("/glint", size, size, 3);
    if (sphere) {
      test::AddSphereLight(scene, "/key", 6, 100, {30, 20, 110});
    }
    if (dome) {
      LightParams fill;
      fill.type = LightType::Dome;
      fill.intensity = 0.2f;
      scene.AddLight("/dome", primTypes::kDomeLight, fill);
    }
  }
  RenderStats Render(int spp, unsigned seed, int catchlightSamples, int firstSample = 0) {
    RenderSettings& settings = delegate.Settings();
    settings.samplesPerPixel = spp;
    settings.seed = seed;
    settings.catchlightSamples = catchlightSamples;
    settings.firstSample = firstSample;
    return pass.Execute("/cam", {{"color", "/color"}, {"glint", "/glint"}});
  }
  std::vector<double> Channel(const char* buffer) {
    std::vector<double> v;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) v.push_back(Buffer(buffer).Resolved(x, y, 0));
    return v;
  }
};

double Mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return sum / double(v.size());
}

}  // namespace

TEST_CASE("catchlight pixels: the edge of a light's reflection in the cornea, none for a dome or when off",
          "[render][catchlight]") {
  CatchlightScene lit(true);
  const RenderStats stats = lit.Render(1, 0, 16);
  std::printf("catchlight pixels: %lld of %d, found in %.4f s\n", (long long)stats.catchlightPixels, kSize * kSize,
              stats.catchlightSeconds);
  CHECK(stats.catchlightPixels >= 8);
  CHECK(stats.catchlightPixels < kSize * kSize / 10);
  CHECK(lit.Render(1, 0, 1).catchlightPixels == 0);
  CatchlightScene domeOnly(false, true);
  CHECK(domeOnly.Render(1, 0, 16).catchlightPixels == 0);
  // 16 times the pixels, probed every 2nd corner: the edge 16 times as long in pixels, its margin twice as wide.
  CatchlightScene large(true, false, kLarge);
  const RenderStats big = large.Render(1, 0, 16);
  std::printf("catchlight pixels at %d x %d: %lld, found in %.4f s\n", kLarge, kLarge, (long long)big.catchlightPixels,
              big.catchlightSeconds);
  CHECK(big.catchlightPixels > 8 * stats.catchlightPixels);
  CHECK(big.catchlightPixels < 64 * stats.catchlightPixels);
}

TEST_CASE("catchlight sub-samples keep the image's mean and cut the glint's edge noise", "[render][catchlight]") {
  // Four seeds with and without sub-samples at 16 spp: the image means agree within 4 standard errors of their
  // difference; the glint AOV's noise (two seeds' difference) over the image is at least 3 times lower with them.
  const int seeds = 4, spp = 16;
  struct Run {
    double mean = 0, meanSq = 0, glintNoise = 0;
  };
  auto run = [&](int catchlightSamples) {
    Run r;
    std::vector<double> first;
    for (int seed = 0; seed < seeds; ++seed) {
      CatchlightScene s(true, true);
      s.Render(spp, unsigned(seed), catchlightSamples);
      const double m = Mean(s.Channel("/color"));
      r.mean += m / seeds, r.meanSq += m * m / seeds;
      const std::vector<double> glint = s.Channel("/glint");
      if (seed == 0) first = glint;
      if (seed == 1) {
        double sq = 0;
        for (std::size_t k = 0; k < glint.size(); ++k) sq += std::pow(glint[k] - first[k], 2);
        r.glintNoise = std::sqrt(sq / (2 * double(glint.size())));
      }
    }
    return r;
  };
  const Run plain = run(1), sub = run(16);
  const auto se = [&](const Run& r) {
    return std::sqrt(std::max(0.0, r.meanSq - r.mean * r.mean) * seeds / (seeds - 1) / seeds);
  };
  const double tolerance = 4 * std::hypot(se(plain), se(sub));
  std::printf("catchlight sub-samples: image mean %.6f without, %.6f with (tolerance %.6f); glint noise %.6f -> %.6f\n",
              plain.mean, sub.mean, tolerance, plain.glintNoise, sub.glintNoise);
  CHECK(std::abs(sub.mean - plain.mean) < std::max(tolerance, 2e-3 * plain.mean));
  CHECK(sub.glintNoise * 3 < plain.glintNoise);
}

TEST_CASE("catchlight pixels' samples are a pure function of their index: two sample ranges merge exactly",
          "[render][catchlight]") {
  CatchlightScene whole(true), first(true), second(true);
  REQUIRE(whole.Render(8, 3, 16).catchlightPixels > 0);
  first.Render(4, 3, 16, 0);
  second.Render(4, 3, 16, 4);
  const std::vector<double> all = whole.Channel("/color"), a = first.Channel("/color"), b = second.Channel("/color");
  double worst = 0;
  for (std::size_t k = 0; k < all.size(); ++k)
    worst = std::max(worst, std::abs((a[k] + b[k]) / 2 - all[k]) / std::max(1e-3, all[k]));
  CHECK(worst < 1e-5);
}
