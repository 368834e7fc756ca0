// Rigid transform interpolation over the shutter (params/motion.h): decomposition, slerp edge cases, bad samples,
// Embree's time steps.
#include "hdeye/params/motion.h"

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <limits>

using namespace hdeye;

namespace {

constexpr double kPi = 3.14159265358979323846;

Matrix4d Trs(const glm::dvec3& t, double angle, const glm::dvec3& axis, const glm::dvec3& scale) {
  return glm::translate(Matrix4d(1.0), t) * glm::rotate(Matrix4d(1.0), angle, axis) * glm::scale(Matrix4d(1.0), scale);
}

double MaxDifference(const Matrix4d& a, const Matrix4d& b) {
  double d = 0;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) d = std::max(d, std::abs(a[c][r] - b[c][r]));
  return d;
}

/// The angle (radians) of the rotation a transform's x axis makes about +z.
double AngleAboutZ(const Matrix4d& m) { return std::atan2(m[0][1], m[0][0]); }

}  // namespace

TEST_CASE("a transform decomposes into translation, rotation and upper-triangular stretch and composes back",
          "[motion]") {
  const Matrix4d trs = Trs({1, -2, 3}, 0.7, glm::normalize(glm::dvec3(1, 2, -1)), {2, 0.5, 3});
  Matrix4d sheared = trs;
  sheared[1] += 0.3 * sheared[0];  // a shear
  const Matrix4d mirrored = trs * glm::scale(Matrix4d(1.0), glm::dvec3(-1, 1, 1));
  for (const Matrix4d& m : {trs, sheared, mirrored}) {
    const auto parts = DecomposeTransform(m);
    REQUIRE(parts);
    INFO("round trip error " << MaxDifference(ComposeTransform(*parts), m));
    CHECK(MaxDifference(ComposeTransform(*parts), m) < 1e-12);
    CHECK(std::abs(glm::length(parts->rotation) - 1) < 1e-12);
    CHECK(parts->stretch[0][1] == 0);
    CHECK(parts->stretch[0][2] == 0);
    CHECK(parts->stretch[1][2] == 0);
  }
  // Translate-rotate-scale: the stretch is the scale itself (the polar decomposition's).
  const auto parts = DecomposeTransform(trs);
  CHECK(std::abs(parts->stretch[0][0] - 2) < 1e-12);
  CHECK(std::abs(parts->stretch[1][1] - 0.5) < 1e-12);
  CHECK(std::abs(parts->stretch[2][2] - 3) < 1e-12);
  CHECK(std::abs(parts->stretch[1][0]) < 1e-12);
  // A mirror keeps a proper rotation and puts the reflection into the last scale.
  CHECK(DecomposeTransform(mirrored)->stretch[2][2] < 0);
  // Singular and non-finite matrices have no decomposition.
  CHECK_FALSE(DecomposeTransform(glm::scale(Matrix4d(1.0), glm::dvec3(1, 0, 1))));
  Matrix4d nan(1.0);
  nan[2][1] = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(DecomposeTransform(nan));
}

TEST_CASE("a rotation interpolates at constant angular speed, translation and scale linearly", "[motion]") {
  const glm::dvec3 z(0, 0, 1);
  const TimeSampled<Matrix4d> samples{{-0.5f, 0.5f},
                                      {Trs({0, 0, 0}, 0, z, {1, 1, 1}), Trs({4, 0, 0}, 2.8, z, {3, 3, 3})}};
  const auto motion = MakeTransformMotion(samples, "test", nullptr);
  REQUIRE(motion);
  for (double u : {0.0, 0.1, 0.25, 0.5, 0.9, 1.0}) {
    const Matrix4d m = motion->At(-0.5 + u);
    const double scale = 1 + 2 * u;
    INFO("u " << u << ": angle " << AngleAboutZ(m) << " scale " << glm::length(glm::dvec3(m[0])) << " x " << m[3][0]);
    CHECK(std::abs(AngleAboutZ(m) - 2.8 * u) < 1e-12);
    CHECK(std::abs(glm::length(glm::dvec3(m[0])) - scale) < 1e-12);
    CHECK(std::abs(m[3][0] - 4 * u) < 1e-12);
  }
  // Clamped outside the samples.
  CHECK(MaxDifference(motion->At(-3), samples.values[0]) < 1e-12);
  CHECK(MaxDifference(motion->At(7), samples.values[1]) < 1e-12);
}

TEST_CASE("a half turn interpolates through a quarter turn about the same axis, never through a shrunk matrix",
          "[motion]") {
  const glm::dvec3 z(0, 0, 1);
  const auto motion = MakeTransformMotion(
      {{0.0f, 1.0f}, {Trs({0, 0, 0}, 0, z, {2, 2, 2}), Trs({0, 0, 0}, kPi, z, {2, 2, 2})}}, "t", nullptr);
  REQUIRE(motion);
  const Matrix4d half = motion->At(0.5);
  const glm::dmat3 linear(half);
  INFO("angle at the middle " << AngleAboutZ(half) << ", det " << glm::determinant(linear));
  CHECK(std::abs(std::abs(AngleAboutZ(half)) - kPi / 2) < 1e-12);
  CHECK(std::abs(glm::determinant(linear) - 8) < 1e-9);  // scale 2 kept: a matrix lerp would give 0 here
  CHECK(std::abs(half[2][2] - 2) < 1e-12);               // the axis stays put
  // Identical samples: the transform does not move at all (no 0/0 in the slerp).
  const Matrix4d m = Trs({1, 2, 3}, 1.1, glm::normalize(glm::dvec3(1, 1, 0)), {1, 2, 3});
  const auto still = MakeTransformMotion({{0.0f, 0.5f, 1.0f}, {m, m, m}}, "t", nullptr);
  REQUIRE(still);
  for (double t : {0.0, 0.3, 0.75, 1.0}) CHECK(MaxDifference(still->At(t), m) < 1e-12);
  // q and -q are one rotation: the interpolation takes the short way whichever sign a sample's quaternion has.
  const auto near = MakeTransformMotion(
      {{0.0f, 1.0f}, {Trs({0, 0, 0}, 3.0, z, {1, 1, 1}), Trs({0, 0, 0}, -3.0, z, {1, 1, 1})}}, "t", nullptr);
  const double mid = AngleAboutZ(near->At(0.5));
  INFO("3 rad to -3 rad: middle at " << mid);
  CHECK(std::abs(std::abs(mid) - kPi) < 1e-9);  // through pi (0.28 rad of turn), not through 0 (6 rad)
}

TEST_CASE("bad motion samples are skipped with one warning each: NaN, singular, a mirror flip, times out of order",
          "[motion]") {
  const Matrix4d a(1.0), b = Trs({1, 0, 0}, 0.2, {0, 0, 1}, {1, 1, 1});
  Matrix4d nan(1.0);
  nan[3][0] = std::numeric_limits<double>::quiet_NaN();
  const Matrix4d singular = glm::scale(Matrix4d(1.0), glm::dvec3(0, 1, 1));
  const Matrix4d mirror = glm::scale(Matrix4d(1.0), glm::dvec3(-1, 1, 1));
  std::vector<std::string> warnings;
  const auto motion = MakeTransformMotion(
      {{0.0f, 0.1f, 0.2f, 0.3f, 0.5f, 0.4f, 1.0f}, {a, nan, singular, mirror, b, b, b}}, "mesh /M", &warnings);
  REQUIRE(motion);
  CHECK(motion->times == std::vector<double>{0.0, 0.5, 1.0});
  REQUIRE(warnings.size() == 4);
  for (const std::string& w : warnings) CHECK(w.rfind("mesh /M: ", 0) == 0);
  CHECK(warnings[0].find("non-finite or singular") != std::string::npos);
  CHECK(warnings[2].find("mirrors") != std::string::npos);
  CHECK(warnings[3].find("not after") != std::string::npos);
  // A mirror throughout is a consistent motion and keeps its handedness.
  const auto mirrored = MakeTransformMotion({{0.0f, 1.0f}, {mirror, b * mirror}}, "t", &warnings);
  REQUIRE(mirrored);
  CHECK(mirrored->times.size() == 2);
  CHECK(glm::determinant(glm::dmat3(mirrored->At(0.5))) < 0);
  // Nothing usable: no motion.
  CHECK_FALSE(MakeTransformMotion({{0.0f}, {nan}}, "t", nullptr));
}

TEST_CASE("Embree's motion steps: uniform authored times are kept, others resampled finer than their smallest gap",
          "[motion]") {
  CHECK(MotionStepTimes({-0.25, 0, 0.25}, -0.25, 0.25) == std::vector<double>{-0.25, 0, 0.25});
  // Samples outside the shutter only shape the ends.
  CHECK(MotionStepTimes({-1, 1}, -0.25, 0.25) == std::vector<double>{-0.25, 0.25});
  // Non-uniform: smallest gap 0.05 over a 0.5 shutter gives 11 steps.
  const std::vector<double> steps = MotionStepTimes({-0.25, -0.2, 0.25}, -0.25, 0.25);
  REQUIRE(steps.size() == 11);
  CHECK(steps.front() == -0.25);
  CHECK(steps.back() == 0.25);
  CHECK(std::abs(steps[1] - -0.2) < 1e-12);
  // Capped: very close samples do not make hundreds of steps.
  CHECK(MotionStepTimes({-0.5, -0.4999, 0.5}, -0.5, 0.5).size() == std::size_t(kMaxMotionSteps));
  // A closed shutter or one sample: one step.
  CHECK(MotionStepTimes({-1, 1}, 0, 0).size() == 1);
  CHECK(MotionStepTimes({0}, -0.5, 0.5).size() == 1);
}
