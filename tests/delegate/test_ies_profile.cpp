// IES LM-63 profiles: the parser's formats and refusals, the lookup's symmetry cases and interpolation, and the
// mean intensity shaping:ies:normalize divides by, against closed forms. Files are authored in the tests.
#include "hdeye/params/iesProfile.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// An LM-63 file: `header` (the format line and keywords), TILT=NONE, then the numbers.
std::string IesText(const std::string& header, const std::string& angles, const std::string& values, int nv, int nh,
                    double multiplier = 1, int type = 1) {
  return header + "TILT=NONE\n1 -1 " + std::to_string(multiplier) + " " + std::to_string(nv) + " " +
         std::to_string(nh) + " " + std::to_string(type) + " 2 0.1 0.1 0.0\n1.0 1.0 60\n" + angles + "\n" + values +
         "\n";
}

const std::string k2002 = "IESNA:LM-63-2002\n[TEST] authored in test_ies_profile\n[MANUFAC] none\n";
const std::string k1995 = "IESNA:LM-63-1995\n[TEST] authored\n";

std::string ParseError(const std::string& text) {
  try {
    ParseIes(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("an LM-63-2002 file parses: angles, candela times the multiplier, numbers across lines and commas ",
          "[ies]") {
  const IesProfile p = ParseIes(IesText(k2002, "0 45 90\n0", "100, 50\n  10", 3, 1, 2.0));
  REQUIRE(p.vertical.size() == 3);
  REQUIRE(p.horizontal.size() == 1);
  CHECK(p.candela[0] == Approx(200));
  CHECK(p.candela[1] == Approx(100));
  CHECK(p.candela[2] == Approx(20));
  CHECK(p.Intensity(0, 0) == Approx(200));
  CHECK(p.Intensity(22.5, 123) == Approx(150));  // linear between knots; rotationally symmetric
  CHECK(p.Intensity(90, 0) == Approx(20));
  CHECK(p.Intensity(90.5, 0) == 0);  // past the web's vertical range
}

TEST_CASE("an LM-63-1995 file and one without a format line parse alike ", "[ies]") {
  const std::string angles = "0 90 180\n0 90", values = "10 20 30\n40 50 60";
  const IesProfile a = ParseIes(IesText(k1995, angles, values, 3, 2));
  const IesProfile b = ParseIes(IesText("", angles, values, 3, 2));
  REQUIRE(a.candela == b.candela);
  CHECK(a.Intensity(90, 90) == Approx(50));
  CHECK(a.Intensity(90, 45) == Approx(35));
}

TEST_CASE("files the renderer cannot use are refused with their reason ", "[ies]") {
  const std::string ok = "0 90\n0";
  CHECK_THAT(ParseError("IESNA:LM-63-2002\n1 2 3\n"), Catch::Contains("no TILT"));
  std::string tilted = IesText(k2002, ok, "1 1", 2, 1);
  tilted.replace(tilted.find("TILT=NONE"), 9, "TILT=INCLUDE");
  CHECK_THAT(ParseError(tilted), Catch::Contains("TILT=INCLUDE"));
  CHECK_THAT(ParseError(IesText(k2002, ok, "1 1", 2, 1, 1, 2)), Catch::Contains("type B"));
  CHECK_THAT(ParseError(IesText(k2002, "0 90\n0", "1", 2, 1)), Catch::Contains("ends before"));  // truncated
  CHECK_THAT(ParseError(IesText(k2002, "90 0\n0", "1 1", 2, 1)), Catch::Contains("not ascending"));
  CHECK_THAT(ParseError(IesText(k2002, "0 200\n0", "1 1", 2, 1)), Catch::Contains("outside"));
  CHECK_THAT(ParseError(IesText(k2002, ok, "1 -1", 2, 1)), Catch::Contains("negative"));
  CHECK_THAT(ParseError(IesText(k2002, "0 90\n0 45", "1 1 1 1", 2, 2)), Catch::Contains("none of LM-63"));
  CHECK_THAT(ParseError(IesText(k2002, ok, "1 x", 2, 1)), Catch::Contains("not a number"));
  std::string huge = IesText(k2002, ok, "1 1", 2, 1);
  huge.replace(huge.find(" 2 1 1 2"), 8, " 99999 99999 1 2");
  CHECK_THAT(ParseError(huge), Catch::Contains("too many"));
}

TEST_CASE("the horizontal sets' symmetries: 0-90 mirrors each quadrant, 0-180 and 90-270 mirror a plane ", "[ies]") {
  // Intensity rising with the horizontal angle, so every fold shows.
  const IesProfile quadrant = ParseIes(IesText(k2002, "0 90\n0 45 90", "0 0 10 10 20 20", 2, 3));
  for (double phi : {10.0, 30.0, 80.0}) {
    CHECK(quadrant.Intensity(0, phi) == Approx(phi * 20 / 90));
    CHECK(quadrant.Intensity(0, 180 - phi) == Approx(phi * 20 / 90));
    CHECK(quadrant.Intensity(0, 180 + phi) == Approx(phi * 20 / 90));
    CHECK(quadrant.Intensity(0, 360 - phi) == Approx(phi * 20 / 90));
    CHECK(quadrant.Intensity(0, -phi) == Approx(phi * 20 / 90));
  }
  const IesProfile half = ParseIes(IesText(k2002, "0 90\n0 90 180", "0 0 10 10 20 20", 2, 3));
  CHECK(half.Intensity(0, 135) == Approx(15));
  CHECK(half.Intensity(0, 225) == Approx(15));
  CHECK(half.Intensity(0, 300) == Approx(60.0 / 9));
  const IesProfile side = ParseIes(IesText(k2002, "0 90\n90 180 270", "0 0 10 10 20 20", 2, 3));
  CHECK(side.Intensity(0, 135) == Approx(5));
  CHECK(side.Intensity(0, 45) == Approx(5));    // mirrored about the 90-270 plane: 180 - 45
  CHECK(side.Intensity(0, 315) == Approx(15));  // 540 - 315 = 225
  const IesProfile full = ParseIes(IesText(k2002, "0 90\n0 90 180 270 360", "1 1 2 2 3 3 4 4 1 1", 2, 5));
  CHECK(full.Intensity(0, 45) == Approx(1.5));
  CHECK(full.Intensity(0, 315) == Approx(2.5));
  CHECK(full.Intensity(0, 359.999) == Approx(1).epsilon(1e-4));
  CHECK(full.Intensity(0, 360 + 45) == Approx(1.5));
}

TEST_CASE("the mean intensity integrates the bilinear web exactly: hemisphere and sphere closed forms ", "[ies]") {
  // A constant downlight over 0-90: its mean over the hemisphere is the constant.
  const IesProfile down = ParseIes(IesText(k2002, "0 30 60 90\n0", "7 7 7 7", 4, 1));
  CHECK(down.MeanIntensity() == Approx(7));
  // C up to 90 degrees, then linear to 0 at 180: flux 2 pi C (1 + 2 / pi), over 4 pi.
  const double C = 3;
  const IesProfile sphere = ParseIes(IesText(k2002, "0 90 180\n0", "3 3 0", 3, 1));
  const double expected = C * (1 + 2 / kPi) / 2;
  std::printf("mean of C to 90 deg then linear to 0 at 180: %.9f (closed form %.9f)\n", sphere.MeanIntensity(),
              expected);
  CHECK(sphere.MeanIntensity() == Approx(expected).epsilon(1e-12));
  // cos(theta) sampled finely over the hemisphere: mean 1/2 (the linear web's error is of order the step^2).
  std::string angles, values;
  for (int i = 0; i <= 90; ++i) {
    angles += std::to_string(i) + " ";
    values += std::to_string(std::cos(i * kPi / 180)) + " ";
  }
  const IesProfile cosine = ParseIes(IesText(k2002, angles + "\n0", values, 91, 1));
  CHECK(cosine.MeanIntensity() == Approx(0.5).epsilon(1e-4));
  // Horizontal variation averages over the set's range: 0-90 from 2 to 4 linearly, mean 3.
  const IesProfile ramp = ParseIes(IesText(k2002, "0 90\n0 90", "2 2 4 4", 2, 2));
  CHECK(ramp.MeanIntensity() == Approx(3));
}
