// The UsdPreviewSurface subset: the BSDF (reciprocity, pdfs, sampling
// weights, energy), the textured dome light (importance sampling and its pdf), and renders that
// must return closed-form answers.
#include "hdeye/hd/renderIndex.h"
#include "hdeye/image/imageWriter.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/previewSurface.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/texture.h"
#include "hdeye/scene/inMemorySceneDelegate.h"
#include "scene_helpers.h"
#include "test_support.h"

#include <eyelib/optics.h>
#include <eyelib/random.h>
#include <eyelib/sampling.h>
#include <unistd.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

using namespace hdeye;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

using test::ErrorOf;
using test::ScratchDir;

}  // namespace

// ---------------------------------------------------------------------------------------------
// The BSDF

namespace {

glm::dvec3 DirectionAt(double cosTheta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
  return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

/// Integrates g(wi) over the upper hemisphere around +z by the midpoint rule in (theta, phi).
double IntegrateHemisphere(const std::function<double(const glm::dvec3&)>& g, int nTheta = 256, int nPhi = 512) {
  double sum = 0;
  for (int i = 0; i < nTheta; ++i) {
    const double theta = (i + 0.5) * (kPi / 2) / nTheta;
    double ring = 0;
    for (int j = 0; j < nPhi; ++j) ring += g(DirectionAt(std::cos(theta), (j + 0.5) * 2 * kPi / nPhi));
    sum += ring * std::sin(theta);
  }
  return sum * (kPi / 2 / nTheta) * (2 * kPi / nPhi);
}

PreviewSurface Surface(glm::dvec3 albedo, double roughness, double metallic, double opacity = 1, double ior = 1.5) {
  PreviewSurface s;
  s.albedo = albedo, s.roughness = roughness, s.metallic = metallic, s.opacity = opacity, s.ior = ior;
  return s;
}

/// s under a clearcoat of the given weight and roughness.
PreviewSurface Coated(PreviewSurface s, double clearcoat, double clearcoatRoughness) {
  s.clearcoat = clearcoat, s.clearcoatRoughness = clearcoatRoughness;
  return s;
}

/// The specular workflow: specularColor replaces metallic and ior.
PreviewSurface SpecularWorkflow(glm::dvec3 albedo, double roughness, glm::dvec3 specularColor) {
  PreviewSurface s = Surface(albedo, roughness, 0);
  s.specularWorkflow = true, s.specularColor = specularColor;
  return s;
}

const glm::dvec3 kUp(0, 0, 1);

/// The surface's directional albedo (red channel) seen from wo, by sampling: the mean BSDF sample weight over
/// n samples (a failed sample counts as 0).
double SampledAlbedo(const PreviewSurface& s, const glm::dvec3& wo, int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs;
    if (SamplePreviewSurface(s, kUp, wo, false, u(rng), u(rng), u(rng), &bs)) sum += bs.weight.x;
  }
  return sum / n;
}

}  // namespace

TEST_CASE("the BSDF is reciprocal and, with ior 1, exactly Lambert", "[bsdf]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.3, -0.2, 0.9));
  for (const PreviewSurface& s :
       {Surface({0.5, 0.3, 0.2}, 0.3, 0), Surface({0.9, 0.6, 0.2}, 0.6, 1),
        Surface({0.7, 0.7, 0.7}, 0.1, 0.4, 0.6, 1.33), Surface({1, 1, 1}, 1, 0.5),
        Coated(Surface({0.5, 0.3, 0.2}, 0.5, 0), 0.8, 0.3), SpecularWorkflow({0.4, 0.5, 0.6}, 0.4, {0.9, 0.5, 0.1})}) {
    for (int i = 0; i < 200; ++i) {
      glm::dvec3 t, b;
      eyelib::OrthonormalBasis(n, &t, &b);
      auto random = [&] {
        const glm::dvec3 l = DirectionAt(u(rng), 2 * kPi * u(rng));
        return l.x * t + l.y * b + l.z * n;
      };
      const glm::dvec3 wo = random(), wi = random();
      const glm::dvec3 f1 = EvalPreviewSurface(s, n, wo, wi), f2 = EvalPreviewSurface(s, n, wi, wo);
      for (int c = 0; c < 3; ++c) {
        INFO("roughness " << s.roughness << " metallic " << s.metallic << " f(wo,wi) " << f1[c] << " f(wi,wo) "
                          << f2[c]);
        REQUIRE(f1[c] == Approx(f2[c]).epsilon(1e-9).margin(1e-12));
      }
    }
  }
  const PreviewSurface lambert = Surface({0.4, 0.5, 0.6}, 0.5, 0, 1, 1.0);
  const glm::dvec3 wo = DirectionAt(0.3, 1), wi = DirectionAt(0.8, 2.5);
  CHECK(EvalPreviewSurface(lambert, kUp, wo, wi).y == Approx(0.5 / kPi).epsilon(1e-12));
  CHECK(PdfPreviewSurface(lambert, kUp, wo, wi) == Approx(0.8 / kPi).epsilon(1e-12));
  CHECK(EvalPreviewSurface(lambert, kUp, wo, -wi) == glm::dvec3(0));  // the opaque part does not transmit
}

TEST_CASE("the BSDF's pdf integrates to the probability that a sample is a non-delta direction above the surface",
          "[bsdf]") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (const PreviewSurface& s :
       {Surface({0.5, 0.5, 0.5}, 0.5, 0, 1, 1.0), Surface({0.5, 0.4, 0.3}, 0.3, 0), Surface({0.9, 0.9, 0.9}, 0.6, 1),
        Surface({1, 1, 1}, 1, 1), Surface({0.6, 0.6, 0.6}, 0.4, 0.5, 0.7, 1.5),
        Coated(Surface({0.5, 0.4, 0.3}, 0.3, 0), 1, 0.5), Coated(Surface({0.5, 0.4, 0.3}, 0.5, 1), 0.5, 0.01),
        SpecularWorkflow({0.5, 0.4, 0.3}, 0.3, {0.2, 0.6, 0.9})}) {
    for (double cosO : {0.9, 0.4, 0.1}) {
      const glm::dvec3 wo = DirectionAt(cosO, 0.3);
      const double integral =
          IntegrateHemisphere([&](const glm::dvec3& wi) { return PdfPreviewSurface(s, kUp, wo, wi); });
      const int n = 100000;
      int smooth = 0;
      for (int i = 0; i < n; ++i) {
        BsdfSample bs;
        if (SamplePreviewSurface(s, kUp, wo, false, u(rng), u(rng), u(rng), &bs) && !bs.delta) ++smooth;
      }
      const double fraction = double(smooth) / n;
      INFO("roughness " << s.roughness << " metallic " << s.metallic << " opacity " << s.opacity << " cos_o " << cosO
                        << ": integral of pdf " << integral << ", fraction of non-delta samples " << fraction);
      CHECK(integral == Approx(fraction).margin(0.006));
      CHECK(integral <= 1.0 + 1e-3);
      if (s.ior == 1.0) CHECK(integral == Approx(1).margin(1e-3));
    }
  }
}

TEST_CASE("a sampled weight is f cos / pdf, and sampling averages to the quadrature albedo", "[bsdf]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (const PreviewSurface& s :
       {Surface({0.5, 0.4, 0.3}, 0.3, 0), Surface({0.9, 0.7, 0.5}, 0.6, 1),
        Surface({0.6, 0.6, 0.6}, 0.2, 0.5, 0.7, 1.5), Surface({0.8, 0.8, 0.8}, 0.15, 0),
        Coated(Surface({0.5, 0.4, 0.3}, 0.6, 0), 1, 0.25), SpecularWorkflow({0.6, 0.5, 0.4}, 0.35, {0.3, 0.5, 0.7})}) {
    for (double cosO : {0.95, 0.5, 0.15}) {
      const glm::dvec3 wo = DirectionAt(cosO, 1.1);
      const int n = 100000;
      glm::dvec3 sum(0);
      for (int i = 0; i < n; ++i) {
        BsdfSample bs;
        if (!SamplePreviewSurface(s, kUp, wo, false, u(rng), u(rng), u(rng), &bs) || bs.delta) continue;
        const double pdf = PdfPreviewSurface(s, kUp, wo, bs.wi);
        const glm::dvec3 expected = EvalPreviewSurface(s, kUp, wo, bs.wi) * (bs.wi.z / pdf);
        REQUIRE(bs.pdf == Approx(pdf).epsilon(1e-9));
        REQUIRE(bs.weight.x == Approx(expected.x).epsilon(1e-9));
        REQUIRE(bs.weight.z == Approx(expected.z).epsilon(1e-9));
        sum += bs.weight;
      }
      const double sampled = sum.y / n;
      const double quadrature = IntegrateHemisphere(
          [&](const glm::dvec3& wi) { return EvalPreviewSurface(s, kUp, wo, wi).y * wi.z; }, 512, 1024);
      INFO("roughness " << s.roughness << " metallic " << s.metallic << " cos_o " << cosO << ": sampled albedo "
                        << sampled << ", quadrature " << quadrature);
      CHECK(sampled == Approx(quadrature).epsilon(0.015));
    }
  }
}

TEST_CASE("white-furnace albedo of a white metal: at most 1, at least 0.9 when smooth", "[bsdf]") {
  std::mt19937_64 rng(5);
  for (double roughness : {0.0, 0.05, 0.2, 0.4, 0.6, 0.8, 1.0}) {
    const PreviewSurface s = Surface({1, 1, 1}, roughness, 1);
    for (double cosO : {1.0, 0.5, 0.2}) {
      const glm::dvec3 wo = DirectionAt(cosO, 0.7);
      const double albedo = SampledAlbedo(s, wo, 50000, rng);
      std::printf("white metal, roughness %.2f, cos_o %.1f: albedo %.4f\n", roughness, cosO, albedo);
      CHECK(albedo <= 1.0 + 1e-9);  // every weight is F G2 / G1 <= 1: no noise allowance needed
      // Single-scattering GGX loses energy with roughness (no multiple-scattering compensation).
      if (roughness <= 0.3) CHECK(albedo >= 0.9);
      // Closed form at alpha = 1, normal incidence: D = 1/pi, G2 = 2 cos_i / (1 + cos_i), so the
      // albedo is the integral of cos_i / (1 + cos_i) over [0, 1], 1 - ln 2.
      if (roughness == 1.0 && cosO == 1.0) CHECK(albedo == Approx(1 - std::log(2.0)).epsilon(0.01));
      if (roughness == 0.0) CHECK(albedo == Approx(1.0).epsilon(1e-12));
    }
  }
  // A mirror has no lobe to light-sample.
  CHECK_FALSE(HasSmoothLobe(Surface({1, 1, 1}, 0, 1), kUp, DirectionAt(0.5, 0)));
  CHECK(HasSmoothLobe(Surface({1, 1, 1}, 0.5, 1), kUp, DirectionAt(0.5, 0)));
}

TEST_CASE("a white dielectric (diffuse under a specular coat) reflects at most what arrives, at every angle",
          "[bsdf]") {
  // By sampling (the weights are f cos / pdf, checked above; quadrature cannot resolve a narrow lobe
  // at grazing incidence). The weights are bounded, so 1% covers the noise of 40000 samples.
  std::mt19937_64 rng(13);
  for (double roughness : {0.0, 0.1, 0.5, 1.0})
    for (double ior : {1.0, 1.5, 3.0})
      for (double cosO : {1.0, 0.5, 0.2, 0.05}) {
        const PreviewSurface s = Surface({1, 1, 1}, roughness, 0, 1, ior);
        const glm::dvec3 wo = DirectionAt(cosO, 0);
        const double albedo = SampledAlbedo(s, wo, 40000, rng);
        INFO("roughness " << roughness << " ior " << ior << " cos_o " << cosO << ": albedo " << albedo);
        CHECK(albedo <= 1.01);
        if (ior == 1.0) CHECK(albedo == Approx(1).margin(1e-9));  // Lambert: every weight is exactly 1
        // Smooth: the coat takes from the diffuse only what it reflects (0.91 at normal incidence for
        // ior 1.5, 0.94-0.98 at grazing). Rough coats lose energy at grazing incidence instead (0.42 at
        // roughness 0.5, cos_o 0.05): the diffuse is dimmed by the smooth-surface Fresnel of the
        // macro normal while the rough lobe reflects less than that. Conservative, not exact.
        if (roughness <= 0.1) CHECK(albedo >= 0.75);
      }
}

TEST_CASE(
    "a clearcoat adds Schlick's 4% white reflection at normal incidence and takes it from what lies below, and "
    "the specular workflow reflects specularColor",
    "[bsdf]") {
  std::mt19937_64 rng(17);
  const glm::dvec3 normal = DirectionAt(1, 0), grazing = DirectionAt(0.2, 0);
  // Over a black, non-reflecting base (ior 1), a mirror coat reflects exactly clearcoat x Schlick(0.04).
  const PreviewSurface black = Surface({0, 0, 0}, 0.5, 0, 1, 1.0);
  for (double c : {1.0, 0.5}) {
    CHECK(SampledAlbedo(Coated(black, c, 0.01), normal, 2000, rng) == Approx(c * 0.04).epsilon(1e-9));
    CHECK(SampledAlbedo(Coated(black, c, 0.01), grazing, 2000, rng) ==
          Approx(c * (0.04 + 0.96 * std::pow(0.8, 5))).epsilon(1e-9));
  }
  // Over a white Lambert base, what the coat reflects is missing below: the sum stays at most 1 at every angle.
  // With a smooth coat at normal incidence it is 0.04 + 0.96 (1 - Fbar), Fbar = 0.04 + 0.96 / 21 the coat's
  // cosine-weighted mean reflectance (the light that reaches the base leaves through the coat too).
  const PreviewSurface white = Surface({1, 1, 1}, 0.5, 0, 1, 1.0);
  for (double roughness : {0.01, 0.3, 0.8})
    for (const glm::dvec3& wo : {normal, grazing}) {
      const double albedo = SampledAlbedo(Coated(white, 1, roughness), wo, 40000, rng);
      INFO("clearcoat roughness " << roughness << " cos_o " << wo.z << ": albedo " << albedo);
      CHECK(albedo <= 1.01);
      if (roughness < 0.1 && wo.z == 1.0) CHECK(albedo == Approx(0.04 + 0.96 * (1 - (0.04 + 0.96 / 21))).margin(0.005));
    }
  // Specular workflow, mirror: the reflection is specularColor at normal incidence, whatever metallic says.
  PreviewSurface mirror = SpecularWorkflow({0, 0, 0}, 0, {0.9, 0.5, 0.1});
  mirror.metallic = 1;
  BsdfSample bs;
  std::uniform_real_distribution<double> u(0, 1);
  glm::dvec3 sum(0);
  const int n = 2000;
  for (int i = 0; i < n; ++i)
    if (SamplePreviewSurface(mirror, kUp, normal, false, u(rng), u(rng), u(rng), &bs)) sum += bs.weight;
  CHECK(sum.x / n == Approx(0.9).epsilon(1e-9));
  CHECK(sum.y / n == Approx(0.5).epsilon(1e-9));
  CHECK(sum.z / n == Approx(0.1).epsilon(1e-9));
  // ... and its diffuse is not dimmed by metallic (kd = 1): with a black specularColor only Schlick's white edge,
  // (1 - c)^5, takes from it.
  const PreviewSurface edge = SpecularWorkflow({0.5, 0.5, 0.5}, 0.5, {0, 0, 0});
  const glm::dvec3 wo = DirectionAt(0.7, 0), wi = DirectionAt(0.4, 2);
  const double specular = EvalPreviewSurface(SpecularWorkflow({0, 0, 0}, 0.5, {0, 0, 0}), kUp, wo, wi).x;
  CHECK(EvalPreviewSurface(edge, kUp, wo, wi).x - specular ==
        Approx(0.5 / kPi * (1 - std::pow(0.3, 5)) * (1 - std::pow(0.6, 5))).epsilon(1e-12));
}

TEST_CASE("glass reflects with the Fresnel probability and refracts with weight 1/eta^2", "[bsdf]") {
  const PreviewSurface glass = Surface({1, 1, 1}, 0.5, 0, 0, 1.5);
  CHECK_FALSE(HasSmoothLobe(glass, kUp, DirectionAt(0.5, 0)));
  for (bool inside : {false, true}) {
    const double cosO = 0.8;
    const double eta = inside ? 1 / 1.5 : 1.5;
    const double fresnel = eyelib::FresnelDielectric(cosO, eta);
    const glm::dvec3 wo = DirectionAt(cosO, 0.2);
    int reflected = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      BsdfSample bs;
      REQUIRE(SamplePreviewSurface(glass, kUp, wo, inside, 0.5, (i + 0.5) / n, 0.5, &bs));
      REQUIRE(bs.delta);
      if (bs.transmitted) {
        REQUIRE(bs.wi.z < 0);
        // Snell: eta sin(theta_t) = sin(theta_o).
        REQUIRE(eta * std::sqrt(1 - bs.wi.z * bs.wi.z) == Approx(std::sqrt(1 - cosO * cosO)).epsilon(1e-9));
        REQUIRE(bs.weight.x == Approx(1 / (eta * eta)).epsilon(1e-12));
      } else {
        REQUIRE(bs.wi.z == Approx(cosO).epsilon(1e-12));
        REQUIRE(bs.weight.x == Approx(1).epsilon(1e-12));
        ++reflected;
      }
    }
    CHECK(double(reflected) / n == Approx(fresnel).margin(1e-3));
  }
  // Beyond the critical angle inside, every sample reflects (total internal reflection).
  BsdfSample bs;
  REQUIRE(SamplePreviewSurface(glass, kUp, DirectionAt(0.3, 0), true, 0.5, 0.999, 0.5, &bs));
  CHECK_FALSE(bs.transmitted);
}

TEST_CASE("the BSDF never returns NaN or infinity, at grazing angles and for mirror-like roughness", "[bsdf]") {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  int samples = 0;
  for (double roughness : {0.0, 0.019, 0.021, 0.05, 1.0})
    for (double metallic : {0.0, 1.0})
      for (double opacity : {0.0, 0.5, 1.0})
        for (double cosO : {1.0, 1e-3, 1e-8, 1e-12, 0.0, -0.1}) {
          const PreviewSurface s =
              Coated(Surface({0.8, 0.5, 0.0}, roughness, metallic, opacity, 1.5), metallic, roughness);
          const glm::dvec3 wo = glm::normalize(DirectionAt(std::abs(cosO), 0.4) * glm::dvec3(1, 1, cosO < 0 ? -1 : 1));
          for (int i = 0; i < 200; ++i) {
            BsdfSample bs;
            if (SamplePreviewSurface(s, kUp, wo, u(rng) < 0.5, u(rng), u(rng), u(rng), &bs)) {
              ++samples;
              REQUIRE(std::isfinite(bs.weight.x + bs.weight.y + bs.weight.z + bs.pdf));
              REQUIRE(glm::length(bs.wi) == Approx(1).epsilon(1e-9));
            }
            const glm::dvec3 wi = DirectionAt(u(rng) < 0.1 ? 1e-10 : u(rng), 2 * kPi * u(rng));
            const glm::dvec3 f = EvalPreviewSurface(s, kUp, wo, wi);
            REQUIRE(std::isfinite(f.x + f.y + f.z + PdfPreviewSurface(s, kUp, wo, wi)));
          }
        }
  CHECK(samples > 10000);
}

// ---------------------------------------------------------------------------------------------
// The textured dome light

namespace {

/// A 64 x 32 lat-long image: a yellow cap above latitude ~72 deg (v > 0.9), red/green/blue bands
/// around longitude +pi/2, 0, -pi/2 (u = 0.25, 0.5, 0.75), grey elsewhere, and a bright spot.
std::shared_ptr<const Texture> TestDomeImage() {
  const int w = 64, h = 32;
  std::vector<float> r(w * h, 0.2f), g(w * h, 0.2f), b(w * h, 0.2f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = (x + 0.5) / w, v = 1 - (y + 0.5) / h;
      glm::vec3 c(0.2f);
      if (v > 0.9)
        c = {1, 1, 0};
      else if (std::abs(u - 0.25) < 0.05)
        c = {1, 0, 0};
      else if (std::abs(u - 0.5) < 0.05)
        c = {0, 1, 0};
      else if (std::abs(u - 0.75) < 0.05)
        c = {0, 0, 1};
      if (x == 40 && y == 20) c = glm::vec3(500);
      const std::size_t i = std::size_t(y) * w + x;
      r[i] = c.r, g[i] = c.g, b[i] = c.b;
    }
  static const std::string path = [&] {
    const std::string p =
        (fs::temp_directory_path() / ("hdeye_test_dome_" + std::to_string(getpid()) + ".exr")).string();
    WriteExr(p, w, h, {{"R", r}, {"G", g}, {"B", b}});
    return p;
  }();
  return Texture::Open(TextureParams::Image(path, TextureWrap::Clamp));
}

RenderLight TexturedDome(const glm::dmat4& transform) {
  LightParams p;
  p.type = LightType::Dome;
  p.textureFile = "in-memory";  // any name: FromParams uses the prebuilt DomeTexture
  p.intensity = 2;
  p.exposure = 1;
  return RenderLight::FromParams(p, transform, DomeTexture::Build(TestDomeImage()));
}

glm::dvec3 DomeRadiance(const RenderLight& l, const glm::dvec3& dir, double* pdf = nullptr) {
  glm::dvec3 radiance(0);
  double p = 0, distance = 0;
  REQUIRE(IntersectLight(l, glm::dvec3(0), dir, std::numeric_limits<double>::infinity(), &radiance, &p, &distance));
  if (pdf) *pdf = p;
  return radiance;
}

}  // namespace

TEST_CASE("the dome's lat-long image follows UsdLux: +y at the top row, +z at u = 0.5, +x at u = 0.25", "[dome]") {
  const RenderLight dome = TexturedDome(glm::dmat4(1.0));
  const double scale = 2 * 2;  // intensity 2 x 2^exposure 1
  CHECK(DomeRadiance(dome, {0, 1, 0}) == scale * glm::dvec3(1, 1, 0));
  CHECK(DomeRadiance(dome, {1, 0, 0}) == scale * glm::dvec3(1, 0, 0));
  CHECK(DomeRadiance(dome, {0, 0, 1}) == scale * glm::dvec3(0, 1, 0));
  CHECK(DomeRadiance(dome, {-1, 0, 0}) == scale * glm::dvec3(0, 0, 1));
  CHECK(DomeRadiance(dome, {0, -1, 0}) == scale * glm::dvec3(0, 1, 0));  // the bands run to the -y pole
  CHECK(DomeRadiance(dome, glm::normalize(glm::dvec3(-1, -0.2, -1))) == scale * glm::dvec3(glm::vec3(0.2f)));
  // The light's transform rotates the dome: 90 deg about x takes its +y pole to world +z.
  const RenderLight rotated = TexturedDome(
      glm::dmat4(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, 0, 1, 0), glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, 0, 1)));
  CHECK(DomeRadiance(rotated, {0, 0, 1}) == scale * glm::dvec3(1, 1, 0));
  CHECK(DomeRadiance(rotated, {1, 0, 0}) == scale * glm::dvec3(1, 0, 0));
  CHECK(DomeRadiance(rotated, {0, -1, 0}) == scale * glm::dvec3(0, 1, 0));
}

TEST_CASE("dome importance sampling: the pdf integrates to 1 and SampleLight's pdf is IntersectLight's", "[dome]") {
  const glm::dmat4 tilt = glm::dmat4(glm::dvec4(0.8, 0.6, 0, 0), glm::dvec4(-0.6, 0.8, 0, 0), glm::dvec4(0, 0, 1, 0),
                                     glm::dvec4(5, 6, 7, 1));
  const RenderLight dome = TexturedDome(tilt);
  // Integral of the pdf (and of the radiance) over the sphere, by the midpoint rule.
  const int nTheta = 1024, nPhi = 2048;
  double pdfIntegral = 0, power = 0;
  for (int i = 0; i < nTheta; ++i) {
    const double theta = (i + 0.5) * kPi / nTheta;
    for (int j = 0; j < nPhi; ++j) {
      const double phi = (j + 0.5) * 2 * kPi / nPhi;
      double pdf = 0;
      const glm::dvec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      const glm::dvec3 radiance = DomeRadiance(dome, dir, &pdf);
      pdfIntegral += pdf * std::sin(theta);
      power += radiance.x * std::sin(theta);
    }
  }
  const double dOmega = (kPi / nTheta) * (2 * kPi / nPhi);
  pdfIntegral *= dOmega, power *= dOmega;
  std::printf("textured dome: integral of pdf %.5f\n", pdfIntegral);
  CHECK(pdfIntegral == Approx(1).margin(3e-3));

  // Samples: their pdf is the one IntersectLight gives, and radiance / pdf averages to the power.
  const int n = 200000;
  double estimate = 0;
  for (int k = 0; k < n; ++k) {
    const LightSample s =
        SampleLight(dome, glm::dvec3(1, 2, 3), eyelib::UniformAt(1, 0, 2 * k), eyelib::UniformAt(1, 0, 2 * k + 1));
    REQUIRE(s.pdf > 0);
    REQUIRE(std::isinf(s.distance));
    double pdf = 0;
    const glm::dvec3 radiance = DomeRadiance(dome, s.dir, &pdf);
    REQUIRE(pdf == Approx(s.pdf).epsilon(1e-6));
    REQUIRE(radiance.x == Approx(s.radiance.x).epsilon(1e-5).margin(1e-9));
    estimate += s.radiance.x / s.pdf;
  }
  estimate /= n;
  std::printf("textured dome: integral of radiance %.4f by quadrature, %.4f by importance sampling\n", power, estimate);
  CHECK(estimate == Approx(power).epsilon(0.01));
}

// ---------------------------------------------------------------------------------------------
// Materials through the delegate, and renders

namespace {

struct Scene : test::RenderStack {
  RenderStats Render() { return pass.Execute("/cam", {{"color", "/color"}}); }
};

/// Mean of channel c over pixels whose alpha is exactly `alpha`.
double MeanWhereAlpha(const RenderBuffer& b, float alpha, int c, int* count) {
  double sum = 0;
  *count = 0;
  for (int y = 0; y < b.Height(); ++y)
    for (int x = 0; x < b.Width(); ++x)
      if (b.Resolved(x, y, 3) == alpha) sum += b.Resolved(x, y, c), ++*count;
  return *count ? sum / *count : 0;
}

}  // namespace

TEST_CASE("material parameters out of range are reported with the prim and the attribute", "[material]") {
  Scene s;
  MeshTopology quad;
  std::vector<Vec3f> points;
  test::Quad(1, &quad, &points);
  s.scene.AddMaterial("/mat", MaterialParams{});
  s.scene.AddMesh("/quad", quad, points, Matrix4d(1.0), "/mat");
  s.scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(4));
  s.scene.AddRenderBuffer("/color", 4, 4, 4);
  s.delegate.Settings().samplesPerPixel = 1;
  CHECK_NOTHROW(s.Render());
  auto expectError = [&](const std::function<void(MaterialParams&)>& edit, const std::string& attribute) {
    MaterialParams m;
    edit(m);
    s.scene.SetMaterialParams("/mat", m);
    const std::string e = ErrorOf([&] { s.Render(); });
    INFO(e);
    CHECK_THAT(e, Catch::Contains("material /mat") && Catch::Contains(attribute));
    CHECK(e.find('\n') == std::string::npos);
  };
  expectError([](MaterialParams& m) { m.roughness = 1.5f; }, "roughness");
  expectError([](MaterialParams& m) { m.metallic = -0.1f; }, "metallic");
  expectError([](MaterialParams& m) { m.opacity = NAN; }, "opacity");
  expectError([](MaterialParams& m) { m.ior = 0.9f; }, "ior");
  expectError([](MaterialParams& m) { m.diffuseColor.g = -1; }, "diffuseColor");
  expectError([](MaterialParams& m) { m.emissiveColor.b = INFINITY; }, "emissiveColor");
  expectError([](MaterialParams& m) { m.opacityThreshold = 2; }, "opacityThreshold");
  // A texture that cannot be read is no error: one warning naming the material and the file.
  MaterialParams missing;
  missing.Texture(MaterialInput::DiffuseColor).texture.file = "/nonexistent/albedo.png";
  s.scene.SetMaterialParams("/mat", missing);
  CHECK_NOTHROW(s.Render());
  const std::vector<std::string> warnings = s.delegate.GetRenderParam()->Warnings();
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("material /mat") && Catch::Contains("/nonexistent/albedo.png"));
  MaterialParams bright;
  bright.emissiveColor = {5, 5, 5};  // emission may exceed 1
  s.scene.SetMaterialParams("/mat", bright);
  CHECK_NOTHROW(s.Render());
}

TEST_CASE("glass furnace: a glass sphere in a uniform white dome returns the dome", "[render]") {
  Scene s;
  MeshTopology topology;
  std::vector<Vec3f> points;
  test::UvSphere(1, 24, 48, &topology, &points);
  MaterialParams glass;
  glass.opacity = 0;
  glass.ior = 1.5f;
  s.scene.AddMaterial("/glass", glass);
  s.scene.AddMesh("/ball", topology, points, Matrix4d(1.0), "/glass");
  LightParams dome;
  dome.type = LightType::Dome;
  s.scene.AddLight("/dome", primTypes::kDomeLight, dome);
  s.scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(4));
  s.scene.AddRenderBuffer("/color", 16, 16, 4);
  s.delegate.Settings().samplesPerPixel = 32;
  s.delegate.Settings().maxDepth = 32;
  const RenderStats stats = s.Render();
  int n = 0;
  const double mean = MeanWhereAlpha(s.Buffer("/color"), 1, 0, &n);
  std::printf("glass furnace: %.5f over %d pixels (%.2f s)\n", mean, n, stats.seconds);
  CHECK(n > 40);
  CHECK(stats.nonFiniteSamples == 0);
  CHECK(mean == Approx(1).epsilon(0.02));
}

TEST_CASE("a white diffuse plane under a textured dome lit above the horizon returns albedo x dome, MIS on and off",
          "[render]") {
  // The dome image is 1 above its equator and 0 below; rotated 90 deg about x, its +y pole is world
  // +z, the plane's normal. The plane sees exactly the lit half: radiance = albedo x colour x
  // intensity x 2^exposure, less the half-texel bilinear blend at the horizon (delta^2 / 6 of it,
  // delta = pi / (2 h): 1e-4 here). Seed-to-seed noise at 1024 samples: about 0.4% (MIS off), 0.1% (on).
  ScratchDir dir;
  const int w = 128, h = 64;
  std::vector<float> r(w * h), g(w * h), b(w * h);
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w; ++x) r[y * w + x] = g[y * w + x] = b[y * w + x] = 1;
  WriteExr(dir / "sky.exr", w, h, {{"R", r}, {"G", g}, {"B", b}});
  const double albedo = 0.5, expected = albedo * 0.5 * 2 * 2;  // colour 0.5, intensity 2, exposure 1
  double results[2];
  for (int mis = 0; mis < 2; ++mis) {
    Scene s;
    MeshTopology plane;
    std::vector<Vec3f> points;
    test::Quad(10, &plane, &points);
    MaterialParams m;
    m.diffuseColor = glm::vec3(float(albedo));
    m.ior = 1;  // pure Lambert
    s.scene.AddMaterial("/mat", m);
    s.scene.AddMesh("/floor", plane, points, Matrix4d(1.0), "/mat");
    LightParams sky;
    sky.type = LightType::Dome;
    sky.textureFile = dir / "sky.exr";
    sky.color = glm::vec3(0.5f);
    sky.intensity = 2;
    sky.exposure = 1;
    const Matrix4d rotateX90(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, 0, 1, 0), glm::dvec4(0, -1, 0, 0),
                             glm::dvec4(0, 0, 0, 1));
    s.scene.AddLight("/sky", primTypes::kDomeLight, sky, rotateX90);
    CameraParams ortho;
    ortho.orthographic = true;
    ortho.horizontalAperture = ortho.verticalAperture = 1;
    s.scene.AddCamera("/cam", ortho, test::LookDownZ(2));
    s.scene.AddRenderBuffer("/color", 8, 8, 4);
    s.delegate.Settings().samplesPerPixel = 1024;
    s.delegate.Settings().mis = mis == 1;
    const RenderStats stats = s.Render();
    int n = 0;
    results[mis] = MeanWhereAlpha(s.Buffer("/color"), 1, 1, &n);
    std::printf("plane under a textured dome, MIS %s: %.5f (expected %.5f)\n", mis ? "on" : "off", results[mis],
                expected);
    CHECK(n == 64);
    CHECK(stats.nonFiniteSamples == 0);
    CHECK(results[mis] == Approx(expected).epsilon(mis ? 0.005 : 0.015));
  }

  // A dome naming a file that cannot be read renders magenta, with one warning naming the light and the file.
  Scene s;
  LightParams bad;
  bad.type = LightType::Dome;
  bad.textureFile = dir / "missing.exr";
  s.scene.AddLight("/badsky", primTypes::kDomeLight, bad);
  s.scene.AddCamera("/cam", CameraParams{}, test::LookDownZ(2));
  s.scene.AddRenderBuffer("/color", 2, 2, 4);
  s.delegate.Settings().samplesPerPixel = 1;
  CHECK_NOTHROW(s.Render());
  const std::vector<std::string> warnings = s.delegate.GetRenderParam()->Warnings();
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("light /badsky") && Catch::Contains("missing.exr"));
  const RenderBuffer& seen = s.Buffer("/color");
  CHECK(seen.Resolved(0, 0, 0) == Approx(1));  // the camera sees the dome: magenta
  CHECK(seen.Resolved(0, 0, 1) == Approx(0));
  CHECK(seen.Resolved(0, 0, 2) == Approx(1));
}
