#pragma once
// A non-eye hit's UsdPreviewSurface at the hit point: the bound material's constants, with each
// textured input (MaterialParams::textures) looked up at the hit's st through its UsdTransform2d and
// filtered over the ray cone's footprint; tangent-space normal maps (tangents from st); opacityThreshold
// cut-outs.
#include "hdeye/render/previewSurface.h"
#include "hdeye/render/rayCone.h"
#include "hdeye/render/renderContext.h"

namespace hdeye {

/// Where the textures are looked up.
struct TextureSite {
  glm::dvec2 st{0};            ///< the mesh's st primvar at the hit
  TextureFootprint footprint;  ///< the ray cone's footprint in st (before any UsdTransform2d)
  StFrame frame;               ///< dp/ds, dp/dt (world), for normal maps
  TextureThread* thread = nullptr;
};

struct SurfaceShading {
  PreviewSurface bsdf;
  glm::dvec3 emission{0};
  glm::dvec3 normal{0, 0, 1};  ///< the shading normal (normal-mapped), on the side of wo
  bool normalMapped = false;   ///< `normal` comes from a normal map
  bool present = true;         ///< false: an opacityThreshold cut-out; the ray goes on as if nothing were there
};

/// `material` at a hit seen from unit direction wo (away from the surface), whose
/// shading normal is n (unit, on wo's side). `albedo` is the untextured diffuse colour (diffuseColor,
/// or displayColor). Every value returned is finite; colours are clamped where they would add energy.
SurfaceShading ShadeMaterial(const SurfaceMaterial& material, const glm::dvec3& albedo, const glm::dvec3& wo,
                             const glm::dvec3& n, const TextureSite& site);

/// The textured diffuse colour of `material` at the site, or `albedo` if diffuseColor is not textured.
glm::dvec3 TexturedAlbedo(const SurfaceMaterial& material, const glm::dvec3& albedo, const TextureSite& site);

}  // namespace hdeye
