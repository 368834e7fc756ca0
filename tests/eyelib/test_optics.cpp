// Fresnel, reflection and refraction: energy, Snell's law, reversibility, total internal reflection.
#include "eyelib/optics.h"
#include "sampling_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace eyelib;
using V = Vec3<double>;

namespace {
// Transmittance from the Fresnel amplitude coefficients and the beam's change of cross-section; an
// independent route to T, so that R + T = 1 is a real check of FresnelDielectric.
double TransmittanceFromAmplitudes(double cosI, double eta) {
  const double sinT2 = (1 - cosI * cosI) / (eta * eta);
  const double cosT = std::sqrt(1 - sinT2);
  const double tPerp = 2 * cosI / (cosI + eta * cosT);
  const double tParl = 2 * cosI / (eta * cosI + cosT);
  const double beam = eta * cosT / cosI;
  return beam * (tPerp * tPerp + tParl * tParl) / 2;
}
}  // namespace

TEST_CASE("R + T = 1 for dielectric Fresnel from both sides, grazing included") {
  double worst = 0;
  for (double eta : {1.0, 1.001, 1.336, 1.376, 1.5, 2.4}) {
    for (int i = 1; i <= 2000; ++i) {
      const double cosI = i / 2000.0;
      const double R = FresnelDielectric(cosI, eta);
      const double T = TransmittanceFromAmplitudes(cosI, eta);
      worst = std::max(worst, std::abs(R + T - 1));
      // From inside, below the critical angle, reciprocity: same R on the way out.
      const double sinT = std::sqrt(1 - cosI * cosI) / eta;
      const double cosT = std::sqrt(1 - sinT * sinT);
      CHECK(FresnelDielectric(-cosT, eta) == Approx(R).margin(1e-12));
    }
  }
  INFO("worst |R + T - 1| = " << worst);
  CHECK(worst < 1e-12);
  CHECK(FresnelDielectric(1.0, 1.376) == Approx(std::pow(0.376 / 2.376, 2)).epsilon(1e-12));
  CHECK(FresnelDielectric(0.0, 1.376) == 1.0);
}

TEST_CASE("Fresnel is 1 beyond the critical angle and never NaN") {
  const double crit = CriticalAngle(1.376);
  CHECK(FresnelDielectric(-std::cos(crit + 1e-9), 1.376) == 1.0);
  CHECK(FresnelDielectric(-std::cos(crit - 1e-6), 1.376) < 1.0);
  for (double c : {-2.0, -1.0, -0.0, 0.0, 1.0, 2.0, 1e-300, -1e-300}) CHECK(std::isfinite(FresnelDielectric(c, 1.376)));
}

TEST_CASE("refraction obeys Snell's law and is reversible, grazing incidence included") {
  std::mt19937_64 rng(7);
  double worstSnell = 0, worstReverse = 0;
  for (int i = 0; i < 100000; ++i) {
    const V n = test::UniformSphere(rng);
    V wi = test::UniformSphere(rng);
    if (glm::dot(wi, n) < 0) wi = -wi;
    if (i % 10 == 0) wi = glm::normalize(wi - (glm::dot(wi, n) - 1e-7) * n);  // 1e-7 rad above grazing
    const double eta = (i % 2) ? 1.376 : 1 / 1.376;
    V wt(0);
    const bool ok = Refract(wi, n, eta, &wt);
    const double sinI = glm::length(glm::cross(wi, n)), sinT = glm::length(glm::cross(wt, n));
    if (eta > 1) REQUIRE(ok);
    if (!ok) {
      CHECK(sinI / eta >= 1 - 1e-12);  // total internal reflection only past the critical angle
      continue;
    }
    CHECK(glm::dot(wt, n) < 0);
    CHECK(std::abs(glm::length(wt) - 1) < 1e-15 * 4);
    worstSnell = std::max(worstSnell, std::abs(sinI - eta * sinT));
    V back(0);
    REQUIRE(Refract(wt, -n, 1 / eta, &back));
    worstReverse = std::max(worstReverse, glm::length(back - wi));
  }
  INFO("worst |sin_i - eta sin_t| = " << worstSnell << ", worst reversal error = " << worstReverse);
  CHECK(worstSnell < 1e-14);
  CHECK(worstReverse < 1e-6);  // grazing reversal is ill-conditioned: |dwi/dwt| ~ 1/cos
}

TEST_CASE("reflection is an involution and preserves the angle to the normal") {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 10000; ++i) {
    const V n = test::UniformSphere(rng), w = test::UniformSphere(rng);
    const V r = Reflect(w, n);
    CHECK(glm::length(Reflect(r, n) - w) < 1e-14);
    CHECK(glm::dot(r, n) == Approx(glm::dot(w, n)).margin(1e-15));
    CHECK(std::abs(glm::length(r) - 1) < 1e-15);
  }
}
