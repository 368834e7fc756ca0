// Deformed, animated eyes on meshes: what an animated frame costs against a full rebuild, and what
// re-projecting a hit costs (docs/deformed_eyes.md). Prints markdown tables.
//
//   bench_deformed_eye [--frames N] [--hits N]
//
// 1. Per-frame update of an animated eye mesh (the procedural eyeball of the tests, squash-and-stretch
//    poses) at Catmull-Clark levels 1-3: SetPoints + RenderIndex::SyncAll + root commit (stencil evaluation
//    of limit points and normals, Embree vertex upload and BVH refit, the eye frames) against a full
//    rebuild of the same mesh (SetTopology: refinement, stencil tables, new Embree geometry and BVH).
// 2. Per-hit cost of the mapping (EyeMeshHitToCanonical) with re-projection and with the affine-frame
//    baseline, on random hits of a deformed eye, single thread; and a whole render with each, for scale.
#include "bench_util.h"
#include "hdeye/prims/eyeMesh.h"
#include "hdeye/render/eyeMeshMapping.h"

#include "../tests/delegate/deformed_eye_helpers.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace hdeye;
using Clock = std::chrono::steady_clock;

namespace {

using bench::Median;

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::vector<Vec3f> Pose(const test::Eyeball& ball, double s) {
  const glm::dvec3 c(0, 0, ball.zCentre);
  const double across = 1 / std::sqrt(s);
  return ball.Deformed([&](const glm::dvec3& p) { return c + glm::dvec3(across, across, s) * (p - c); });
}

void UpdateCost(int frames) {
  std::printf("## 1. Per-frame update vs full rebuild (eyeball 48 rings x 48 segments, medians of %d frames)\n\n",
              frames);
  std::printf(
      "| level | triangles | frame update (ms) | stencil evals / frame | full rebuild (ms) | refinements / rebuild | "
      "rebuild / update |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int level = 1; level <= 3; ++level) {
    test::Eyeball ball(48, 24, 48, level);
    RenderDelegate delegate;
    RenderIndex index{&delegate};
    InMemorySceneDelegate scene{&index};
    scene.AddEyeMesh("/eye", ball.topology, ball.points, EyeParams());
    scene.SetPrimvar("/eye", "rest", ball.Rest());
    index.SyncAll();
    rtcCommitScene(delegate.RootScene());
    auto* mesh = static_cast<EyeMesh*>(index.GetRprim("/eye"));
    std::vector<double> update, rebuild;
    const int evals0 = mesh->Stats().stencilEvaluations;
    for (int f = 0; f < frames; ++f) {
      const auto pose = Pose(ball, 1 + 0.5 * std::sin(0.3 * f));
      const auto t0 = Clock::now();
      scene.SetPoints("/eye", pose);
      index.SyncAll();
      rtcCommitScene(delegate.RootScene());
      update.push_back(Seconds(t0, Clock::now()));
    }
    const double evalsPerFrame = double(mesh->Stats().stencilEvaluations - evals0) / frames;
    const int refinements0 = mesh->Stats().refinements;
    for (int f = 0; f < std::max(3, frames / 4); ++f) {
      const auto pose = Pose(ball, 1 + 0.5 * std::sin(0.3 * f));
      const auto t0 = Clock::now();
      scene.SetTopology("/eye", ball.topology, pose);
      index.SyncAll();
      rtcCommitScene(delegate.RootScene());
      rebuild.push_back(Seconds(t0, Clock::now()));
    }
    const double refinementsPerRebuild = double(mesh->Stats().refinements - refinements0) / rebuild.size();
    std::printf("| %d | %d | %.3f | %.1f | %.3f | %.1f | %.1fx |\n", level, mesh->TriangleCount(), 1e3 * Median(update),
                evalsPerFrame, 1e3 * Median(rebuild), refinementsPerRebuild, Median(rebuild) / Median(update));
  }
  std::printf("\n");
}

void HitCost(int hits) {
  std::printf(
      "## 2. Per-hit cost of the mapping (single thread, %d random hits on a sheared, squashed level-2 eye)\n\n", hits);
  test::Eyeball ball(48, 24, 48, 2);
  const double zc = ball.zCentre;
  const auto deformed = ball.Deformed(
      [&](const glm::dvec3& p) { return glm::dvec3(1.3 * p.x + 0.4 * (p.z - zc), 0.9 * p.y, zc + 0.6 * (p.z - zc)); });
  std::printf("| mapping | ns / hit | cornea hits |\n|---|---|---|\n");
  double nsOn = 0, nsOff = 0;
  for (bool reprojection : {true, false}) {
    RenderDelegate delegate;
    RenderIndex index{&delegate};
    InMemorySceneDelegate scene{&index};
    EyeParams eye;
    eye.reprojection = reprojection;
    scene.AddEyeMesh("/eye", ball.topology, deformed, eye);
    scene.SetPrimvar("/eye", "rest", ball.Rest());
    index.SyncAll();
    auto* mesh = static_cast<EyeMesh*>(index.GetRprim("/eye"));
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> uni(0, 1);
    struct Query {
      unsigned tri;
      double u, v;
      glm::dvec3 d;
    };
    std::vector<Query> queries(hits);
    for (Query& q : queries) {
      q.tri = unsigned(uni(rng) * mesh->TriangleCount()) % unsigned(mesh->TriangleCount());
      q.u = 0.5 * uni(rng), q.v = 0.5 * uni(rng);
      q.d = glm::normalize(glm::dvec3(uni(rng) - 0.5, uni(rng) - 0.5, -1));
    }
    std::vector<double> runs;
    int cornea = 0;
    double sink = 0;
    for (int run = 0; run < 5; ++run) {
      cornea = 0;
      const auto t0 = Clock::now();
      for (const Query& q : queries) {
        const EyeMeshHit h = EyeMeshHitToCanonical(*mesh->Context(), mesh->Eye(), q.tri, q.u, q.v, q.d);
        cornea += h.onCornea;
        sink += h.canonicalDir.x;
      }
      runs.push_back(Seconds(t0, Clock::now()));
    }
    const double ns = 1e9 * Median(runs) / hits;
    (reprojection ? nsOn : nsOff) = ns;
    std::printf("| %s | %.0f | %d%s |\n",
                reprojection ? "re-projection (projection, local rotation)" : "baseline (affine frame)", ns, cornea,
                sink == 12345.678 ? " " : "");
  }
  std::printf("\nRe-projection costs %.0f ns more per hit than the baseline's affine mapping.\n\n", nsOn - nsOff);

  std::printf(
      "### A whole render for scale (64 x 64, 16 spp, all threads, sclera walk off; the tests' stretched eye)\n\n");
  std::printf("| mapping | seconds | camera samples / s |\n|---|---|---|\n");
  test::Eyeball coarse(32, 16, 32, 1);
  const auto stretched = Pose(coarse, 2.0);
  for (bool reprojection : {true, false}) {
    std::vector<double> secs;
    for (int run = 0; run < 3; ++run) {
      test::DeformedEyeScene s(64, 38.2);
      EyeParams eye;
      eye.irisColor = glm::vec3(0.5f);
      eye.reprojection = reprojection;
      s.scene.AddEyeMesh("/eye", coarse.topology, stretched, eye);
      s.scene.SetPrimvar("/eye", "rest", coarse.Rest());
      secs.push_back(s.Render(16).seconds);
    }
    std::printf("| %s | %.3f | %.0f |\n", reprojection ? "re-projection" : "baseline", Median(secs),
                64 * 64 * 16 / Median(secs));
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 40, hits = 200000;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
      frames = std::max(3, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--hits") && i + 1 < argc)
      hits = std::max(1000, std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "usage: bench_deformed_eye [--frames N] [--hits N]\n");
      return 2;
    }
  }
  std::printf("# bench_deformed_eye: animated eye meshes, update vs rebuild, re-projection per hit\n\n");
  UpdateCost(frames);
  HitCost(hits);
  return 0;
}
