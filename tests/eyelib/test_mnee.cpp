// Manifold next event estimation through the analytic cornea: Snell's law at the solutions, the
// generalized geometry term against closed forms and finite differences, and the irradiance against
// an independent light-tracing reference.
#include "eyelib/entry_point_table.h"
#include "eyelib/mnee.h"
#include "eyelib/optics.h"
#include "mnee_test_helpers.h"
#include "sampling_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <random>

using namespace eyelib;

namespace {

Vec3d IrisPoint(const AnteriorChamber<double>& chamber, double r, double phi) {
  return {r * std::cos(phi), r * std::sin(phi), chamber.IrisZ()};
}

/// An iris point between the pupil and the iris edge, at a random radius (sqrt: denser outwards) and azimuth.
template <class Rng> Vec3d RandomIrisPoint(const AnteriorChamber<double>& chamber, Rng& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const double r = chamber.PupilRadius() + (chamber.IrisRadius() - chamber.PupilRadius()) * std::sqrt(u(rng));
  return IrisPoint(chamber, r, 2 * paper::kPi * u(rng));
}

LightEnd PointEnd(double degrees, double distance = 100) {
  return {false, test::PointLightAt(degrees, distance).position, {}};
}

}  // namespace

TEST_CASE("with a cornea of index 1 the transfer is the inverse-square law times the iris cosine") {
  ChamberParams params;
  params.corneaIor = 1.0;
  const AnteriorChamber<double> chamber(params);
  std::mt19937_64 rng(1);
  for (int i = 0; i < 500; ++i) {
    const Vec3d x = IrisPoint(chamber, test::Uniform(rng, 2.1, 7.0), test::Uniform(rng, 0, 6.28));
    const LightEnd light = PointEnd(test::Uniform(rng, 0, 60));
    const MneeResult r = FindRefractionPaths(chamber, x, light);
    const Vec3d d = light.position - x;
    const double expected = (d.z / glm::length(d)) / glm::dot(d, d);
    INFO("x = (" << x.x << ", " << x.y << ")");
    REQUIRE(r.solutions.size() == 1);
    CHECK(r.solutions[0].fresnelT == Approx(1.0).margin(1e-15));
    CHECK(r.transfer == Approx(expected).epsilon(1e-9));
  }
}

TEST_CASE("converged paths obey Snell's law at the cornea, in both models") {
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    ChamberParams params;
    params.model = model;
    const AnteriorChamber<double> chamber(params);
    std::mt19937_64 rng(2);
    double worst = 0;
    int converged = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3d x = IrisPoint(chamber, test::Uniform(rng, 2.0, chamber.IrisRadius()), test::Uniform(rng, 0, 6.28));
      const LightEnd light = PointEnd(test::Uniform(rng, 0, 80), test::Uniform(rng, 20, 1000));
      const MneeResult r = FindRefractionPaths(chamber, x, light);
      for (const MneeSolution& s : r.solutions) {
        ++converged;
        const Vec3d a = glm::normalize(s.p - x), b = glm::normalize(light.position - s.p);
        // n sin(theta_inside) = sin(theta_outside), and the three directions are coplanar.
        const double sinIn = glm::length(glm::cross(a, s.normal)), sinOut = glm::length(glm::cross(b, s.normal));
        worst = std::max(worst, std::abs(chamber.CorneaIor() * sinIn - sinOut));
        CHECK(std::abs(glm::dot(glm::cross(a, b), s.normal)) < 1e-9);
        CHECK(std::isfinite(s.transfer));
        CHECK(s.transfer > 0);
      }
    }
    INFO(ToString(model) << ": " << converged << " paths, worst |n sin_i - sin_t| = " << worst);
    CHECK(converged > 1500);
    CHECK(worst < 1e-10);
  }
}

TEST_CASE("the generalized geometry term matches a finite-difference Jacobian of the solution") {
  const AnteriorChamber<double> chamber;
  std::mt19937_64 rng(3);
  double worst = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3d x = IrisPoint(chamber, test::Uniform(rng, 2.2, 7.0), test::Uniform(rng, 0, 6.28));
    const LightEnd light = PointEnd(test::Uniform(rng, 0, 60));
    const MneeResult r = FindRefractionPaths(chamber, x, light);
    if (r.solutions.size() != 1) continue;
    const MneeSolution& s = r.solutions[0];
    // d(u, v)/dx by central differences of re-solved paths, then the closed-form transfer rebuilt.
    const double h = 1e-5;
    auto solveAt = [&](const Vec3d& xx) { return SolveRefractionPath(chamber, xx, light, s.p.x, s.p.y).p; };
    const Vec3d px1 = solveAt(x + Vec3d(h, 0, 0)), px0 = solveAt(x - Vec3d(h, 0, 0));
    const Vec3d py1 = solveAt(x + Vec3d(0, h, 0)), py0 = solveAt(x - Vec3d(0, h, 0));
    const double det = ((px1.x - px0.x) * (py1.y - py0.y) - (px1.y - px0.y) * (py1.x - py0.x)) / (4 * h * h);
    const Vec3d b = light.position - s.p;
    const double lb = glm::length(b);
    const auto d = chamber.Surface().Height(s.p.x, s.p.y);
    const double fd = s.fresnelT * std::abs(glm::dot(Vec3d(-d.hx, -d.hy, 1), b / lb)) * std::abs(det) / (lb * lb);
    worst = std::max(worst, std::abs(fd / s.transfer - 1));
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-5);
}

TEST_CASE("a distant light equals a far point light of matching intensity") {
  const AnteriorChamber<double> chamber;
  for (double deg : {0.0, 30.0, 60.0}) {
    const double D = 1e7;
    const LightEnd point = PointEnd(deg, D);
    const LightEnd distant{true, {}, glm::normalize(point.position)};
    const Vec3d x = IrisPoint(chamber, 4.0, 2.0);
    const double ePoint = FindRefractionPaths(chamber, x, point).transfer * D * D;
    const double eDistant = FindRefractionPaths(chamber, x, distant).transfer;
    CHECK(ePoint == Approx(eDistant).epsilon(1e-5));
  }
}

TEST_CASE("invalid input and lights behind the eye give no path and no NaN") {
  const AnteriorChamber<double> chamber;
  const double nan = std::nan("");
  const Vec3d x = IrisPoint(chamber, 4, 0);
  CHECK(SolveRefractionPath(chamber, Vec3d(nan, 0, -3), PointEnd(0), 0, 0).status == MneeStatus::InvalidInput);
  CHECK(SolveRefractionPath(chamber, x, {false, Vec3d(0, nan, 10), {}}, 0, 0).status == MneeStatus::InvalidInput);
  CHECK(SolveRefractionPath(chamber, x, PointEnd(0), nan, 0).status == MneeStatus::InvalidInput);
  CHECK(SolveRefractionPath(chamber, Vec3d(0, 0, 1), PointEnd(0), 0, 0).status == MneeStatus::InvalidInput);
  const MneeResult behind = FindRefractionPaths(chamber, x, PointEnd(150), test::Seeds(true));
  CHECK(behind.solutions.empty());
  CHECK(behind.transfer == 0);
}

TEST_CASE("started at the approximate entry point, MNEE finds the straight line's paths in fewer iterations") {
  // SeedStrategy::start: Newton from where the light's centre refracts towards x, for points of a 1 mm sphere light
  // 100 mm away at 30, 62 and 80 degrees off the gaze, iris points over the whole disk. The paths found must be the
  // same (a fold's second path may differ in a few: either is MNEE's one-solution estimate), in fewer iterations
  // (about 3 against 5 per converged estimate).
  const AnteriorChamber<double> chamber;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (double degrees : {30.0, 62.0, 80.0}) {
    const Vec3d centre = PointEnd(degrees).position;
    long iterationsLine = 0, iterationsEntry = 0, found = 0, same = 0;
    double transferLine = 0, transferEntry = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const Vec3d x = RandomIrisPoint(chamber, rng);
      const double z = 2 * u(rng) - 1, a = 2 * paper::kPi * u(rng), s = std::sqrt(1 - z * z);
      const LightEnd end{false, centre + Vec3d(s * std::cos(a), s * std::sin(a), z), {}};
      SeedStrategy seeds;
      const MneeResult line = FindRefractionPaths(chamber, x, end, seeds);
      const Vec3d entry = ApproximateEntryPoint(chamber, x, {false, centre, {}});
      seeds.start = Vec2<double>(entry.x, entry.y);
      const MneeResult started = FindRefractionPaths(chamber, x, end, seeds);
      iterationsLine += line.iterations, iterationsEntry += started.iterations;
      transferLine += line.transfer, transferEntry += started.transfer;
      if (line.solutions.empty() != started.solutions.empty()) continue;
      if (line.solutions.empty()) continue;
      ++found;
      same += glm::length(line.solutions[0].p - started.solutions[0].p) < 1e-6;
    }
    std::printf(
        "light %.0f deg: iterations per estimate %.2f from the straight line, %.2f from the entry point; "
        "%ld of %ld first paths the same; transfer %+.4f %%\n",
        degrees, double(iterationsLine) / n, double(iterationsEntry) / n, same, found,
        100 * (transferEntry / transferLine - 1));
    // Where the light leaves part of the iris in shadow, the failed solves there (and their retries) dominate both.
    CHECK(iterationsEntry < (degrees < 60 ? 0.8 : 1.0) * iterationsLine);
    CHECK(same >= 0.998 * found);
    CHECK(std::abs(transferEntry / transferLine - 1) < 0.002);
  }
}

TEST_CASE("a small light's failed start is not worth retrying: the same light, in a fraction of the iterations") {
  // SeedStrategy::retryStart off, for lights under sin 0.05 of angular radius 15 mm to 1 m away, 0-88 degrees off the
  // gaze: the meridian seeds a failed start would be retried from find no light it missed.
  const AnteriorChamber<double> chamber;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (double distance : {15.0, 100.0, 1000.0})
    for (double degrees : {0.0, 62.0, 80.0, 88.0}) {
      const double radius = 0.049 * distance, a0 = degrees * paper::kPi / 180;
      const Vec3d centre(distance * std::sin(a0), 0, distance * std::cos(a0));
      double retried = 0, once = 0;
      long iterationsRetried = 0, iterationsOnce = 0;
      for (int i = 0; i < 4000; ++i) {
        const Vec3d x = RandomIrisPoint(chamber, rng);
        const double z = 2 * u(rng) - 1, a = 2 * paper::kPi * u(rng), s = std::sqrt(1 - z * z);
        const LightEnd end{false, centre + radius * Vec3d(s * std::cos(a), s * std::sin(a), z), {}};
        MneeOptions options;
        options.scleraOccludes = false;
        SeedStrategy seeds;
        const Vec3d entry = ApproximateEntryPoint(chamber, x, {false, centre, {}});
        seeds.start = Vec2<double>(entry.x, entry.y);
        const MneeResult withRetry = FindRefractionPaths(chamber, x, end, seeds, options);
        seeds.retryStart = false;
        const MneeResult without = FindRefractionPaths(chamber, x, end, seeds, options);
        retried += withRetry.transfer, once += without.transfer;
        iterationsRetried += withRetry.iterations, iterationsOnce += without.iterations;
      }
      std::printf("light %4.0f mm away, %2.0f deg: light without the retry %+.4f %%, iterations %.2f -> %.2f\n",
                  distance, degrees, 100 * (once / retried - 1), iterationsRetried / 4000.0, iterationsOnce / 4000.0);
      CHECK(std::abs(once / retried - 1) < 1e-4);
      if (degrees >= 62) CHECK(iterationsOnce < 0.4 * iterationsRetried);
    }
}

TEST_CASE("a distant direction started at its own entry point needs no retry, from above or below the rim plane") {
  // IrisIrradianceFromLight's start for a dome's or a distant light's sampled direction: ApproximateEntryPoint along
  // it (from mid-cone for light from below the rim plane), no retry. Against the straight line with the meridian
  // retry, over the whole sphere of directions: the same light, in fewer iterations.
  const AnteriorChamber<double> chamber;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  MneeOptions options;
  options.scleraOccludes = false;
  for (const auto& [zLow, zHigh] : {std::pair{-0.62, 0.0}, std::pair{0.0, 1.0}}) {
    double retried = 0, started = 0;
    long iterationsRetried = 0, iterationsStarted = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec3d x = RandomIrisPoint(chamber, rng);
      const double z = zLow + (zHigh - zLow) * u(rng), a = 2 * paper::kPi * u(rng), s = std::sqrt(1 - z * z);
      const LightEnd end{true, {}, Vec3d(s * std::cos(a), s * std::sin(a), z)};
      SeedStrategy seeds;
      const MneeResult withRetry = FindRefractionPaths(chamber, x, end, seeds, options);
      const Vec3d entry = ApproximateEntryPoint(chamber, x, end);
      seeds.start = Vec2<double>(entry.x, entry.y);
      seeds.retryStart = false;
      const MneeResult once = FindRefractionPaths(chamber, x, end, seeds, options);
      retried += withRetry.transfer, started += once.transfer;
      iterationsRetried += withRetry.iterations, iterationsStarted += once.iterations;
    }
    std::printf("directions z in [%.2f, %.2f]: light from the entry point %+.4f %%, iterations %.2f -> %.2f\n", zLow,
                zHigh, 100 * (started / retried - 1), iterationsRetried / 20000.0, iterationsStarted / 20000.0);
    CHECK(started >= (1 - 1e-4) * retried);
    CHECK(iterationsStarted < 0.5 * iterationsRetried);
  }
}

TEST_CASE("no path leaves towards a direction further below the rim plane than the cap's normals tilt") {
  // MneeStatus::BehindCap: z <= -sin(atan(MaxSlope)). MaxSlope is the steepest slope over the cap; every direction
  // light refracted out of the cap from an iris point takes lies above the bound (and comes within a few degrees of
  // it), and MNEE makes no solve below it.
  for (CorneaModel model : {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid}) {
    ChamberParams params;
    params.model = model;
    const AnteriorChamber<double> chamber(params);
    const AnteriorSurface<double>& surface = chamber.Surface();
    double steepest = 0;
    for (int i = 0; i <= 10000; ++i)
      steepest = std::max(steepest, std::abs(surface.Slope(surface.RimRadius() * i / 1e4)));
    CHECK(surface.MaxSlope() == Approx(steepest).epsilon(1e-3));
    const double bound = -surface.MaxSlope() / std::sqrt(1 + surface.MaxSlope() * surface.MaxSlope());
    double lowest = 1;
    for (int k = 0; k <= 40; ++k) {
      const Vec3d x =
          IrisPoint(chamber, chamber.PupilRadius() + (chamber.IrisRadius() - chamber.PupilRadius()) * k / 40.0, 0.0);
      for (int i = 1; i <= 200; ++i)
        for (int j = 0; j < 64; ++j) {
          const double r = surface.RimRadius() * i / 200, phi = 2 * paper::kPi * j / 64;
          const Vec3d p(r * std::cos(phi), r * std::sin(phi), surface.Sag(r));
          Vec3d out;
          if (Refract(glm::normalize(x - p), -surface.Normal(p.x, p.y), 1 / chamber.CorneaIor(), &out))
            lowest = std::min(lowest, out.z);
        }
      const LightEnd below{true, {}, Vec3d(std::sqrt(1 - bound * bound), 0, bound - 1e-12)};
      CHECK(SolveRefractionPath(chamber, x, below, 0, 0).status == MneeStatus::BehindCap);
    }
    std::printf("%s: max slope %.4f, bound z = %.4f, lowest refracted direction z = %.4f\n", ToString(model),
                surface.MaxSlope(), bound, lowest);
    CHECK(lowest > bound);
    CHECK(lowest < bound + 0.1);
  }
}

TEST_CASE("a tabulated entry point starts MNEE as well as the computed one") {
  // EntryPointTable: a bilinear lookup of 33 x 33 converged nodes over the iris, against
  // ApproximateEntryPoint's three steps from the apex, for points on a small light 100 mm and 15 mm away at 0-88
  // degrees, iris points over the whole disk: the same light, in no more iterations, from a start as near the path.
  const AnteriorChamber<double> chamber;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0, 1);
  MneeOptions options;
  options.scleraOccludes = false;
  for (double distance : {15.0, 100.0})
    for (double degrees : {0.0, 30.0, 62.0, 80.0, 88.0}) {
      const double a0 = degrees * paper::kPi / 180, radius = 0.049 * distance;
      const Vec3d centre(distance * std::sin(a0), 0, distance * std::cos(a0));
      const EntryPointTable table(chamber, {false, centre, {}});
      double computed = 0, tabulated = 0, offComputed = 0, offTabulated = 0;
      long iterationsComputed = 0, iterationsTabulated = 0, found = 0;
      for (int i = 0; i < 4000; ++i) {
        const Vec3d x = RandomIrisPoint(chamber, rng);
        const double z = 2 * u(rng) - 1, a = 2 * paper::kPi * u(rng), s = std::sqrt(1 - z * z);
        const LightEnd end{false, centre + radius * Vec3d(s * std::cos(a), s * std::sin(a), z), {}};
        SeedStrategy seeds;
        seeds.retryStart = false;
        const Vec3d fromApex = ApproximateEntryPoint(chamber, x, {false, centre, {}}), fromTable = table.At(chamber, x);
        seeds.start = Vec2<double>(fromApex.x, fromApex.y);
        const MneeResult one = FindRefractionPaths(chamber, x, end, seeds, options);
        seeds.start = Vec2<double>(fromTable.x, fromTable.y);
        const MneeResult other = FindRefractionPaths(chamber, x, end, seeds, options);
        computed += one.transfer, tabulated += other.transfer;
        iterationsComputed += one.iterations, iterationsTabulated += other.iterations;
        if (one.solutions.empty()) continue;
        ++found;
        offComputed += glm::length(fromApex - one.solutions[0].p);
        offTabulated += glm::length(fromTable - one.solutions[0].p);
      }
      std::printf(
          "light %3.0f mm, %2.0f deg: light from the table %+.4f %%, iterations %.2f -> %.2f, start %.4f -> %.4f mm "
          "off the path\n",
          distance, degrees, 100 * (tabulated / computed - 1), iterationsComputed / 4000.0,
          iterationsTabulated / 4000.0, offComputed / std::max(1L, found), offTabulated / std::max(1L, found));
      CHECK(std::abs(tabulated / computed - 1) < 1e-3);
      CHECK(iterationsTabulated <= 1.05 * iterationsComputed);
      CHECK(offTabulated <= 1.5 * offComputed + 1e-3 * found);
    }
}

TEST_CASE("a tabulated entry point is the converged one out to the iris edge") {
  // EntryPointTable's lookup against ApproximateEntryPoint run to convergence (20 steps), on rings from the pupil to
  // 0.999 of the iris radius: the outermost cells straddle the disk's edge, where the nodes outside continue the map.
  const AnteriorChamber<double> chamber;
  for (double distance : {15.0, 100.0})
    for (double degrees : {0.0, 30.0, 62.0, 80.0, 88.0}) {
      const LightEnd light = PointEnd(degrees, distance);
      const EntryPointTable table(chamber, light);
      double sum = 0, worst = 0, worstEdge = 0;
      int n = 0;
      for (int ring = 0; ring <= 60; ++ring) {
        const double r =
            chamber.PupilRadius() + (0.999 * chamber.IrisRadius() - chamber.PupilRadius()) * std::sqrt(ring / 60.0);
        for (int k = 0; k < 90; ++k) {
          const Vec3d x = IrisPoint(chamber, r, 2 * paper::kPi * (k + 0.5) / 90);
          const double off = glm::length(table.At(chamber, x) - ApproximateEntryPoint(chamber, x, light, 20));
          sum += off, ++n;
          double& worstHere = r > 0.95 * chamber.IrisRadius() ? worstEdge : worst;
          worstHere = std::max(worstHere, off);
        }
      }
      std::printf(
          "light %3.0f mm, %2.0f deg: table %.4f mm from the converged entry on average, worst %.4f mm "
          "(%.4f mm in the outer 5 %%)\n",
          distance, degrees, sum / n, worst, worstEdge);
      // Grazing light enters near the rim, where the map bends fastest (a cell of 0.47 mm is coarse there).
      CHECK(sum / n < (degrees < 70 ? 0.01 : 0.05));
      CHECK(worstEdge < 0.15);
    }
}
