// The paper's numbers, as tests (Chiang and Burley 2018, section 2 and figure 3).
#include "eyelib/anterior_chamber.h"
#include "eyelib/anterior_surface.h"
#include "eyelib/optics.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

using namespace eyelib;

namespace {
const double kDeg = paper::kPi / 180;
const AnteriorSurface<double> kEllipsoidCone(CorneaModel::EllipsoidCone);
const AnteriorSurface<double> kParaboloid(CorneaModel::Paraboloid);
}  // namespace

TEST_CASE("the 15.08 mm chord sits 3.735 mm below the apex, within 2 micrometres") {
  const double depth = -kEllipsoidCone.Sag(15.08 / 2);
  INFO("f(7.54) = " << -depth << " mm");
  CHECK(std::abs(depth - 3.735) < 2e-3);
}

TEST_CASE("the ellipsoid piece follows 0.75 z^2 + 15.6 z + r^2 = 0 through the apex") {
  for (double r = 0; r < 5.01; r += 0.25) {
    const double z = kEllipsoidCone.Sag(r);
    INFO("r = " << r << " z = " << z);
    CHECK(std::abs(0.75 * z * z + 15.6 * z + r * r) < 1e-12);
    CHECK(z > -15.6 / 1.5);  // the sheet through the apex, not the back of the ellipsoid
  }
  CHECK(kEllipsoidCone.Sag(0) == 0);
  CHECK(kEllipsoidCone.Normal(0, 0) == Vec3<double>(0, 0, 1));
}

TEST_CASE("the conical extension subtends 38 degrees between the 10.02 and 15.08 mm chords") {
  for (double r : {5.02, 6.0, 7.0, 7.54}) {
    const double angle = std::atan(-kEllipsoidCone.Slope(r)) / kDeg;
    INFO("r = " << r << " angle = " << angle);
    CHECK(std::abs(angle - 38.0) < 1e-12);
    CHECK(kEllipsoidCone.PieceAt(r) == SurfacePiece::Cone);
  }
  CHECK(kEllipsoidCone.PieceAt(5.0) == SurfacePiece::Ellipsoid);
}

TEST_CASE("the ellipsoid-cone junction at the 10.02 mm chord is continuous and convex") {
  const double rj = 10.02 / 2, h = 1e-9;
  const double below = kEllipsoidCone.Sag(rj - h), above = kEllipsoidCone.Sag(rj + h);
  const double slopeIn = kEllipsoidCone.Slope(rj - h), slopeOut = kEllipsoidCone.Slope(rj + h);
  std::printf("junction: f = %.9f mm, slope ellipsoid %.4f, cone %.4f, kink %.2f deg\n", below, slopeIn, slopeOut,
              (std::atan(-slopeOut) - std::atan(-slopeIn)) / kDeg);
  CHECK(std::abs(below - above) < 1e-8);
  CHECK(std::abs(slopeIn - (-0.773)) < 1e-3);
  CHECK(std::abs(slopeOut - (-0.781)) < 1e-3);
  CHECK(slopeOut < slopeIn);  // slope keeps decreasing: the surface stays convex across the kink
}

TEST_CASE("the surface is convex everywhere on the cap") {
  for (const auto* s : {&kEllipsoidCone, &kParaboloid}) {
    for (double r = 0; r <= 7.54; r += 0.01) {
      const auto k = s->Curvatures(r);
      INFO(ToString(s->Model()) << " r = " << r);
      CHECK(k.meridional >= 0);
      CHECK(k.sagittal > 0);
    }
  }
}

TEST_CASE("the apex radius of curvature is 7.8 mm (ellipsoid) and 7.25 mm (paraboloid)") {
  CHECK(1 / kEllipsoidCone.Curvatures(0).meridional == Approx(7.8).epsilon(1e-12));
  CHECK(1 / kEllipsoidCone.Curvatures(0).sagittal == Approx(7.8).epsilon(1e-12));
  CHECK(1 / kParaboloid.Curvatures(0).meridional == Approx(7.25).epsilon(1e-12));
}

TEST_CASE("the paraboloid 14.5 z + r^2 = 0 against the ellipsoid-cone, as a sag table") {
  std::printf("\n  r (mm) | ellipsoid-cone f (mm) | paraboloid f (mm) | difference (um)\n");
  double worst = 0, worstR = 0;
  for (double r : {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 5.01, 5.5, 6.0, 6.5, 7.0, 7.25, 7.54}) {
    const double fe = kEllipsoidCone.Sag(r), fp = kParaboloid.Sag(r);
    std::printf("  %6.2f | %21.5f | %17.5f | %15.1f\n", r, fe, fp, (fp - fe) * 1e3);
    CHECK(std::abs(fp + r * r / 14.5) < 1e-12);
    if (std::abs(fp - fe) > worst) worst = std::abs(fp - fe), worstR = r;
  }
  std::printf("  worst difference %.1f um at r = %.2f mm\n", worst * 1e3, worstR);
  // The paraboloid is deeper everywhere off-axis; it crosses the 3.735 mm iris plane before the rim.
  CHECK(worstR == Approx(7.54));
  CHECK(worst == Approx(56.8516 / 14.5 - 3.73414).margin(1e-4));
  CHECK(kParaboloid.InverseSag(-3.735) == Approx(std::sqrt(14.5 * 3.735)).epsilon(1e-12));
}

TEST_CASE("the limbus defaults are 11.64 and 12.89 mm, as ratios over the 15.08 mm iris") {
  const AnteriorChamber<double> chamber;
  CHECK(2 * chamber.LimbusInnerRadius() == Approx(11.64).epsilon(1e-12));
  CHECK(2 * chamber.LimbusOuterRadius() == Approx(12.89).epsilon(1e-12));
  CHECK(chamber.Params().limbusInnerRatio == Approx(0.772).margin(5e-4));
  CHECK(chamber.Params().limbusOuterRatio == Approx(0.855).margin(5e-4));
  CHECK(chamber.IrisZ() == -3.735);
}

TEST_CASE("the critical angle inside the cornea is 46.6 degrees") {
  CHECK(CriticalAngle(1.376) / kDeg == Approx(46.6).margin(0.05));
}
