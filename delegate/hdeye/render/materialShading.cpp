#include "hdeye/render/materialShading.h"

#include <algorithm>
#include <cmath>

namespace hdeye {
namespace {

constexpr double kDegrees = 3.14159265358979323846 / 180;

/// A textured input's value at the site, RGBA, or nullptr-like `false` when the input is not textured.
bool LookupInput(const SurfaceMaterial& material, MaterialInput which, const TextureSite& site, glm::vec4* value) {
  if (!material.textures) return false;
  const BoundTexture& bound = (*material.textures)[std::size_t(which)];
  if (!bound.texture) return false;
  const TextureInput& in = bound.input;
  // UsdTransform2d: scale, then rotate, then translate; the footprint goes through the linear part.
  const double c = std::cos(in.rotation * kDegrees), s = std::sin(in.rotation * kDegrees);
  auto linear = [&](glm::dvec2 v) {
    v *= glm::dvec2(in.scale);
    return glm::dvec2(c * v.x - s * v.y, s * v.x + c * v.y);
  };
  const glm::dvec2 st = linear(site.st) + glm::dvec2(in.translation);
  TextureFootprint fp;
  fp.dstDx = glm::vec2(linear(glm::dvec2(site.footprint.dstDx)));
  fp.dstDy = glm::vec2(linear(glm::dvec2(site.footprint.dstDy)));
  *value = bound.texture->Lookup(glm::vec2(st), fp, site.thread);
  if (in.channel >= 0 && in.channel < 4) *value = glm::vec4((*value)[in.channel]);
  return true;
}

double Unit(double v) { return std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.0; }

/// The tangent-space normal m (x along dp/ds, y along dp/dt, z along n) in world space; n where the
/// map or the st frame is unusable, or where the mapped normal would face away from wo.
glm::dvec3 MapNormal(const glm::dvec3& m, const glm::dvec3& n, const glm::dvec3& wo, const StFrame& frame) {
  if (!frame.valid || !(m.z > 0) || !std::isfinite(m.x + m.y + m.z)) return n;
  glm::dvec3 t = frame.dpds - glm::dot(frame.dpds, n) * n;
  const double lt = glm::length(t);
  if (!(lt > 1e-12)) return n;
  t /= lt;
  glm::dvec3 b = glm::cross(n, t);
  if (glm::dot(b, frame.dpdt) < 0) b = -b;  // st may be mirrored: b follows dp/dt
  const glm::dvec3 mapped = t * m.x + b * m.y + n * m.z;
  const double l = glm::length(mapped);
  if (!(l > 1e-12)) return n;
  const glm::dvec3 unit = mapped / l;
  return glm::dot(unit, wo) > 1e-3 ? unit : n;
}

/// The textured inputs of `material` over its constants in `out` (and `opacity`, which the caller's cut-out test
/// reads).
void ApplyTextures(const SurfaceMaterial& material, const glm::dvec3& wo, const TextureSite& site, SurfaceShading* out,
                   double* opacity) {
  out->bsdf.albedo = TexturedAlbedo(material, out->bsdf.albedo, site);
  glm::vec4 v;
  if (LookupInput(material, MaterialInput::Roughness, site, &v)) out->bsdf.roughness = Unit(v.x);
  if (LookupInput(material, MaterialInput::Metallic, site, &v)) out->bsdf.metallic = Unit(v.x);
  if (LookupInput(material, MaterialInput::Opacity, site, &v)) *opacity = Unit(v.x);
  if (LookupInput(material, MaterialInput::Ior, site, &v) && std::isfinite(v.x))
    out->bsdf.ior = std::max(1.0, double(v.x));
  if (LookupInput(material, MaterialInput::SpecularColor, site, &v))
    out->bsdf.specularColor = glm::clamp(glm::dvec3(v), glm::dvec3(0), glm::dvec3(1));
  if (LookupInput(material, MaterialInput::Clearcoat, site, &v)) out->bsdf.clearcoat = Unit(v.x);
  if (LookupInput(material, MaterialInput::ClearcoatRoughness, site, &v)) out->bsdf.clearcoatRoughness = Unit(v.x);
  if (LookupInput(material, MaterialInput::EmissiveColor, site, &v))
    out->emission = glm::max(glm::dvec3(v), glm::dvec3(0));
  if (LookupInput(material, MaterialInput::Normal, site, &v)) {
    out->normal = MapNormal(glm::dvec3(v), out->normal, wo, site.frame);
    out->normalMapped = true;
  }
}

}  // namespace

glm::dvec3 TexturedAlbedo(const SurfaceMaterial& material, const glm::dvec3& albedo, const TextureSite& site) {
  glm::vec4 v;
  if (!LookupInput(material, MaterialInput::DiffuseColor, site, &v)) return albedo;
  return glm::clamp(glm::dvec3(v), glm::dvec3(0), glm::dvec3(1));
}

SurfaceShading ShadeMaterial(const SurfaceMaterial& material, const glm::dvec3& albedo, const glm::dvec3& wo,
                             const glm::dvec3& n, const TextureSite& site) {
  const MaterialParams& m = material.params;
  SurfaceShading out;
  out.bsdf.albedo = albedo;
  out.bsdf.roughness = m.roughness;
  out.bsdf.metallic = m.metallic;
  double opacity = m.opacity;
  out.bsdf.ior = m.ior;
  out.bsdf.specularWorkflow = m.useSpecularWorkflow;
  out.bsdf.specularColor = glm::dvec3(m.specularColor);
  out.bsdf.clearcoat = m.clearcoat;
  out.bsdf.clearcoatRoughness = m.clearcoatRoughness;
  out.emission = glm::dvec3(m.emissiveColor);
  out.normal = n;
  if (material.textures) ApplyTextures(material, wo, site, &out, &opacity);
  if (m.opacityThreshold > 0) {
    out.present = opacity >= m.opacityThreshold;
    opacity = 1;
  }
  out.bsdf.opacity = opacity;
  return out;
}

}  // namespace hdeye
