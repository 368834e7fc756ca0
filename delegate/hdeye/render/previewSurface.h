#pragma once
// The BSDF of UsdPreviewSurface (metallic and specular workflows, clearcoat), at one shading point.
// Every sampling routine has its pdf beside it, and the tests check they agree.
//
// Lobes, mixed by `opacity`:
//   opaque part (weight opacity):
//     clearcoat a white GGX lobe of its own roughness, F = clearcoat x Schlick(0.04) (index 1.5), over
//               everything below, which it dims by (1 - Fc(cos_o)) (1 - Fc(cos_i)) (reciprocal; what
//               the coat reflects does not also reach the base). Below kMirrorRoughness a delta lobe.
//     diffuse   kd albedo / pi * (1 - Fd(cos_o)) (1 - Fd(cos_i))   (reciprocal; what the
//               specular coat reflects is not also scattered diffusely). Metallic workflow: kd = 1 -
//               metallic, Fd the exact dielectric Fresnel of `ior`; specular workflow: kd = 1, Fd the
//               largest channel of Schlick(specularColor).
//     specular  GGX microfacet D G2 F / (4 cos_o cos_i), Smith height-correlated G2, perceptual
//               roughness (alpha = roughness^2, at least kMinAlpha), F = mix(Fd(wo.h), albedo, metallic):
//               the spec's F0 = ((1 - ior) / (1 + ior))^2 with F90 = 1 for metallic 0 (exact
//               dielectric Fresnel here, which Schlick's form approximates), F0 = F90 = albedo for
//               metallic 1; specular workflow: F = Schlick(specularColor), white at the edge.
//               Below kMirrorRoughness it is a mirror: a delta lobe, never light-sampled.
//   glass part (weight 1 - opacity): a smooth dielectric of index `ior`, reflecting with the Fresnel
//     probability, else refracting (radiance scaled by 1/eta^2, pbrt's non-symmetric BTDF, as the
//     cornea does). Rough transmission is not modelled: roughness does not blur the glass.
//     thinWalled (open surfaces, thinWalls.h): a thin sheet instead, reflecting with the two-interface
//     reflectance R_sheet = 2 Fd / (1 + Fd), else transmitting straight through (wi = -wo, unscaled).
// Fd is the exact unpolarised Fresnel reflectance of a dielectric of index `ior` (eyelib's). With
// ior = 1, Fd = 0: no coat, and the opaque part is exactly Lambert.
//
// Conventions: directions are unit, world space, pointing away from the surface; `n` is the unit
// shading normal on the side of wo (dot(n, wo) > 0). f is in 1/sr, pdfs per steradian.
#include <glm/glm.hpp>

namespace hdeye {

struct PreviewSurface {
  glm::dvec3 albedo{0.18};           ///< diffuseColor (or its texture), linear, >= 0
  double roughness = 0.5;            ///< perceptual, [0, 1]
  double metallic = 0;               ///< [0, 1]
  double opacity = 1;                ///< [0, 1]; below 1 part of the surface is glass
  double ior = 1.5;                  ///< >= 1
  bool thinWalled = false;           ///< the glass part is a thin sheet (no refraction, no inside)
  bool specularWorkflow = false;     ///< useSpecularWorkflow: specularColor instead of metallic and ior
  glm::dvec3 specularColor{0};       ///< linear, [0, 1]: the specular workflow's F0 (edge colour white)
  double clearcoat = 0;              ///< [0, 1]: weight of the white clearcoat lobe
  double clearcoatRoughness = 0.01;  ///< perceptual, [0, 1] (the spec's default is a mirror)

  /// A pure Lambertian reflector (the sclera, and anything that must stay Lambert).
  static PreviewSurface Lambert(const glm::dvec3& albedo) {
    PreviewSurface s;
    s.albedo = albedo, s.roughness = 1, s.metallic = 0, s.opacity = 1, s.ior = 1;
    return s;
  }
};

/// Reflectance of a thin dielectric sheet of index `ior` at cosine `cosTheta` (both interfaces and the light
/// bouncing between them: R + T^2 R / (1 - R^2) = 2R / (1 + R), with R the single-interface Fresnel).
double ThinSheetReflectance(double cosTheta, double ior);

/// Roughness below which the specular lobe is a perfect mirror (alpha < 4e-4: a GGX lobe that
/// narrow is a mirror to within the float precision of hit points, and its pdf would overflow MIS).
constexpr double kMirrorRoughness = 0.02;
/// Smallest GGX alpha used for rough lobes.
constexpr double kMinAlpha = 1e-3;

/// One sampled scattering direction.
struct BsdfSample {
  glm::dvec3 wi{0};          ///< unit, away from the surface
  glm::dvec3 weight{0};      ///< f |cos_i| / pdf (delta lobes: their reflectance over their probability)
  double pdf = 0;            ///< solid-angle pdf for non-delta samples (for MIS); for delta samples the
                             ///< lobe's selection probability (not a density: never MIS-weighted)
  bool delta = false;        ///< a mirror or glass event: lights it meets count in full
  bool transmitted = false;  ///< crossed to the other side of the surface (into or out of the glass)
};

/// The BSDF at one shading point seen from one outgoing direction wo: the shading frame, wo's Fresnel terms and
/// the lobe probabilities are computed once, then shared by next event estimation (Eval, Pdf) and the
/// continuation (Sample) of the same path vertex. Holds a reference to `s`, which must outlive it. The free
/// functions below are the same computations with a new PreviewSurfaceAt per call.
class PreviewSurfaceAt {
 public:
  /// n: the unit shading normal on the side of wo; wo: unit, away from the surface.
  PreviewSurfaceAt(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo);

  /// Whether the surface has a non-delta lobe (diffuse or rough specular) worth light sampling from wo.
  bool HasSmoothLobe() const;
  /// The non-delta part of f(wo, wi) (1/sr), as EvalPreviewSurface.
  glm::dvec3 Eval(const glm::dvec3& wi) const;
  /// The solid-angle pdf (1/sr) with which Sample returns the non-delta direction wi, as PdfPreviewSurface.
  double Pdf(const glm::dvec3& wi) const;
  /// Eval(wi), with Pdf(wi) written to *pdf: the two share their half vector and microfacet terms.
  glm::dvec3 EvalAndPdf(const glm::dvec3& wi, double* pdf) const;
  /// A direction sampled from three uniform numbers, as SamplePreviewSurface.
  bool Sample(bool inside, double u0, double u1, double u2, BsdfSample* sample) const;

  /// The lobe selection probabilities from wo (proportional to each lobe's estimated reflectance).
  struct Lobes {
    double diffuse = 0, specular = 0, coat = 0, glass = 0;
  };

 private:
  glm::dvec3 ToLocal(const glm::dvec3& v) const;
  glm::dvec3 ToWorld(const glm::dvec3& v) const;
  /// f without the opacity factor (1/sr) and the non-delta pdf (1/sr) at local li (above the surface).
  void OpaqueTerms(const glm::dvec3& li, glm::dvec3* f, double* pdf) const;

  const PreviewSurface& s_;
  glm::dvec3 n_, t_, b_;           ///< the shading frame (z along n)
  glm::dvec3 wo_, lo_;             ///< wo in world space and in the frame
  bool above_ = false;             ///< wo is above the surface (lo_.z > the smallest cosine scattered from)
  glm::dvec3 specularO_{0};        ///< the specular lobe's Fresnel at cos_o
  double diffuseO_ = 0;            ///< what the specular lobe takes from the diffuse at cos_o
  double coatO_ = 0, underO_ = 1;  ///< the clearcoat's reflectance at cos_o, and 1 minus it
  glm::dvec3 diffuseBase_{0};      ///< the diffuse lobe's f before its cos_i Fresnel factor
  double invIor2_ = 1;             ///< 1 / ior^2, for the Fresnel terms
  Lobes lobes_;

 public:
  /// A rough lobe's terms of wo alone: alpha^2, GGX Lambda(wo), G1(wo) and alpha^2 / (4 pi cos_o) (D's constant
  /// over the reflection's 4 cos_o).
  struct GgxFromWo {
    double a2 = 0, lambda = 0, g1 = 1, dOverFourCos = 0;
  };

 private:
  GgxFromWo ggxO_, coatGgxO_;  ///< the rough specular and clearcoat lobes'
};

/// The non-delta part of f(wo, wi) (1/sr): diffuse plus rough specular, times opacity. Zero for wi
/// below the surface (the opaque part does not transmit) and for wo at or below it.
glm::dvec3 EvalPreviewSurface(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo, const glm::dvec3& wi);

/// The solid-angle pdf with which SamplePreviewSurface returns the non-delta direction wi.
double PdfPreviewSurface(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo, const glm::dvec3& wi);

/// Whether the surface has a non-delta lobe (diffuse or rough specular) worth light sampling from wo.
bool HasSmoothLobe(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo);

/// Samples a direction from three uniform numbers: u0 picks the lobe (by estimated reflectance), u1 and
/// u2 the direction (and for glass, u1 also reflect or refract). `inside`: wo is inside the glass part
/// (the relative index is then 1/ior). Returns false when no direction carries light (black surface,
/// a microfacet sample below the horizon): the path ends there, which is the energy the lobe loses.
/// The weight and pdf are always finite.
bool SamplePreviewSurface(const PreviewSurface& s, const glm::dvec3& n, const glm::dvec3& wo, bool inside, double u0,
                          double u1, double u2, BsdfSample* sample);

}  // namespace hdeye
