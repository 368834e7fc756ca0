#pragma once
// What the renderer is given of cameras, lights, materials and eyes: the parameters a scene delegate returns
// (hd/sceneDelegate.h) and the prims hand on to the renderer. World units are whatever the scene uses (USD:
// usually cm or m); eyes carry their own transform into eyelib's canonical millimetre frame.
#include "hdeye/params/iesProfile.h"
#include "hdeye/params/textureParams.h"

#include <eyelib/anterior_chamber.h>

#include <glm/glm.hpp>

#include <array>
#include <string>
#include <vector>

namespace hdeye {

using Matrix4d = glm::dmat4;  ///< column vectors: world = M * local
using Vec3f = glm::vec3;
using Vec2f = glm::vec2;

/// Camera parameters, in the units USD uses for them.
struct CameraParams {
  bool orthographic = false;
  double focalLength = 50;                ///< mm (perspective)
  double horizontalAperture = 36;         ///< mm, or scene units of width (orthographic)
  double verticalAperture = 24;           ///< mm, or scene units of height (orthographic)
  double nearClip = 1e-3, farClip = 1e7;  ///< scene units
  /// Thin-lens depth of field (UsdGeomCamera): the lens's f-number (unitless); 0 is a pinhole (no blur).
  double fStop = 0;
  /// Distance from the lens to the plane in focus, scene units (> 0 when fStop > 0).
  double focusDistance = 0;
  /// Scene units per unit of focalLength (and, for perspective cameras, the apertures): USD's tenth of a
  /// scene unit (Gf.Camera's convention, 0.1: focalLength 50 is 5 scene units, 50 mm in a cm scene). Sizes the
  /// lens aperture: diameter = focalLength * focalLengthUnit / fStop, scene units.
  double focalLengthUnit = 0.1;
  /// The shutter interval, frames relative to the frame (UsdGeomCamera shutter:open / shutter:close, or the render's
  /// override): each camera path carries a time in [shutterOpen, shutterClose] and sees the scene as it is then.
  /// open == close is a sharp render at that time (0: today's render, bit for bit).
  double shutterOpen = 0, shutterClose = 0;
};

/// The lens aperture's diameter of a camera, scene units (0 for a pinhole or orthographic camera).
inline double LensApertureDiameter(const CameraParams& p) {
  return p.orthographic || !(p.fStop > 0) ? 0.0 : p.focalLength * p.focalLengthUnit / p.fStop;
}

/// The light kinds the delegate renders.
enum class LightType { Sphere, Distant, Rect, Disk, Dome, Cylinder };

/// UsdLuxShapingAPI: the cone and focus of a light's emission about its primary axis (local -z).
struct LightShaping {
  bool enabled = false;          ///< the prim has ShapingAPI (otherwise the fields below are ignored)
  float coneAngle = 90;          ///< degrees off the axis past which the light emits nothing
  float coneSoftness = 0;        ///< [0, 1]: the fraction of the cone over which emission smoothsteps to 0
  float focus = 0;               ///< exponent of |cos(off-axis angle)| (< 0: ignored)
  glm::vec3 focusTint{0, 0, 0};  ///< colour the focus falloff tends to off the axis (white: no focus)
  /// shaping:ies:file, parsed (the scene delegate reads the file); empty: no profile. Its intensity (candela)
  /// multiplies the emission (RenderLight::FromParams has the angles).
  IesProfile ies;
  /// shaping:ies:angleScale: the profile is looked up at vertical angle (theta - 180) / (1 + angleScale) + 180
  /// degrees (clamped to [0, 180]; angleScale below -1 taken as -1).
  float iesAngleScale = 0;
  bool iesNormalize = false;  ///< divide the profile by its mean intensity (IesProfile::MeanIntensity)
};

/// Light parameters (UsdLux). Radiance = color (or the colorTemperature's blackbody colour, times color)
/// * intensity * 2^exposure / sizeFactor (renderLight.h: RenderLight::FromParams, with the formulas).
struct LightParams {
  /// Set by the light sprim from its prim type (what a scene delegate passes here is ignored).
  LightType type = LightType::Sphere;
  glm::vec3 color{1, 1, 1};
  float intensity = 1, exposure = 0;  ///< intensity in nits (radiance); exposure in stops
  /// Divide the radiance by the light's world-space area (distant: by its angular size), so resizing keeps
  /// its power (distant: intensity becomes the illuminance, lux, of a surface facing it).
  bool normalize = false;
  bool enableColorTemperature = false;
  float colorTemperature = 6500;  ///< kelvin, [1000, 10000]: blackbody colour, 6500 = white (used when enabled)
  /// Sphere: render as a point light with the sphere's radiant intensity (pi r^2 L, r in world units).
  bool treatAsPoint = false;
  LightShaping shaping;
  /// Cylinder: render as a line along its axis with the cylinder's radiant intensity (2 r L sin of the angle
  /// to the axis per unit length, r and the length in world units).
  bool treatAsLine = false;
  float radius = 0.5f;          ///< sphere, disk, cylinder (scene units)
  float length = 1;             ///< cylinder, along its local x (scene units)
  float width = 1, height = 1;  ///< rect (scene units)
  float angle = 0.53f;          ///< distant: angular diameter, degrees
  /// Dome: a lat-long image; rect: an image over the rectangle (RenderLight::rectImage's orientation). Any
  /// format OpenImageIO reads; empty: a constant colour.
  std::string textureFile;
  /// Dome: the lat-long image's top pole is the light's local +z (UsdLuxDomeLight_1 poleAxis "Z", or "scene" on
  /// a Z-up stage), a +90 degree turn about x of the default +y pole; false: +y (UsdLuxDomeLight).
  bool domePoleZ = false;
  /// Light linking (UsdLuxLightAPI's collection:lightLink, resolved by the scene delegate): the rprims this light
  /// does not illuminate. Empty: it lights everything.
  std::vector<std::string> lightLinkExcludes;
  /// Shadow linking (collection:shadowLink): the rprims whose shadows this light ignores (its shadow rays pass
  /// through them). Empty: everything casts shadows.
  std::vector<std::string> shadowLinkExcludes;
};

/// The UsdPreviewSurface inputs a texture can drive.
enum class MaterialInput {
  DiffuseColor,
  EmissiveColor,
  Roughness,
  Metallic,
  Opacity,
  Ior,
  Normal,
  SpecularColor,
  Clearcoat,
  ClearcoatRoughness,
  Count
};
constexpr int kMaterialInputCount = int(MaterialInput::Count);

/// A material input read from a UsdUVTexture: the texture, which of its outputs, and the UsdTransform2d
/// between the mesh's st primvar and the texture's st (st' = R(rotation) (st * scale) + translation).
struct TextureInput {
  TextureParams texture;  ///< texture.file empty: the input is not textured
  int channel = -1;       ///< the UsdUVTexture output: -1 rgb, 0..3 r, g, b, a (float inputs take one)
  glm::vec2 scale{1, 1};
  float rotation = 0;  ///< degrees, counter-clockwise
  glm::vec2 translation{0, 0};
  bool Active() const { return !texture.file.empty(); }
};

/// Material parameters (UsdPreviewSurface subset). Colours are linear; opacity below 1 makes the
/// surface a dielectric of index `ior` (glass), unless opacityThreshold > 0 makes opacity a cut-out mask.
struct MaterialParams {
  glm::vec3 diffuseColor{0.18f, 0.18f, 0.18f};
  /// diffuseColor reads the prim's displayColor (a UsdPrimvarReader of it): the instancer's per-instance colour or
  /// the prim's displayColor where there is one, else diffuseColor (the reader's fallback).
  bool diffuseFromDisplayColor = false;
  glm::vec3 emissiveColor{0, 0, 0};
  float roughness = 0.5f;  ///< GGX, perceptual (alpha = roughness^2), [0, 1]
  float metallic = 0;      ///< [0, 1]
  float opacity = 1;       ///< [0, 1]
  /// [0, 1]. Above 0: a point whose opacity is below it is not there (card eyelashes, leaves), and one
  /// at or above it is opaque.
  float opacityThreshold = 0;
  float ior = 1.5f;  ///< dielectric index of refraction (>= 1)
  /// useSpecularWorkflow: the specular lobe's colour at normal incidence is specularColor (white at the
  /// edge) instead of coming from metallic and ior.
  bool useSpecularWorkflow = false;
  glm::vec3 specularColor{0, 0, 0};  ///< linear, [0, 1]
  float clearcoat = 0;               ///< [0, 1]: a white coat of index 1.5 over everything
  float clearcoatRoughness = 0.01f;  ///< perceptual, [0, 1]
  /// Inputs driven by textures (looked up by the mesh's `st` primvar), indexed by MaterialInput; an
  /// active one replaces the constant above. Normal: a tangent-space normal map (tangents from st).
  std::array<TextureInput, kMaterialInputCount> textures;
  TextureInput& Texture(MaterialInput i) { return textures[std::size_t(i)]; }
  const TextureInput& Texture(MaterialInput i) const { return textures[std::size_t(i)]; }
};

/// An eye's parameters (the EyeAPI schema's attributes). Lengths in the canonical frame are mm.
struct EyeParams {
  eyelib::ChamberParams chamber;           ///< model, iris depth, pupil, limbus ratios, cornea ior
  glm::vec3 irisColor{0.35f, 0.2f, 0.1f};  ///< diffuse albedo of the iris
  glm::vec3 scleraColor{0.8f, 0.78f, 0.75f};
  /// Image over the iris disk in the canonical frame (u along +x, v along +y, the disk of diameter
  /// ChamberParams' iris diameter filling [0, 1]^2); irisColor multiplies it (white: the texture as is).
  std::string irisTexture;
  /// Canonical frame (mm, apex at the origin, gaze +z) to the prim's local space. A similarity
  /// (rotation, uniform scale, translation); e.g. scale 0.1 for a scene in centimetres.
  Matrix4d modelTransform{1.0};
  /// The limbal arc (Chiang and Burley 2018, section 3): the teleportation cylinder inside the sclera's
  /// random walk. Only eye meshes have a sclera volume; analytic eyes ignore it.
  bool limbalArc = true;
  /// Sclera scattering distance per RGB channel, mm (the artist's mean free path; > 0 and finite).
  glm::vec3 scleraMeanFreePath{1.0f, 0.8f, 0.6f};  ///< mm
  /// Eye meshes: the artist's iris projection frame (eye:irisProjection) to the prim's local
  /// space, so it moves with the eye. A rest point q in this frame projects along its z onto its xy
  /// plane: canonical (x, y) = 7.54 mm * (q.x, q.y), i.e. the frame's [-1, 1]^2 square is the iris
  /// texture's square (the 15.08 mm iris disk inscribed). Unused unless hasIrisProjection; the default
  /// is the model frame along the gaze: modelTransform * scale(7.54).
  Matrix4d irisProjection{1.0};
  bool hasIrisProjection = false;
  /// Eye meshes: re-project hits onto the analytic model (the paper's method). Off is the comparison
  /// baseline of docs/deformed_eyes.md: the analytic eye carried by the mesh's best-fit affine
  /// deformation, its optics following that frame (what putting the deformation into the eye's
  /// transform would give).
  bool reprojection = true;
};

}  // namespace hdeye
