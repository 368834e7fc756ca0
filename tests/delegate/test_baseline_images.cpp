// Image regression tests: two small scenes rendered through the public flow (InMemorySceneDelegate ->
// RenderIndex -> RenderPass) and compared against committed baseline EXRs in tests/baselines/.
//
// The comparison is noise-aware, so a baseline survives a legitimate change of sampling (another seed,
// another sample order, another light-selection strategy) but not a change of the image:
//
//   relative RMSE of channel c:  e_c = sqrt( (1/N) sum_p (x_p - b_p)^2 ) / ( mean(|b|) + eps )
//   relative mean bias of c:     m_c = | (1/N) sum_p (x_p - b_p) | / ( mean(|b|) + eps )
//   block relative RMSE of c:    k_c = sqrt( (1/B) sum_blocks ( mean_{p in block} (x_p - b_p) )^2 ) / ( mean(|b|) + eps
//   )
//                                      over the B blocks of 8x8 pixels (trimmed pixels count as x_p = b_p)
//
// where x is the new render, b the baseline, eps = 1e-4 (only keeps a black channel from dividing by
// zero; every compared channel has a mean far above it), mean(|b|) is over all pixels, and the sums
// over p run over the N pixels left after dropping the ceil(0.25%) of pixels with the largest |x - b|
// (11 of 64x64, 8 of 64x48): the eye's corneal glint of the small key light covers ~1% of one pixel, so
// at 64 spp whether 0, 1 or 2 samples land on it is luck, and that one pixel alone made the untrimmed
// seed-to-seed relative RMSE of the eye's colour 1.7-2.0 (0.09 trimmed). The tolerances (above kEye)
// come from the same quantities measured between renders that differ only in their seed (the noise
// level at that spp); the hidden test "[.baseline-noise]" re-measures them and checks the margin.
// The per-pixel RMSE catches large local changes and noise blow-ups (fireflies, a sampler gone bad);
// the block RMSE, whose noise is ~1/8 of it, catches moderate regional changes (a moved highlight or
// caustic, a light moved by 10 deg); the mean bias, whose noise is ~1/sqrt(N) of the RMSE's, catches
// small global ones (a light 10% too bright). The per-pixel RMSE alone would miss both of the latter at
// these spp: a 10% brighter key moves it by less than the seed-to-seed noise.
//
// Exact checks, which no sampling change may alter:
//   - the coverage mask: which pixels' centre sample (sample 0 is the pixel centre, seed-independent)
//     hits geometry, read from the primId AOV (-1 on a miss), must be equal; alpha must lie in [0, 1],
//     and where the baseline's alpha is exactly 1 (every sample hit) the centre sample must hit, where
//     it is exactly 0 it must miss (alpha itself, averaged over jittered samples, is also a noisy channel);
//   - primId equal where both hit; normals (also from sample 0) within 1e-4 where both hit;
//   - no non-finite sample (RenderStats::nonFiniteSamples == 0).
//
// Regenerate the baselines (after an intended change of the images; review the diff first):
//   HDEYE_UPDATE_BASELINES=1 build/tests/hdeye_tests "[baseline]"
// A missing baseline fails with a message naming the file and that command.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "hdeye/scene/sampleScenes.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#ifndef HDEYE_BASELINE_DIR
#error "HDEYE_BASELINE_DIR must name tests/baselines (set in tests/CMakeLists.txt)"
#endif

using namespace hdeye;

namespace {

constexpr double kEps = 1e-4;
constexpr double kTrim = 0.0025;
constexpr int kBlock = 8;

/// Tolerances of one channel (the metrics at the top of this file).
struct Tolerance {
  double rmse, bias, block;
};

/// One render's AOV planes by EXR channel name, and its stats.
struct Image {
  int width = 0, height = 0;
  std::map<std::string, std::vector<float>> planes;
  RenderStats stats;
};

struct SceneSpec {
  const char* name;  ///< baseline file is <name>.exr
  int width, height, spp;
  /// Tolerances (see the top of this file), per compared noisy channel group.
  std::map<std::string, Tolerance> tolerance;  ///< by channel
};

/// Renders into the buffers named in `aovs` (AOV name -> components) and returns their planes, named
/// as the example writes them.
Image Render(InMemorySceneDelegate& scene, RenderDelegate& delegate, RenderIndex& index, const SceneSpec& spec,
             unsigned seed, const std::vector<std::pair<std::string, int>>& aovs) {
  std::vector<AovBinding> bindings;
  for (const auto& [aov, components] : aovs) {
    scene.AddRenderBuffer("/Render/" + aov, spec.width, spec.height, components);
    bindings.push_back({aov, "/Render/" + aov});
  }
  delegate.Settings().samplesPerPixel = spec.spp;
  delegate.Settings().seed = seed;
  delegate.Settings().threads = 1;
  RenderPass pass(&index);
  Image image;
  image.width = spec.width, image.height = spec.height;
  image.stats = pass.Execute(sampleScenes::kCamera, bindings);
  static const std::map<std::string, std::vector<std::string>> names = {
      {"color", {"R", "G", "B", "A"}},
      {"normal", {"N.X", "N.Y", "N.Z"}},
      {"primId", {"primId"}},
      {"irisMnee", {"irisMnee.R", "irisMnee.G", "irisMnee.B"}}};
  for (const auto& [aov, components] : aovs) {
    const auto planes = static_cast<const RenderBuffer*>(index.GetBprim("/Render/" + aov))->ResolvedPlanes();
    for (int c = 0; c < components; ++c) image.planes[names.at(aov)[c]] = planes[c];
  }
  return image;
}

// ---- the scenes (as delegate/examples/renderScene.cpp builds them) ----

// Tolerances: relative RMSE and block RMSE 2.5x their seed-to-seed values measured at this spp (seed
// pairs 0/1, 2/3, 4/5 and the baseline against seeds 3 and 7 agree within ~20%); relative mean bias
// ~3 sigma, sigma = (seed-to-seed relative RMSE) / sqrt(N), the standard error of a mean of N independent
// pixel differences (one seed pair is one draw of it: the largest seen was 1.3 sigma).
// Seed-to-seed (0 vs 1), relRMSE / blockRMSE / sigma:
//   eye, 64 spp:   R,G,B 0.087-0.090 / 0.011-0.012 / 0.0014;  A 0.020 / 0.0027 / 0.0003;
//                  irisMnee 0.27 / 0.030 / 0.0042
//   ball, 256 spp: R 0.048 / 0.0084 / 0.0009;  G 0.040 / 0.0063 / 0.0007;  B 0.034 / 0.0051 / 0.0006;
//                  A 0.0054 / 0.0005 / 0.0001 (re-measured after the UsdPreviewSurface specular coat: its
//                  highlights raised the block noise from 0.0041-0.0053)
// A key light 10% brighter gives relBias 0.017-0.020 (eye colour), 0.041 (irisMnee), 0.025-0.038 (ball
// colour), 4-13x these tolerances; the eye's key at 65 deg instead of 75 gives blockRMSE 0.069 (colour)
// and 0.19 (irisMnee), 2.3-2.5x.
const SceneSpec kEye{"eye_side_lit",
                     64,
                     64,
                     64,
                     {{"R", {0.22, 0.0045, 0.03}},
                      {"G", {0.22, 0.0045, 0.03}},
                      {"B", {0.22, 0.0045, 0.03}},
                      {"A", {0.05, 0.001, 0.007}},
                      {"irisMnee.R", {0.67, 0.013, 0.075}},
                      {"irisMnee.G", {0.67, 0.013, 0.075}},
                      {"irisMnee.B", {0.67, 0.013, 0.075}}}};
const SceneSpec kBall{"ball_on_floor",
                      64,
                      48,
                      256,
                      {{"R", {0.13, 0.003, 0.021}},
                       {"G", {0.10, 0.0025, 0.016}},
                       {"B", {0.09, 0.002, 0.013}},
                       {"A", {0.015, 0.0003, 0.0013}}}};

/// The side-lit eye sample scene (hdeye/scene/sampleScenes.h). AOVs: color, irisMnee, and primId for the
/// coverage mask.
Image RenderEye(unsigned seed, float keyScale = 1) {
  RenderDelegate delegate;
  RenderIndex index(&delegate);
  InMemorySceneDelegate scene(&index);
  sampleScenes::AddSideLitEye(scene, 75, keyScale);
  return Render(scene, delegate, index, kEye, seed, {{"color", 4}, {"irisMnee", 3}, {"primId", 1}});
}

/// The ball-on-a-floor sample scene. AOVs: color, normal, primId.
Image RenderBall(unsigned seed, float keyScale = 1) {
  RenderDelegate delegate;
  RenderIndex index(&delegate);
  InMemorySceneDelegate scene(&index);
  sampleScenes::AddBallOnFloor(scene, keyScale);
  return Render(scene, delegate, index, kBall, seed, {{"color", 4}, {"normal", 3}, {"primId", 1}});
}

// ---- metrics ----

struct Error {
  double rmse = 0, bias = 0, block = 0;  ///< relative, as defined at the top of this file
};

Error Compare(const std::vector<float>& x, const std::vector<float>& b, int width) {
  const std::size_t n = b.size();
  std::vector<double> d(n);
  double mean = 0;
  for (std::size_t p = 0; p < n; ++p) d[p] = double(x[p]) - b[p], mean += std::abs(double(b[p]));
  // Trim: the kTrim share of pixels with the largest |x - b| count as equal (sub-pixel glints, see the top).
  const std::size_t trim = std::size_t(std::ceil(kTrim * double(n))), keep = n - trim;
  std::vector<std::size_t> order(n);
  for (std::size_t p = 0; p < n; ++p) order[p] = p;
  std::nth_element(order.begin(), order.begin() + keep, order.end(),
                   [&](std::size_t u, std::size_t v) { return std::abs(d[u]) < std::abs(d[v]); });
  for (std::size_t k = keep; k < n; ++k) d[order[k]] = 0;
  double sq = 0, diff = 0;
  for (std::size_t p = 0; p < n; ++p) sq += d[p] * d[p], diff += d[p];
  const double denom = mean / double(n) + kEps;
  // Blocks of kBlock x kBlock pixels: the RMSE of their mean differences.
  const int height = int(n) / width, bx = width / kBlock, by = height / kBlock;
  double blockSq = 0;
  for (int j = 0; j < by; ++j)
    for (int i = 0; i < bx; ++i) {
      double sum = 0;
      for (int y = j * kBlock; y < (j + 1) * kBlock; ++y)
        for (int xx = i * kBlock; xx < (i + 1) * kBlock; ++xx) sum += d[std::size_t(y) * width + xx];
      blockSq += (sum / (kBlock * kBlock)) * (sum / (kBlock * kBlock));
    }
  return {std::sqrt(sq / double(keep)) / denom, std::abs(diff / double(keep)) / denom,
          std::sqrt(blockSq / (bx * by)) / denom};
}

std::string BaselinePath(const SceneSpec& spec) { return std::string(HDEYE_BASELINE_DIR) + "/" + spec.name + ".exr"; }

bool UpdateRequested() {
  const char* v = std::getenv("HDEYE_UPDATE_BASELINES");
  return v && std::string(v) == "1";
}

/// Writes the render as the baseline (update mode) or compares it with the committed one.
void CheckAgainstBaseline(const SceneSpec& spec, const Image& image) {
  INFO("scene " << spec.name);
  CHECK(image.stats.nonFiniteSamples == 0);
  CHECK(image.stats.passes == spec.spp);
  const std::string path = BaselinePath(spec);
  if (UpdateRequested()) {
    std::vector<ImagePlane> planes;
    for (const auto& [name, pixels] : image.planes) planes.push_back({name, pixels});
    WriteExr(path, image.width, image.height, planes);
    std::printf("[baseline] %s: HDEYE_UPDATE_BASELINES=1, wrote %s (%lld bytes)\n", spec.name, path.c_str(),
                static_cast<long long>(std::filesystem::file_size(path)));
    SUCCEED("wrote baseline " << path);
    return;
  }
  if (!std::filesystem::exists(path))
    FAIL("baseline " << path << " is missing; create it (and review it) with: HDEYE_UPDATE_BASELINES=1 "
                     << "<build>/tests/hdeye_tests \"[baseline]\"");
  int w = 0, h = 0;
  const auto read = ReadExr(path, &w, &h);
  REQUIRE(w == image.width);
  REQUIRE(h == image.height);
  std::map<std::string, std::vector<float>> base;
  for (const auto& plane : read) base[plane.name] = plane.pixels;
  for (const auto& [name, pixels] : image.planes) {
    INFO("channel " << name << " of " << path);
    REQUIRE(base.count(name) == 1);
  }
  REQUIRE(base.size() == image.planes.size());

  // Exact: coverage of the centre samples, primId where both hit, normals where both hit, alpha where
  // the baseline's alpha is exactly 0 or 1 (no sample, or every sample, hit: away from silhouettes).
  const auto& id = image.planes.at("primId");
  const auto& baseId = base.at("primId");
  const auto& alpha = image.planes.at("A");
  const auto& baseAlpha = base.at("A");
  int coverageMismatch = 0, idMismatch = 0, alphaMismatch = 0, normalMismatch = 0, hits = 0;
  double maxNormalDiff = 0;
  for (std::size_t p = 0; p < id.size(); ++p) {
    const bool hit = id[p] >= 0, baseHit = baseId[p] >= 0;
    coverageMismatch += hit != baseHit;
    if (hit && baseHit) {
      ++hits;
      idMismatch += id[p] != baseId[p];
      if (image.planes.count("N.X"))
        for (const char* c : {"N.X", "N.Y", "N.Z"}) {
          const double d = std::abs(double(image.planes.at(c)[p]) - base.at(c)[p]);
          maxNormalDiff = std::max(maxNormalDiff, d);
          normalMismatch += d > 1e-4;
        }
    }
    // Alpha exactly 1 needs the centre sample to hit; exactly 0 needs it to miss.
    if ((baseAlpha[p] == 1 && !hit) || (baseAlpha[p] == 0 && hit)) ++alphaMismatch;
    if (alpha[p] < 0 || alpha[p] > 1) ++alphaMismatch;
  }
  std::printf(
      "[baseline] %s: %d of %zu pixels covered; coverage mismatches %d, primId mismatches %d, alpha "
      "mismatches %d, normal max |diff| %.2g; non-finite samples %lld; %.2f s at %d spp\n",
      spec.name, hits, id.size(), coverageMismatch, idMismatch, alphaMismatch, maxNormalDiff,
      static_cast<long long>(image.stats.nonFiniteSamples), image.stats.seconds, image.stats.passes);
  CHECK(hits > 100);
  CHECK(coverageMismatch == 0);
  CHECK(idMismatch == 0);
  CHECK(alphaMismatch == 0);
  CHECK(normalMismatch == 0);

  // Noisy: relative RMSE and relative mean bias per channel against the measured-noise tolerances.
  for (const auto& [name, tol] : spec.tolerance) {
    const Error e = Compare(image.planes.at(name), base.at(name), image.width);
    const bool fail = e.rmse > tol.rmse || e.bias > tol.bias || e.block > tol.block;
    std::printf("[baseline] %s %-11s relRMSE %.4f (tol %.4f)  relBias %.4f (tol %.4f)  blockRMSE %.4f (tol %.4f)%s\n",
                spec.name, name.c_str(), e.rmse, tol.rmse, e.bias, tol.bias, e.block, tol.block,
                fail ? "  <-- FAIL" : "");
    INFO("channel " << name << ": relative RMSE " << e.rmse << " (tolerance " << tol.rmse << "), relative mean bias "
                    << e.bias << " (tolerance " << tol.bias << "), block relative RMSE " << e.block << " (tolerance "
                    << tol.block << ")");
    CHECK(e.rmse <= tol.rmse);
    CHECK(e.bias <= tol.bias);
    CHECK(e.block <= tol.block);
  }
}

/// The seed-to-seed noise of a scene: the same metrics between seeds 0 and 1, printed with the
/// tolerance's margin over them. Run it after changing a scene, its size or spp, and set the
/// tolerances from it (see above kEye).
void MeasureNoise(const SceneSpec& spec, const Image& a, const Image& b) {
  std::printf("[baseline noise] %s: %.2f s and %.2f s per render (one thread)\n", spec.name, a.stats.seconds,
              b.stats.seconds);
  for (const auto& [name, tol] : spec.tolerance) {
    const Error e = Compare(b.planes.at(name), a.planes.at(name), a.width);
    const double sigma = e.rmse / std::sqrt(double(a.width * a.height));  // standard error of the bias
    std::printf(
        "[baseline noise] %s %-11s seed 0 vs 1: relRMSE %.4f (tol %.4f = %.1fx)  relBias %.5f, sigma %.5f "
        "(tol %.4f = %.1f sigma)  blockRMSE %.4f (tol %.4f = %.1fx)\n",
        spec.name, name.c_str(), e.rmse, tol.rmse, tol.rmse / e.rmse, e.bias, sigma, tol.bias, tol.bias / sigma,
        e.block, tol.block, tol.block / e.block);
    CHECK(tol.rmse >= 2 * e.rmse);
    CHECK(tol.bias >= 2.5 * sigma);
    CHECK(tol.block >= 2 * e.block);
  }
}

}  // namespace

TEST_CASE("baseline image: the analytic eye lit from 75 deg (color, irisMnee, coverage)", "[baseline]") {
  CheckAgainstBaseline(kEye, RenderEye(0));
}

TEST_CASE("baseline image: the subdivided ball on a floor (color, normal, primId)", "[baseline]") {
  CheckAgainstBaseline(kBall, RenderBall(0));
}

TEST_CASE("baseline noise: seed-to-seed differences stay well inside the tolerances", "[.baseline-noise]") {
  MeasureNoise(kEye, RenderEye(0), RenderEye(1));

  MeasureNoise(kBall, RenderBall(0), RenderBall(1));
}
