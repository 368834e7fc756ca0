// Properties of the surface models and of ray intersection over large random sets, both precisions.
#include "eyelib/anterior_surface.h"
#include "reference_intersection.h"
#include "sampling_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <random>

using namespace eyelib;
using V = Vec3<double>;

namespace {
const CorneaModel kModels[] = {CorneaModel::EllipsoidCone, CorneaModel::Paraboloid};

/// Distance from p to the surface along z, times the normal's z: the first-order distance to the surface.
double SurfaceResidual(const AnteriorSurface<double>& s, const V& p) {
  const double r = std::sqrt(p.x * p.x + p.y * p.y);
  return std::abs(p.z - s.Sag(r)) * s.Normal(p.x, p.y).z;
}
}  // namespace

TEST_CASE("slope, curvature and height derivatives agree with finite differences") {
  for (CorneaModel model : kModels) {
    const AnteriorSurface<double> s(model);
    std::mt19937_64 rng(3);
    for (int i = 0; i < 2000; ++i) {
      const double r = test::Uniform(rng, 0.01, 7.5), phi = test::Uniform(rng, 0, 6.283);
      if (std::abs(r - s.JunctionRadius()) < 1e-3) continue;  // the kink has no derivative
      const double x = r * std::cos(phi), y = r * std::sin(phi), h = 1e-6;
      INFO(ToString(model) << " r = " << r);
      CHECK(s.Slope(r) == Approx((s.Sag(r + h) - s.Sag(r - h)) / (2 * h)).margin(1e-8));
      CHECK(s.SecondDerivative(r) == Approx((s.Slope(r + h) - s.Slope(r - h)) / (2 * h)).margin(1e-6));
      const auto d = s.Height(x, y);
      const auto dxp = s.Height(x + h, y), dxm = s.Height(x - h, y), dyp = s.Height(x, y + h);
      const auto dym = s.Height(x, y - h);
      CHECK(d.hx == Approx((dxp.h - dxm.h) / (2 * h)).margin(1e-8));
      CHECK(d.hy == Approx((dyp.h - dym.h) / (2 * h)).margin(1e-8));
      CHECK(d.hxx == Approx((dxp.hx - dxm.hx) / (2 * h)).margin(1e-6));
      CHECK(d.hxy == Approx((dyp.hx - dym.hx) / (2 * h)).margin(1e-6));
      CHECK(d.hyy == Approx((dyp.hy - dym.hy) / (2 * h)).margin(1e-6));
      const V n = s.Normal(x, y);
      CHECK(glm::dot(n, V(-d.hx, -d.hy, 1)) == Approx(glm::length(V(-d.hx, -d.hy, 1))).epsilon(1e-12));
    }
  }
}

TEST_CASE("every hit lies on the surface, inside the rim, with a unit outward normal (1M rays)") {
  std::printf("\n  model          | prec   | rays   | hits   | worst residual (mm) | worst |n|-1\n");
  for (CorneaModel model : kModels) {
    const AnteriorSurface<double> sd(model);
    const AnteriorSurface<float> sf(model);
    std::mt19937_64 rng(5);
    double worstD = 0, worstF = 0, worstNormD = 0, worstNormF = 0;
    int hitsD = 0, hitsF = 0;
    const int n = 500000;
    for (int i = 0; i < n; ++i) {
      // Origins anywhere within 30 mm of the eye, including inside the chamber; half the rays aimed
      // at the cap, half in any direction.
      const V o = V(test::Uniform(rng, -30, 30), test::Uniform(rng, -30, 30), test::Uniform(rng, -25, 30));
      const V aim(test::Uniform(rng, -8, 8), test::Uniform(rng, -8, 8), test::Uniform(rng, -4, 0.5));
      const V d = (i % 2) ? glm::normalize(aim - o) : test::UniformSphere(rng);
      if (auto hit = sd.Intersect({o, d})) {
        ++hitsD;
        REQUIRE(RadiusSquared(hit->point) <= 7.54 * 7.54);
        worstD = std::max(worstD, SurfaceResidual(sd, hit->point));
        worstNormD = std::max(worstNormD, std::abs(glm::length(hit->normal) - 1));
        CHECK(glm::length(hit->normal - sd.Normal(hit->point.x, hit->point.y)) < 1e-9);
        CHECK(glm::length(o + hit->t * d - hit->point) < 1e-12 * (1 + glm::length(o)));
      }
      const Vec3<float> of = test::RoundTo<float>(o), df = test::RoundTo<float>(d);
      if (auto hit = sf.Intersect({of, df})) {
        ++hitsF;
        worstF = std::max(worstF, SurfaceResidual(sd, V(hit->point)));
        worstNormF = std::max(worstNormF, double(std::abs(glm::length(hit->normal) - 1)));
      }
    }
    std::printf("  %-14s | double | %6d | %6d | %19.3g | %.2g\n", ToString(model), n, hitsD, worstD, worstNormD);
    std::printf("  %-14s | float  | %6d | %6d | %19.3g | %.2g\n", ToString(model), n, hitsF, worstF, worstNormF);
    CHECK(hitsD > n / 5);
    CHECK(worstD < 1e-13);
    CHECK(worstF < 1e-5);  // ~ a few ulps of the 30 mm origin the hit is computed from
    CHECK(worstNormD < 1e-15);
    CHECK(worstNormF < 1e-6);
    CHECK(std::abs(hitsF - hitsD) < n / 10000);  // float disagrees on hit/miss only at the ill-conditioned fringe
  }
}

TEST_CASE("the analytic hit agrees with an independent bisection reference on random rays") {
  for (CorneaModel model : kModels) {
    const AnteriorSurface<double> s(model);
    std::mt19937_64 rng(9);
    double worst = 0;
    int mismatches = 0;
    for (int i = 0; i < 20000; ++i) {
      const V o = V(test::Uniform(rng, -20, 20), test::Uniform(rng, -20, 20), test::Uniform(rng, -15, 20));
      const V d = test::UniformSphere(rng);
      const auto ref = test::ReferenceIntersect(model, o, d);
      const auto hit = s.Intersect({o, d});
      if (ref.ambiguous) continue;
      if (bool(hit) != ref.hit) {
        ++mismatches;
        continue;
      }
      if (hit) worst = std::max(worst, glm::length(hit->point - ref.point));
    }
    INFO(ToString(model) << ": mismatches " << mismatches << ", worst distance to reference " << worst << " mm");
    CHECK(mismatches == 0);
    CHECK(worst < 1e-11);
  }
}
