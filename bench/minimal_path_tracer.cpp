#include "minimal_path_tracer.h"

#include "hdeye/render/fastTrig.h"
#include "hdeye/render/previewSurface.h"
#include "hdeye/render/sampleDirections.h"
#include "hdeye/render/sampleStream.h"

#include <eyelib/random.h>
#include <eyelib/sampling.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The cheapest stream of uniform numbers that is still good enough for a path tracer: a 64-bit LCG whose state is
/// seeded per (pixel, sample) by SplitMix64, each output mixed once (PCG's xorshift-multiply).
class LcgSampler {
 public:
  LcgSampler(const MinimalScene& s, int x, int y, int sample)
      : state_(eyelib::SplitMix64((std::uint64_t(y) * s.width + x) * std::uint64_t(s.spp) + std::uint64_t(sample))) {}
  double Next() {
    state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
    std::uint64_t x = state_ ^ (state_ >> 29);
    x *= 0xbf58476d1ce4e5b9ull;
    return double((x ^ (x >> 32)) >> 11) * 0x1.0p-53;
  }
  void Next2D(double* u, double* v) { *u = Next(), *v = Next(); }
  void PixelJitter(double* u, double* v) { Next2D(u, v); }

 private:
  std::uint64_t state_;
};

/// The renderer's own sampler (ZSobol, its key table made once per image).
class ZSobolSampler {
 public:
  ZSobolSampler(const MinimalScene& s, int x, int y, int sample)
      : stream_(hdeye::SamplerKind::ZSobol, 0, x, y, s.width, std::uint64_t(sample), s.sampleKeys) {}
  double Next() { return stream_.Next(); }
  void Next2D(double* u, double* v) { stream_.Next2D(u, v); }
  void PixelJitter(double* u, double* v) { stream_.PixelJitter(u, v); }

 private:
  hdeye::SampleStream stream_;
};

double PowerHeuristic(double a, double b) { return a * a / (a * a + b * b); }

/// The renderer's float ray from a double origin and direction.
void SetRay(const glm::dvec3& o, const glm::dvec3& d, double tNear, double tFar, RTCRay* ray) {
  ray->org_x = float(o.x), ray->org_y = float(o.y), ray->org_z = float(o.z);
  ray->dir_x = float(d.x), ray->dir_y = float(d.y), ray->dir_z = float(d.z);
  ray->tnear = float(tNear);
  ray->tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
  ray->mask = ~0u, ray->flags = 0, ray->time = 0;
}

/// A cosine-distributed direction about unit n (the renderer's sample, in n's frame).
glm::dvec3 CosineDirection(const glm::dvec3& n, double u1, double u2) {
  glm::dvec3 t, b;
  eyelib::OrthonormalBasis(n, &t, &b);
  const glm::dvec3 l = hdeye::CosineHemisphereLocal(u1, u2);
  return l.x * t + l.y * b + l.z * n;
}

/// A Lambertian surface of one albedo.
class LambertAt {
 public:
  LambertAt(double albedo, const glm::dvec3& n, const glm::dvec3&) : albedo_(albedo), n_(n) {}
  bool HasSmoothLobe() const { return true; }
  glm::dvec3 EvalAndPdf(const glm::dvec3& wi, double* pdf) const {
    *pdf = std::max(0.0, glm::dot(wi, n_)) / kPi;
    return glm::dvec3(albedo_ / kPi);
  }
  template <class Sampler> bool Sample(Sampler& rng, glm::dvec3* wi, glm::dvec3* weight, double* pdf) const {
    double u1, u2;
    rng.Next2D(&u1, &u2);
    *wi = CosineDirection(n_, u1, u2);
    *weight = glm::dvec3(albedo_);  // f cos / pdf
    *pdf = glm::dot(*wi, n_) / kPi;
    return true;
  }

 private:
  double albedo_;
  glm::dvec3 n_;
};

/// The renderer's UsdPreviewSurface BSDF with UsdPreviewSurface's defaults (roughness 0.5, ior 1.5) and the albedo.
class PreviewSurfaceBsdfAt {
 public:
  PreviewSurfaceBsdfAt(double albedo, const glm::dvec3& n, const glm::dvec3& wo)
      : surface_(Surface(albedo)), at_(surface_, n, wo) {}
  bool HasSmoothLobe() const { return at_.HasSmoothLobe(); }
  glm::dvec3 EvalAndPdf(const glm::dvec3& wi, double* pdf) const { return at_.EvalAndPdf(wi, pdf); }
  template <class Sampler> bool Sample(Sampler& rng, glm::dvec3* wi, glm::dvec3* weight, double* pdf) const {
    const double uLobe = rng.Next();
    double u1, u2;
    rng.Next2D(&u1, &u2);
    hdeye::BsdfSample bs;
    if (!at_.Sample(false, uLobe, u1, u2, &bs)) return false;
    *wi = bs.wi, *weight = bs.weight, *pdf = bs.pdf;
    return true;
  }

 private:
  static hdeye::PreviewSurface Surface(double albedo) {
    hdeye::PreviewSurface s;
    s.albedo = glm::dvec3(albedo);
    return s;
  }
  hdeye::PreviewSurface surface_;
  hdeye::PreviewSurfaceAt at_;
};

template <class Sampler, class BsdfAt> class Tracer {
 public:
  explicit Tracer(const MinimalScene& s) : s_(s) {}

  glm::dvec3 Li(glm::dvec3 o, glm::dvec3 d, double tNear, Sampler& rng) {
    glm::dvec3 L(0), beta(1);
    bool specular = true;  // the camera ray: lights it meets count in full
    double bsdfPdf = 0;
    for (int depth = 0; depth <= s_.maxDepth; ++depth) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      RTCRayHit rh;
      SetRay(o, d, tNear, kInf, &rh.ray);
      rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(s_.scene, &context, &rh);
      ++rays;
      const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      const double t = hit ? double(rh.ray.tfar) : kInf;
      // The lights this ray meets before the surface, weighted against having sampled them.
      double keyPdf;
      if (KeyAlong(o, d, t, &keyPdf)) L += beta * s_.keyRadiance * (specular ? 1 : PowerHeuristic(bsdfPdf, keyPdf));
      if (!hit) {
        L += beta * s_.domeRadiance * (specular ? 1 : PowerHeuristic(bsdfPdf, 0.5 / (4 * kPi)));
        break;
      }
      const glm::dvec3 p = o + t * d;
      glm::dvec3 n = glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);  // the ball's instances only translate
      n *= (glm::dot(n, d) > 0 ? -1 : 1) / std::sqrt(glm::dot(n, n));
      const glm::dvec3 origin = p + n * (1e-5 * (1 + std::abs(p.x) + std::abs(p.y) + std::abs(p.z)));
      const BsdfAt bsdf(s_.albedo, n, -d);
      L += beta * DirectLight(bsdf, origin, n, rng);
      glm::dvec3 weight;
      if (!bsdf.Sample(rng, &d, &weight, &bsdfPdf)) break;
      o = origin, tNear = 0;
      specular = false;
      beta *= weight;
      if (depth >= 3) {
        const double q = std::min(0.95, std::max({beta.x, beta.y, beta.z}));
        if (rng.Next() >= q) break;
        beta /= q;
      }
    }
    return L;
  }

  std::int64_t rays = 0, shadowRays = 0;

 private:
  /// Whether the ray meets the key light's sphere before distance tMax, and the pdf (per steradian, light choice
  /// included) with which DirectLight samples that direction.
  bool KeyAlong(const glm::dvec3& o, const glm::dvec3& d, double tMax, double* pdf) const {
    const glm::dvec3 toC = s_.keyPosition - o;
    const double d2 = glm::dot(toC, toC), r2 = s_.keyRadius * s_.keyRadius;
    const double b = glm::dot(d, toC), disc = b * b - (d2 - r2);
    if (!(d2 > r2) || disc < 0) return false;
    const double tHit = b - std::sqrt(disc);
    if (!(tHit > 0) || tHit >= tMax) return false;
    *pdf = 0.5 / (2 * kPi * (1 - std::sqrt(std::max(0.0, 1 - r2 / d2))));
    return true;
  }

  /// One light chosen uniformly, sampled, tested for a shadow and weighted by the power heuristic.
  glm::dvec3 DirectLight(const BsdfAt& bsdf, const glm::dvec3& origin, const glm::dvec3& n, Sampler& rng) {
    const double pick = rng.Next();
    double u1, u2;
    rng.Next2D(&u1, &u2);
    if (!bsdf.HasSmoothLobe()) return glm::dvec3(0);
    glm::dvec3 dir, radiance;
    double pdf, distance;
    if (pick < 0.5) {
      const glm::dvec3 toC = s_.keyPosition - origin;
      const double d2 = glm::dot(toC, toC), r2 = s_.keyRadius * s_.keyRadius;
      if (!(d2 > r2)) return glm::dvec3(0);
      const double dc = std::sqrt(d2), oneMinusCosMax = 1 - std::sqrt(1 - r2 / d2);
      dir = hdeye::SampleConeAbout(toC / dc, oneMinusCosMax, u1, u2);
      const double b = glm::dot(dir, toC);
      distance = b - std::sqrt(std::max(0.0, b * b - (d2 - r2)));  // the sphere's near side
      pdf = 0.5 / (2 * kPi * oneMinusCosMax);
      radiance = s_.keyRadiance;
    } else {
      const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z));
      double s, c;
      hdeye::SinCos2Pi(u2, &s, &c);
      dir = glm::dvec3(r * c, r * s, z);
      distance = kInf;
      pdf = 0.5 / (4 * kPi);
      radiance = s_.domeRadiance;
    }
    const double cosS = glm::dot(dir, n);
    if (!(cosS > 0)) return glm::dvec3(0);
    double bsdfPdf;
    const glm::dvec3 f = bsdf.EvalAndPdf(dir, &bsdfPdf);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    SetRay(origin, dir, 0, distance * (1 - 1e-6), &ray);
    rtcOccluded1(s_.scene, &context, &ray);
    ++rays, ++shadowRays;
    if (ray.tfar < 0) return glm::dvec3(0);  // Embree sets tfar to -inf when something blocks the ray
    return f * radiance * (cosS * PowerHeuristic(pdf, bsdfPdf) / pdf);
  }

  const MinimalScene& s_;
};

template <class Sampler, class BsdfAt> MinimalResult Trace(const MinimalScene& scene) {
  Tracer<Sampler, BsdfAt> tracer(scene);
  const double aspect = double(scene.width) / scene.height, invW = 1.0 / scene.width, invH = 1.0 / scene.height;
  double sum = 0;
  for (int y = 0; y < scene.height; ++y)
    for (int x = 0; x < scene.width; ++x)
      for (int s = 0; s < scene.spp; ++s) {
        Sampler rng(scene, x, y, s);
        double jx, jy;
        rng.PixelJitter(&jx, &jy);
        const hdeye::WorldRay ray = scene.camera.GenerateRay((x + jx) * invW, (y + jy) * invH, aspect);
        const glm::dvec3 L = tracer.Li(ray.origin, ray.dir, ray.tNear, rng);
        sum += L.x + L.y + L.z;
      }
  MinimalResult r;
  r.rays = tracer.rays, r.shadowRays = tracer.shadowRays;
  r.meanRadiance = sum / (3.0 * double(scene.width) * scene.height * scene.spp);
  return r;
}

}  // namespace

const char* MinimalVariantName(MinimalVariant v) {
  switch (v) {
    case MinimalVariant::Lambert: return "Lambert, counter hash";
    case MinimalVariant::ZSobol: return "Lambert, ZSobol";
    case MinimalVariant::PreviewSurface: return "UsdPreviewSurface, counter hash";
    case MinimalVariant::Both: return "UsdPreviewSurface, ZSobol";
  }
  return "";
}

MinimalResult TraceMinimal(const MinimalScene& scene, MinimalVariant variant) {
  switch (variant) {
    case MinimalVariant::Lambert: return Trace<LcgSampler, LambertAt>(scene);
    case MinimalVariant::ZSobol: return Trace<ZSobolSampler, LambertAt>(scene);
    case MinimalVariant::PreviewSurface: return Trace<LcgSampler, PreviewSurfaceBsdfAt>(scene);
    case MinimalVariant::Both: return Trace<ZSobolSampler, PreviewSurfaceBsdfAt>(scene);
  }
  return {};
}

}  // namespace bench
