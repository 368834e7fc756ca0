// The renderer's fast sampling helpers (fastTrig.h, sampleDirections.h) against libm and their definitions.
#include "hdeye/render/sampleDirections.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace hdeye;

TEST_CASE("SinCos2Pi and SinCosReduced agree with libm to 1e-13 over the unit interval and plus or minus pi/4",
          "[sampling]") {
  constexpr double kTwoPi = 6.283185307179586477;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0, 1);
  double worst = 0, worstReduced = 0;
  for (int i = 0; i < 200000; ++i) {
    // The quarter turns and their neighbours exactly, then random points.
    const double u = i <= 64 ? i / 64.0 : i <= 128 ? std::nextafter((i - 64) / 64.0, 0.0) : uniform(rng);
    double s, c;
    SinCos2Pi(u, &s, &c);
    REQUIRE(std::isfinite(s));
    REQUIRE(std::isfinite(c));
    worst = std::max({worst, std::abs(s - std::sin(kTwoPi * u)), std::abs(c - std::cos(kTwoPi * u))});
    const double a = (2 * uniform(rng) - 1) * 0.7853981633974483;
    SinCosReduced(a, &s, &c);
    worstReduced = std::max({worstReduced, std::abs(s - std::sin(a)), std::abs(c - std::cos(a))});
  }
  CHECK(worst < 1e-13);
  CHECK(worstReduced < 1e-13);
}

TEST_CASE(
    "eyelib's OrthonormalBasis is orthonormal and right-handed, and the cone and hemisphere samples are unit and "
    "inside",
    "[sampling]") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (int i = 0; i < 100000; ++i) {
    glm::dvec3 n = i == 0 ? glm::dvec3(0, 0, -1) : i == 1 ? glm::dvec3(0, 0, 1) : glm::dvec3(0);
    if (i > 1) n = glm::normalize(glm::dvec3(2 * uniform(rng) - 1, 2 * uniform(rng) - 1, 2 * uniform(rng) - 1));
    glm::dvec3 t, b;
    eyelib::OrthonormalBasis(n, &t, &b);
    REQUIRE(std::abs(glm::length(t) - 1) < 1e-12);
    REQUIRE(std::abs(glm::length(b) - 1) < 1e-12);
    REQUIRE(std::abs(glm::dot(t, n)) < 1e-12);
    REQUIRE(std::abs(glm::dot(b, n)) < 1e-12);
    REQUIRE(std::abs(glm::dot(t, b)) < 1e-12);
    REQUIRE(glm::length(glm::cross(t, b) - n) < 1e-12);
    glm::vec3 tf, bf;  // eyelib's single-precision optics use the same frame
    eyelib::OrthonormalBasis(glm::vec3(n), &tf, &bf);
    REQUIRE(glm::length(glm::cross(tf, bf) - glm::vec3(n)) < 1e-6f);
    REQUIRE(std::abs(glm::dot(tf, bf)) < 1e-6f);
    const double oneMinusCosMax = i % 3 == 0 ? 1e-12 : uniform(rng);
    const glm::dvec3 w = SampleConeAbout(n, oneMinusCosMax, uniform(rng), uniform(rng));
    REQUIRE(std::abs(glm::length(w) - 1) < 1e-12);
    REQUIRE(1 - glm::dot(w, n) <= oneMinusCosMax * (1 + 1e-9) + 1e-15);
    const glm::dvec3 h = CosineHemisphereLocal(uniform(rng), uniform(rng));
    REQUIRE(std::abs(glm::length(h) - 1) < 1e-12);
    REQUIRE(h.z >= 0);
  }
}

TEST_CASE("a cone sample is uniform in solid angle: its mean cosine is 1 - oneMinusCosMax / 2", "[sampling]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uniform(0, 1);
  const glm::dvec3 w = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
  for (double oneMinusCosMax : {0.01, 0.5, 1.5}) {
    double sum = 0;
    constexpr int kSamples = 200000;
    for (int i = 0; i < kSamples; ++i)
      sum += glm::dot(SampleConeAbout(w, oneMinusCosMax, uniform(rng), uniform(rng)), w);
    // Uniform in 1 - cos over [0, m]: variance m^2 / 12, so the mean's standard error is m / sqrt(12 N).
    CHECK(std::abs(sum / kSamples - (1 - oneMinusCosMax / 2)) < 5 * oneMinusCosMax / std::sqrt(12.0 * kSamples));
  }
}
