// The anterior chamber: iris plane, pupil, limbus blend and parameter validation.
#include "eyelib/anterior_chamber.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace eyelib;
using V = Vec3<double>;

TEST_CASE("the iris disk ends where the iris plane meets the cornea, capped at the rim") {
  const AnteriorChamber<double> anatomical;
  CHECK(anatomical.IrisRadius() == Approx(7.54));
  ChamberParams shallow;
  shallow.irisDepth = -AnteriorSurface<double>().Sag(11.64 / 2);  // figure 4(a): iris at the inner limbus
  const AnteriorChamber<double> a(shallow);
  CHECK(a.IrisRadius() == Approx(11.64 / 2).epsilon(1e-12));
  ChamberParams parab;
  parab.model = CorneaModel::Paraboloid;
  CHECK(AnteriorChamber<double>(parab).IrisRadius() == Approx(std::sqrt(14.5 * 3.735)).epsilon(1e-12));
}

TEST_CASE("rays meet the iris between the pupil and the iris edge, from either side") {
  const AnteriorChamber<double> c;
  CHECK(c.IntersectIris({V(3, 0, 0), V(0, 0, -1)})->point.z == -3.735);
  CHECK_FALSE(c.IntersectIris({V(1, 0, 0), V(0, 0, -1)}));       // through the 2 mm pupil radius
  CHECK_FALSE(c.IntersectIris({V(7.6, 0, 0), V(0, 0, -1)}));     // beyond the iris edge
  CHECK(c.IntersectIris({V(3, 0, -5), V(0, 0, 1)}));             // from behind
  CHECK_FALSE(c.IntersectIris({V(3, 0, 0), V(1, 0, 0)}));        // parallel to the plane
  CHECK_FALSE(c.IntersectIris({V(3, 0, 0), V(0, 0, -1)}, 3.0));  // beyond tMax
}

TEST_CASE("the limbus weight rises smoothly from cornea (0) to sclera (1) between its edges") {
  const AnteriorChamber<double> c;
  CHECK(c.LimbusWeight(0) == 0);
  CHECK(c.LimbusWeight(11.64 / 2) == 0);
  CHECK(c.LimbusWeight(12.89 / 2) == 1);
  CHECK(c.LimbusWeight(7.54) == 1);
  CHECK(c.LimbusWeight((11.64 + 12.89) / 4) == Approx(0.5));
  double prev = 0;
  for (double r = 5.8; r < 6.5; r += 1e-3) {
    CHECK(c.LimbusWeight(r) >= prev);
    prev = c.LimbusWeight(r);
  }
}

TEST_CASE("out-of-range chamber parameters are reported by name") {
  auto message = [](auto edit) {
    ChamberParams p;
    edit(p);
    return ValidateChamberParams(p);
  };
  CHECK(ValidateChamberParams({}).empty());
  CHECK_THAT(message([](ChamberParams& p) { p.irisDepth = -1; }), Catch::Contains("irisDepth"));
  CHECK_THAT(message([](ChamberParams& p) { p.limbusInnerRatio = 0.9; }), Catch::Contains("limbusInnerRatio"));
  CHECK_THAT(message([](ChamberParams& p) { p.limbusOuterRatio = 1.5; }), Catch::Contains("limbusOuterRatio"));
  CHECK_THAT(message([](ChamberParams& p) { p.corneaIor = 0.9; }), Catch::Contains("corneaIor"));
  CHECK_THAT(message([](ChamberParams& p) { p.irisDepth = std::nan(""); }), Catch::Contains("irisDepth"));
  CHECK_THAT(message([](ChamberParams& p) { p.pupilDiameter = 20; }), Catch::Contains("pupilDiameter"));
}
