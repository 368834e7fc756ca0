// MNEE hard cases: a convergence table per case (success rate, iterations, residual), never NaN.
#include "eyelib/mnee.h"
#include "mnee_test_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

using namespace eyelib;

namespace {

struct Case {
  std::string name;
  LightEnd light;
  std::vector<double> irisRadii;  // mm
  double minSuccess;              // fraction of iris points that must find a path
};

LightEnd PointAt(double deg, double dist = 100) { return {false, test::PointLightAt(deg, dist).position, {}}; }

}  // namespace

TEST_CASE("MNEE hard cases: convergence table, no NaN, lights behind the eye find nothing") {
  const AnteriorChamber<double> chamber;
  const double pupil = chamber.PupilRadius(), root = chamber.IrisRadius();
  const std::vector<double> everywhere = {pupil + 1e-9, 3.0, 4.5, 6.0, root - 1e-6};
  const std::vector<Case> cases = {
      {"point 0 deg", PointAt(0), everywhere, 0.8},  // the iris root sees the light only through the sclera
      {"point 30 deg", PointAt(30), everywhere, 0.8},
      {"point 60 deg", PointAt(60), everywhere, 0.5},
      {"point 75 deg", PointAt(75), everywhere, 0.4},
      {"point 85 deg", PointAt(85), everywhere, 0.3},
      {"behind the eye (120 deg)", PointAt(120), everywhere, 0.0},
      {"pupil edge, 45 deg", PointAt(45), {pupil, pupil + 1e-12}, 1.0},
      {"iris root, 45 deg", PointAt(45), {root - 1e-9, root - 1e-3}, 0.4},
      {"paths through the junction (iris r 4.4-4.8, 20 deg)", PointAt(20), {4.4, 4.5, 4.6, 4.7, 4.8}, 0.9},
      {"light 1 mm from the apex", PointAt(10, 1.0), everywhere, 0.5},
      {"far light, 1e6 mm", PointAt(40, 1e6), everywhere, 0.8},
      {"distant light 40 deg", {true, {}, glm::normalize(test::PointLightAt(40).position)}, everywhere, 0.8},
  };
  std::printf(
      "\n| case | solves | success | mean iterations | max iterations | max residual | statuses "
      "|\n|---|---|---|---|---|---|---|\n");
  for (const Case& c : cases) {
    int solves = 0, ok = 0, itSum = 0, itMax = 0, nan = 0;
    double resMax = 0;
    std::map<std::string, int> statuses;
    for (double r : c.irisRadii)
      for (int k = 0; k < 64; ++k) {
        const double phi = 2 * paper::kPi * k / 64;
        const Vec3d x(r * std::cos(phi), r * std::sin(phi), chamber.IrisZ());
        const Vec2<double> seed = StraightLineSeed(chamber, x, c.light);
        const MneeSolution s = SolveRefractionPath(chamber, x, c.light, seed.x, seed.y);
        ++solves;
        ++statuses[ToString(s.status)];
        if (!std::isfinite(s.transfer) || !std::isfinite(s.residual)) ++nan;
        if (s.status != MneeStatus::Converged) continue;
        ++ok;
        itSum += s.iterations;
        itMax = std::max(itMax, s.iterations);
        resMax = std::max(resMax, s.residual);
      }
    std::string st;
    for (const auto& [name, n] : statuses) st += name + " " + std::to_string(n) + "; ";
    std::printf("| %s | %d | %.1f%% | %.1f | %d | %.1e | %s |\n", c.name.c_str(), solves, 100.0 * ok / solves,
                ok ? double(itSum) / ok : 0.0, itMax, resMax, st.c_str());
    INFO(c.name);
    CHECK(nan == 0);
    CHECK(double(ok) / solves >= c.minSuccess);
    CHECK(itMax <= MneeOptions{}.maxIterations);
    CHECK(resMax <= MneeOptions{}.tolerance);
    if (c.minSuccess == 0) CHECK(ok == 0);
  }
}
