// MNEE at the ellipsoid-cone junction (r = 5.01 mm), where the anterior surface has a 0.3 degree slope kink
// and a curvature jump. An iris point can have one path through each piece there (the pieces' caustics
// overlap) or none (a gap); a Newton solve on the piecewise surface finds at most one.
//
// The check: the light that enters the cornea within 0.15 mm of the junction, light-traced (rays binned only
// if they enter in that band) against MNEE restricted to the paths whose cornea point lies in the band,
// integrated over the iris with jittered points (an unbiased quadrature). Flux totals are compared, with
// both estimates' standard errors; the same for the whole cap bounds the bias everywhere else.
#include "mnee_test_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

using namespace eyelib;

namespace {

constexpr double kBandHalfWidth = 0.15;  // mm, in cornea radius around the junction

/// A point light of unit intensity 100 mm from the apex, `degrees` off the gaze at azimuth `azimuthDeg`.
EyeLight PointLight(double degrees, double azimuthDeg) {
  const double t = degrees * paper::kPi / 180, a = azimuthDeg * paper::kPi / 180;
  EyeLight light;
  light.position = 100.0 * Vec3d(std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t));
  return light;
}

struct FluxComparison {
  double lightTraced = 0, lightTracedError = 0;  // W, flux onto the iris through the band
  double mnee = 0, mneeError = 0;
  double Relative() const { return mnee / lightTraced - 1; }
  double Z() const {
    return std::abs(mnee - lightTraced) / std::sqrt(lightTracedError * lightTracedError + mneeError * mneeError);
  }
};

/// Flux onto the iris disk that enters the cornea in `band`: light tracing, and MNEE (`seeds`) integrated
/// over the light tracer's cells with k x k jittered points each.
FluxComparison CompareBandFlux(const AnteriorChamber<double>& chamber, const EyeLight& light, const CorneaBand& band,
                               const SeedStrategy& seeds, std::int64_t rays, int k) {
  const IrisGrid grid{40, 7.54};
  const IrradianceMap lt = LightTraceIris(chamber, light, grid, rays, 23, band);
  const double area = grid.CellSize() * grid.CellSize();
  FluxComparison c;
  double var = 0;
  for (std::size_t i = 0; i < lt.irradiance.size(); ++i) {
    c.lightTraced += lt.irradiance[i] * area;
    var += lt.stdError[i] * lt.stdError[i] * area * area;
  }
  c.lightTracedError = std::sqrt(var);
  double mneeVar = 0;
  for (int j = 0; j < grid.cells; ++j)
    for (int i = 0; i < grid.cells; ++i) {
      const Vec2<double> centre = grid.CellCenter(i, j);
      double sum = 0, pairVar = 0, previous = 0;
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
          const std::uint64_t idx = (std::uint64_t(j * grid.cells + i) * k + a) * k + b;
          const Vec3d x(centre.x + grid.CellSize() * ((a + UniformAt(7, 0, idx)) / k - 0.5),
                        centre.y + grid.CellSize() * ((b + UniformAt(7, 1, idx)) / k - 0.5), chamber.IrisZ());
          const double r = std::hypot(x.x, x.y);
          double e = 0;
          if (r >= chamber.PupilRadius() && r <= chamber.IrisRadius())
            for (const MneeSolution& s : FindRefractionPaths(chamber, x, {false, light.position, {}}, seeds).solutions)
              if (band.Contains(std::hypot(s.p.x, s.p.y))) e += s.transfer * light.power;
          sum += e;
          // One jittered point per stratum: the variance from neighbouring strata taken pairwise (collapsed
          // strata), which does not count the stratification's gain as noise.
          if (b % 2 == 1) pairVar += (e - previous) * (e - previous);
          previous = e;
        }
      const double n = double(k) * k;
      c.mnee += sum / n * area;
      mneeVar += pairVar / (n * n) * area * area;
    }
  c.mneeError = std::sqrt(mneeVar);
  return c;
}

void PrintRow(const char* what, double deg, double az, const FluxComparison& c) {
  std::printf("| %s | %g deg, azimuth %g | %.5g | %.5g | %+.2f%% | %.2f%% | %.1f |\n", what, deg, az, c.lightTraced,
              c.mnee, 100 * c.Relative(),
              100 * std::sqrt(c.lightTracedError * c.lightTracedError + c.mneeError * c.mneeError) / c.lightTraced,
              c.Z());
}

}  // namespace

TEST_CASE("one-path MNEE brings the light that light tracing does through the ellipsoid-cone junction band") {
  const AnteriorChamber<double> chamber;
  const double J = chamber.Surface().JunctionRadius();
  const CorneaBand band{J - kBandHalfWidth, J + kBandHalfWidth};
  std::printf("\n| light through | point light | light traced (W) | MNEE one path (W) | difference | sigma | z |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  // Frontal to grazing, and scene B's direction (62 degrees, azimuth 200).
  for (const auto& [deg, az] : {std::pair{0.0, 0.0}, {30.0, 0.0}, {62.0, 200.0}, {75.0, 0.0}}) {
    const FluxComparison c = CompareBandFlux(chamber, PointLight(deg, az), band, SeedStrategy{}, 3'000'000, 12);
    PrintRow("junction band", deg, az, c);
    INFO(deg << " deg: light traced " << c.lightTraced << ", MNEE " << c.mnee << " (" << 100 * c.Relative() << "%, z "
             << c.Z() << ")");
    CHECK(c.Z() < 4);
    CHECK(std::abs(c.Relative()) < 0.01);
  }
}

TEST_CASE("one-path MNEE's flux onto the iris over the whole cornea is within 0.3% of light tracing") {
  // The bound on the bias away from the junction (the fold's second paths at grazing light are the rest).
  const AnteriorChamber<double> chamber;
  std::printf("\n| light through | point light | light traced (W) | MNEE one path (W) | difference | sigma | z |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const auto& [deg, az] : {std::pair{0.0, 0.0}, {30.0, 0.0}, {62.0, 200.0}, {75.0, 0.0}}) {
    const FluxComparison c = CompareBandFlux(chamber, PointLight(deg, az), CorneaBand{}, SeedStrategy{}, 3'000'000, 8);
    PrintRow("whole cap", deg, az, c);
    INFO(deg << " deg: light traced " << c.lightTraced << ", MNEE " << c.mnee << " (" << 100 * c.Relative() << "%)");
    CHECK(c.Z() < 4);
    CHECK(std::abs(c.Relative()) < 0.003);
  }
}

TEST_CASE("both paths of a junction pair lie near the junction and the default search finds every pair") {
  // With the pairing radius widened to 4 mm every seed is solved on both pieces: the pairs found that way
  // bound how far from the junction a pair's paths lie, and the default radius must find the same light.
  const AnteriorChamber<double> chamber;
  const double J = chamber.Surface().JunctionRadius();
  SeedStrategy wide;
  wide.junctionPairRadius = 4;
  int pairs = 0, missed = 0;
  double farthest = 0;
  for (double distance : {12.0, 100.0, 1e6})
    for (double deg : {0.0, 30.0, 60.0, 88.0}) {
      const EyeLight light = PointLight(deg, 20);
      const int n = 120;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const Vec3d x(-7.5 + 15.0 * (i + 0.5) / n, -7.5 + 15.0 * (j + 0.5) / n, chamber.IrisZ());
          const double r = std::hypot(x.x, x.y);
          if (r < chamber.PupilRadius() || r > chamber.IrisRadius()) continue;
          const LightEnd end{false, light.position * (distance / 100), {}};
          const MneeResult all = FindRefractionPaths(chamber, x, end, wide);
          int ellipsoid = 0, cone = 0;
          double d = 0;
          for (const MneeSolution& s : all.solutions) {
            (s.piece == SurfacePiece::Cone ? cone : ellipsoid)++;
            d = std::max(d, std::abs(std::hypot(s.p.x, s.p.y) - J));
          }
          if (ellipsoid == 0 || cone == 0) continue;
          ++pairs;
          farthest = std::max(farthest, d);
          const MneeResult byDefault = FindRefractionPaths(chamber, x, end);
          missed += std::abs(byDefault.transfer - all.transfer) > 1e-9 * all.transfer;
        }
    }
  std::printf("\njunction pairs: %d, farthest path %.4f mm from the junction, missed by the default search %d\n", pairs,
              farthest, missed);
  CHECK(pairs > 50);  // the overlap exists: the test is not vacuous
  CHECK(farthest < SeedStrategy{}.junctionPairRadius / 4);
  CHECK(missed == 0);
}
