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
  glm::vec4 v;
  out.bsdf.albedo = TexturedAlbedo(material, albedo, site);
  out.bsdf.roughness = LookupInput(material, MaterialInput::Roughness, site, &v) ? Unit(v.x) : m.roughness;
  out.bsdf.metallic = LookupInput(material, MaterialInput::Metallic, site, &v) ? Unit(v.x) : m.metallic;
  double opacity = LookupInput(material, MaterialInput::Opacity, site, &v) ? Unit(v.x) : m.opacity;
  out.bsdf.ior = LookupInput(material, MaterialInput::Ior, site, &v) && std::isfinite(v.x) ? std::max(1.0, double(v.x))
                                                                                           : double(m.ior);
  if (m.opacityThreshold > 0) {
    out.present = opacity >= m.opacityThreshold;
    opacity = 1;
  }
  out.bsdf.opacity = opacity;
  out.bsdf.specularWorkflow = m.useSpecularWorkflow;
  out.bsdf.specularColor = glm::dvec3(m.specularColor);
  if (LookupInput(material, MaterialInput::SpecularColor, site, &v))
    out.bsdf.specularColor = glm::clamp(glm::dvec3(v), glm::dvec3(0), glm::dvec3(1));
  out.bsdf.clearcoat = LookupInput(material, MaterialInput::Clearcoat, site, &v) ? Unit(v.x) : m.clearcoat;
  out.bsdf.clearcoatRoughness =
      LookupInput(material, MaterialInput::ClearcoatRoughness, site, &v) ? Unit(v.x) : m.clearcoatRoughness;
  out.emission = glm::dvec3(m.emissiveColor);
  if (LookupInput(material, MaterialInput::EmissiveColor, site, &v))
    out.emission = glm::max(glm::dvec3(v), glm::dvec3(0));
  out.normal = n;
  if (LookupInput(material, MaterialInput::Normal, site, &v)) {
    out.normal = MapNormal(glm::dvec3(v), n, wo, site.frame);
    out.normalMapped = true;
  }
  return out;
}

}  // namespace hdeye
