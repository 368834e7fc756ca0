#include "hdeye/render/previewSurface.h"

#include "hdeye/render/sampleDirections.h"

#include <eyelib/eye_constants.h>
#include <eyelib/optics.h>
#include <eyelib/sampling.h>

#include <algorithm>
#include <cmath>

namespace hdeye {

namespace {

using eyelib::paper::kPi;
constexpr double kInvPi = 1 / kPi;

double Luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

bool Finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Exact dielectric Fresnel reflectance from outside (cos clamped to [0, 1]) for index ior over air (invIor2 =
/// 1 / ior^2); about 0 for ior = 1. eyelib::FresnelDielectric's formula with the divisions shared: its two amplitude
/// ratios a / e and b / d squared and summed over one division, (a^2 d^2 + b^2 e^2) / (e^2 d^2), and 1 / ior^2 once
/// per shading point (every denominator is positive: cosT > 0 whenever sin2T < 1).
/// c in [0, 1] with its square c2 given (a caller that has c2 before c, as a square root of it, then need not wait
/// for the root to start the transmitted cosine's).
double FresnelCoatCos2(double c, double c2, double ior, double invIor2) {
  const double sin2T = (1 - c2) * invIor2;
  if (sin2T >= 1) return 1;
  const double cosT = std::sqrt(1 - sin2T);
  const double a = ior * c - cosT, e = ior * c + cosT, b = c - ior * cosT, d = c + ior * cosT;
  const double a2 = a * a, e2 = e * e, b2 = b * b, d2 = d * d;
  return (a2 * d2 + b2 * e2) / (2 * e2 * d2);
}
double FresnelCoat(double cosTheta, double ior, double invIor2) {
  const double c = std::clamp(cosTheta, 0.0, 1.0);
  return FresnelCoatCos2(c, c * c, ior, invIor2);
}

/// Schlick's Fresnel from its normal-incidence reflectance f0 (white at grazing incidence).
glm::dvec3 Schlick(const glm::dvec3& f0, double c) {
  const double m = 1 - std::clamp(c, 0.0, 1.0);
  return f0 + (glm::dvec3(1) - f0) * (m * m * m * m * m);
}

/// The specular reflectance at a microfacet seen at cosine c: the spec's F0/F90 interpolation by metallic,
/// or Schlick of specularColor in the specular workflow.
/// c in [0, 1], c2 = c^2.
glm::dvec3 SpecularFresnel(const PreviewSurface& s, double c, double c2, double invIor2) {
  if (s.specularWorkflow) return Schlick(s.specularColor, c);
  return glm::mix(glm::dvec3(FresnelCoatCos2(c, c2, s.ior, invIor2)), s.albedo, s.metallic);
}

/// What the specular lobe takes from the diffuse at cosine c (scalar, so the product stays reciprocal).
double DiffuseFresnel(const PreviewSurface& s, double c, double invIor2) {
  if (!s.specularWorkflow) return FresnelCoat(c, s.ior, invIor2);
  const glm::dvec3 f = Schlick(s.specularColor, c);
  return std::max({f.x, f.y, f.z});
}
double DiffuseWeight(const PreviewSurface& s) { return s.specularWorkflow ? 1.0 : 1 - s.metallic; }

/// The clearcoat's reflectance at cosine c: clearcoat x Schlick with F0 = 0.04 (index 1.5).
constexpr double kClearcoatF0 = 0.04;
double CoatFresnel(const PreviewSurface& s, double c) { return s.clearcoat * Schlick(glm::dvec3(kClearcoatF0), c).x; }
/// What reaches the layers under the clearcoat, seen from cosine c.
double UnderCoat(const PreviewSurface& s, double c) { return 1 - CoatFresnel(s, c); }

bool IsMirror(const PreviewSurface& s) { return s.roughness < kMirrorRoughness; }
double Alpha(const PreviewSurface& s) { return std::max(kMinAlpha, s.roughness * s.roughness); }
bool CoatIsMirror(const PreviewSurface& s) { return s.clearcoatRoughness < kMirrorRoughness; }
double CoatAlpha(const PreviewSurface& s) { return std::max(kMinAlpha, s.clearcoatRoughness * s.clearcoatRoughness); }

// GGX (Trowbridge-Reitz), isotropic, in the local frame (z = normal).
/// Smith's Lambda for GGX; w.z > 0.
double GgxLambda(double alpha, const glm::dvec3& w) {
  const double c2 = w.z * w.z;
  const double tan2 = std::max(0.0, 1 - c2) / std::max(c2, 1e-300);
  return 0.5 * (std::sqrt(1 + alpha * alpha * tan2) - 1);
}

/// A microfacet normal from the distribution of normals visible from wo, D(h) G1(wo) max(0, wo.h) / cos_o, so its
/// reflection pdf is D(h) G1(wo) / (4 cos_o). Dupuy and Benyoub 2023 ("Sound and complete visible normal sampling
/// with spherical caps"): in the configuration where GGX is a hemisphere (wo stretched by alpha), the visible normal
/// is wo plus a direction uniform on the spherical cap z > -wo.z; no tangent frame (Heitz 2018's needs one, and a
/// square root and division more).
glm::dvec3 SampleGgxVisibleNormal(double alpha, const glm::dvec3& wo, double u1, double u2) {
  // Normalisations as one reciprocal square root times the vector (wo.z > 0, so the first is never of zero).
  const glm::dvec3 v(alpha * wo.x, alpha * wo.y, wo.z);
  const glm::dvec3 vh = v * (1 / std::sqrt(glm::dot(v, v)));
  const double z = (1 - u1) * (1 + vh.z) - vh.z;  // uniform in [-vh.z, 1]
  const double sinT = std::sqrt(std::clamp(1 - z * z, 0.0, 1.0));
  double sinPhi, cosPhi;
  SinCos2Pi(u2, &sinPhi, &cosPhi);
  const glm::dvec3 nh = glm::dvec3(sinT * cosPhi, sinT * sinPhi, z) + vh;  // nh.z >= 0
  const glm::dvec3 ne(alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z));
  const double len2 = glm::dot(ne, ne);
  return len2 > 0 ? ne * (1 / std::sqrt(len2)) : glm::dvec3(0, 0, 1);
}

/// The specular lobe's Fresnel and what it takes from the diffuse, at one cosine c: one exact Fresnel (or
/// Schlick) evaluation for both.
struct FresnelTerms {
  glm::dvec3 specular;  ///< SpecularFresnel(s, c)
  double diffuse;       ///< DiffuseFresnel(s, c)
};
FresnelTerms FresnelAt(const PreviewSurface& s, double c, double invIor2) {
  if (s.specularWorkflow) {
    const glm::dvec3 f = Schlick(s.specularColor, c);
    return {f, std::max({f.x, f.y, f.z})};
  }
  const double fd = FresnelCoat(c, s.ior, invIor2);
  return {glm::mix(glm::dvec3(fd), s.albedo, s.metallic), fd};
}

using LobeProbabilities = PreviewSurfaceAt::Lobes;
/// Lobe selection from wo's Fresnel terms (under: UnderCoat(s, cos_o), coat: CoatFresnel(s, cos_o)).
LobeProbabilities SelectLobes(const PreviewSurface& s, const FresnelTerms& fo, double under, double coat) {
  const double wD = s.opacity * under * DiffuseWeight(s) * Luminance(s.albedo) * (1 - fo.diffuse);
  const double wS = s.opacity * under * Luminance(fo.specular);
  const double wC = s.opacity * coat;
  const double wG = 1 - s.opacity;
  const double total = wD + wS + wC + wG;
  if (!(total > 0) || !std::isfinite(total)) return {};
  const double inv = 1 / total;
  return {wD * inv, wS * inv, wC * inv, wG * inv};
}

/// One rough GGX lobe at the half vector h of local directions wo, wi (both above): the reflection with
/// height-correlated masking-shadowing D G2 / (4 cos_o cos_i), and the solid-angle pdf of reflecting wo into wi
/// about a visible normal, D G1(wo) / (4 cos_o). `o`: the lobe's terms of wo alone.
struct GgxTerms {
  double reflection = 0, pdf = 0;
};
using GgxFromWo = PreviewSurfaceAt::GgxFromWo;
GgxFromWo GgxOf(double alpha, double cosO, const glm::dvec3& lo) {
  const double lambda = GgxLambda(alpha, lo), a2 = alpha * alpha;
  return {a2, lambda, 1 / (1 + lambda), a2 / (4 * kPi * cosO)};
}
/// The half vector is not formed: with x = 1 + wo.wi = |wo + wi|^2 / 2 and sz = cos_o + cos_i (> 0, both above),
/// cos_h^2 = sz^2 / (2 x), so D = a2 / (pi q^2) with q = cos_h^2 (a2 - 1) + 1 = m / (2 x), m = sz^2 (a2 - 1) + 2 x
/// (q >= min(1, a2) > 0). And (1 + Lambda(wi)) cos_i = (cos_i + sqrt(cos_i^2 + a2 sin_i^2)) / 2 (Lambda's tan^2 over
/// cos_i's square cancels the reflection's 1 / cos_i). The two terms are then one division and one square root.
GgxTerms GgxLobe(const GgxFromWo& o, double cosI, double x, double sz) {
  const double m = sz * sz * (o.a2 - 1) + 2 * x, ci2 = cosI * cosI;
  const double g2Den = cosI * (0.5 + o.lambda) + 0.5 * std::sqrt(std::max(0.0, ci2 + o.a2 * (1 - ci2)));
  // D / (4 cos_o) times 1 / ((1 + Lambda(wo) + Lambda(wi)) cos_i), 1 / q^2 = 4 x^2 / m^2.
  const double r = o.dOverFourCos * (4 * x * x) / (m * m * g2Den);
  return {r, r * g2Den * o.g1};
}

// Below this cosine a direction is treated as lying in the surface: no scattering from or into it.
constexpr double kMinCos = 1e-9;

}  // namespace

double ThinSheetReflectance(double cosTheta, double ior) {
  const double r = eyelib::FresnelDielectric(std::clamp(cosTheta, 0.0, 1.0), ior);
  return r < 1 ? 2 * r / (1 + r) : 1.0;
}

inline glm::dvec3 PreviewSurfaceAt::ToLocal(const glm::dvec3& v) const {
  return {glm::dot(v, t_), glm::dot(v, b_), glm::dot(v, n_)};
}
inline glm::dvec3 PreviewSurfaceAt::ToWorld(const glm::dvec3& v) const { return v.x * t_ + v.y * b_ + v.z * n_; }

PreviewSurfaceAt::PreviewSurfaceAt(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo)
    : s_(s), n_(n), wo_(wo) {
  eyelib::OrthonormalBasis(n_, &t_, &b_);
  lo_ = ToLocal(wo);
  above_ = lo_.z > kMinCos;
  if (!above_) return;
  invIor2_ = 1 / (s.ior * s.ior);
  const FresnelTerms fo = FresnelAt(s, lo_.z, invIor2_);
  specularO_ = fo.specular, diffuseO_ = fo.diffuse;
  coatO_ = CoatFresnel(s, lo_.z), underO_ = 1 - coatO_;
  lobes_ = SelectLobes(s, fo, underO_, coatO_);
  diffuseBase_ = DiffuseWeight(s) * s.albedo * (kInvPi * (1 - diffuseO_));
  if (!IsMirror(s)) ggxO_ = GgxOf(Alpha(s), lo_.z, lo_);
  if (!CoatIsMirror(s)) coatGgxO_ = GgxOf(CoatAlpha(s), lo_.z, lo_);
}

void PreviewSurfaceAt::OpaqueTerms(const glm::dvec3& li, glm::dvec3* f, double* pdf) const {
  const PreviewSurface& s = s_;
  const LobeProbabilities& p = lobes_;
  glm::dvec3 base = diffuseBase_ * (1 - DiffuseFresnel(s, li.z, invIor2_));
  double density = p.diffuse * li.z * kInvPi;
  // Both rough lobes reflect about the same half vector h = (lo + li) / |lo + li|, not formed (GgxLobe): its
  // cosine with wo, the Fresnel terms', is sqrt(x / 2), x = 1 + lo.li (its square known before the root).
  const double x = 1 + glm::dot(lo_, li), sz = lo_.z + li.z;
  const bool halfway = x > 0;  // lo and li not opposite (then no half vector)
  const double cosH2 = std::min(1.0, 0.5 * x), cosH = std::sqrt(std::max(0.0, cosH2));
  if (halfway && !IsMirror(s)) {
    const GgxTerms g = GgxLobe(ggxO_, li.z, x, sz);
    if (g.reflection > 0) base += g.reflection * SpecularFresnel(s, cosH, cosH2, invIor2_);
    if (p.specular > 0) density += p.specular * g.pdf;
  }
  // Without a coat UnderCoat is 1 - 0 x (a finite Schlick term) = 1 exactly: not evaluated.
  glm::dvec3 value = base * (underO_ * (s.clearcoat == 0 ? 1.0 : UnderCoat(s, li.z)));
  if (halfway && !CoatIsMirror(s)) {
    const GgxTerms g = GgxLobe(coatGgxO_, li.z, x, sz);
    if (s.clearcoat > 0 && g.reflection > 0) value += glm::dvec3(g.reflection * CoatFresnel(s, cosH));
    if (p.coat > 0) density += p.coat * g.pdf;
  }
  *f = value, *pdf = density;
}

bool PreviewSurfaceAt::HasSmoothLobe() const {
  if (!above_) return false;
  const LobeProbabilities& p = lobes_;
  return p.diffuse > 0 || (p.specular > 0 && !IsMirror(s_)) || (p.coat > 0 && !CoatIsMirror(s_));
}

glm::dvec3 PreviewSurfaceAt::EvalAndPdf(const glm::dvec3& wi, double* pdf) const {
  *pdf = 0;
  const glm::dvec3 li = ToLocal(wi);
  if (!above_ || !(li.z > kMinCos)) return glm::dvec3(0);
  glm::dvec3 opaque;
  double density;
  OpaqueTerms(li, &opaque, &density);
  if (std::isfinite(density)) *pdf = density;
  const glm::dvec3 f = s_.opacity * opaque;
  return Finite(f) ? f : glm::dvec3(0);
}

glm::dvec3 PreviewSurfaceAt::Eval(const glm::dvec3& wi) const {
  double pdf;
  return EvalAndPdf(wi, &pdf);
}

double PreviewSurfaceAt::Pdf(const glm::dvec3& wi) const {
  double pdf;
  EvalAndPdf(wi, &pdf);
  return pdf;
}

bool PreviewSurfaceAt::Sample(bool inside, double u0, double u1, double u2, BsdfSample* out) const {
  *out = BsdfSample{};
  const PreviewSurface& s = s_;
  const glm::dvec3 &n = n_, &wo = wo_, &lo = lo_;
  if (!above_) return false;
  const LobeProbabilities& p = lobes_;

  if (u0 >= p.diffuse + p.specular + p.coat) {
    // Glass: reflect with the Fresnel probability, else refract (a thin sheet: pass straight through).
    if (!(p.glass > 0)) return false;
    if (s.thinWalled) {
      const bool reflect = u1 < ThinSheetReflectance(lo.z, s.ior);
      out->wi = reflect ? eyelib::Reflect(wo, n) : -wo;
      out->weight = glm::dvec3((1 - s.opacity) / p.glass);
      out->transmitted = !reflect;
      out->pdf = p.glass;
      out->delta = true;
      return Finite(out->weight);
    }
    const double eta = inside ? 1 / s.ior : s.ior;  // index of the far side over wo's side
    const double fresnel = eyelib::FresnelDielectric(lo.z, eta);
    glm::dvec3 wt(0);
    const double scale = (1 - s.opacity) / p.glass;
    if (u1 < fresnel || !eyelib::Refract(wo, n, eta, &wt)) {
      out->wi = eyelib::Reflect(wo, n);
      out->weight = glm::dvec3(scale);
    } else {
      out->wi = wt;
      out->weight = glm::dvec3(scale / (eta * eta));  // radiance compresses into the denser side
      out->transmitted = true;
    }
    out->pdf = p.glass;
    out->delta = true;
    return Finite(out->weight);
  }

  const bool coatLobe = u0 >= p.diffuse + p.specular;
  if (coatLobe && CoatIsMirror(s)) {
    out->wi = eyelib::Reflect(wo, n);
    out->weight = glm::dvec3(s.opacity * coatO_ / p.coat);  // p.coat > 0 here
    out->pdf = p.coat;
    out->delta = true;
    return Finite(out->weight);
  }
  if (!coatLobe && u0 >= p.diffuse && IsMirror(s)) {
    out->wi = eyelib::Reflect(wo, n);
    const double under = underO_;  // down through the coat and back up at the same angle
    out->weight = s.opacity * under * under * specularO_ / p.specular;  // p.specular > 0 here
    out->pdf = p.specular;
    out->delta = true;
    return Finite(out->weight);
  }

  glm::dvec3 li;
  if (u0 < p.diffuse) {
    li = CosineHemisphereLocal(u1, u2);  // drawn in the local frame: no trip through world space
  } else if (coatLobe) {
    const glm::dvec3 h = SampleGgxVisibleNormal(CoatAlpha(s), lo, u1, u2);
    li = 2 * glm::dot(lo, h) * h - lo;
  } else {
    const glm::dvec3 h = SampleGgxVisibleNormal(Alpha(s), lo, u1, u2);
    li = 2 * glm::dot(lo, h) * h - lo;
  }
  if (!(li.z > kMinCos)) return false;  // a microfacet reflection below the horizon: lost energy
  glm::dvec3 f;
  double pdf;
  OpaqueTerms(li, &f, &pdf);
  if (!(pdf > 0) || !std::isfinite(pdf)) return false;
  out->wi = ToWorld(li);  // unit to rounding: li is, and the frame is orthonormal
  out->weight = s.opacity * f * (li.z / pdf);
  out->pdf = pdf;
  return Finite(out->weight);
}

glm::dvec3 EvalPreviewSurface(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo,
                              const glm::dvec3& wi) {
  return PreviewSurfaceAt(s, n, wo).Eval(wi);
}

double PdfPreviewSurface(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo, const glm::dvec3& wi) {
  return PreviewSurfaceAt(s, n, wo).Pdf(wi);
}

bool HasSmoothLobe(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo) {
  return PreviewSurfaceAt(s, n, wo).HasSmoothLobe();
}

bool SamplePreviewSurface(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo, bool inside, double u0,
                          double u1, double u2, BsdfSample* out) {
  return PreviewSurfaceAt(s, n, wo).Sample(inside, u0, u1, u2, out);
}

}  // namespace hdeye
