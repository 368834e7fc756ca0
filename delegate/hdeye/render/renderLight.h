#pragma once
// Lights as the renderer sees them, in world space, with sampling and evaluation (each sampling
// routine has its pdf beside it). Radiance in the scene's radiometric units.
#include "hdeye/params/primParams.h"
#include "hdeye/render/distribution2d.h"
#include "hdeye/render/texture.h"

#include <glm/glm.hpp>

#include <memory>

namespace hdeye {

/// A dome light's lat-long image with its importance-sampling distribution, built once per texture
/// (at light sync) and shared by every RenderLight made from it.
///
/// Orientation (UsdLuxDomeLight, which follows OpenEXR's lat-long environment maps), in the light's
/// local frame: the image's top row is latitude +pi/2 (the +y pole), its bottom row -pi/2 (-y); its
/// left column is longitude +pi, its right column -pi; latitude 0, longitude 0 is +z and longitude
/// +pi/2 is +x. So with texture coordinates (u, v), v = 0 at the bottom row:
///   latitude = pi (v - 1/2), longitude = pi (1 - 2u),
///   direction = (cos(lat) sin(lon), sin(lat), cos(lat) cos(lon)).
/// The light's transform rotates this frame into the world (its scale and translation are ignored).
struct DomeTexture {
  std::shared_ptr<const Texture> image;
  /// Over the image's (u, v), one cell per texel (row 0 at v = 0), weights = luminance x sin(theta)
  /// (theta the polar angle from +y), each texel's luminance taken as the largest of its 3x3
  /// neighbourhood so every direction the bilinear lookup lights has a non-zero pdf.
  Distribution2D distribution;

  /// Throws std::invalid_argument if image is null.
  static std::shared_ptr<const DomeTexture> Build(std::shared_ptr<const Texture> image);
};

/// UsdLuxShapingAPI as the renderer evaluates it (see EmissionShaping).
struct ShapingRt {
  bool enabled = false;
  double cutoff = kHalfTurn;       ///< cone angle, radians off the axis
  double smoothStart = kHalfTurn;  ///< radians: emission smoothsteps from 1 here to 0 at cutoff
  double focus = 0;                ///< exponent of |cos| (0: none)
  glm::dvec3 focusTint{0};
  /// The IES profile (null: none), its angleScale's profile scale 1 + angleScale (>= 0), and the factor its
  /// candela values are multiplied by (1, or 1 / MeanIntensity with shaping:ies:normalize).
  std::shared_ptr<const IesProfile> ies;
  double iesProfileScale = 1;
  double iesFactor = 1;
  static constexpr double kHalfTurn = 3.14159265358979323846;
};

struct LightMotion;

struct RenderLight {
  LightType type = LightType::Sphere;
  /// Emitted radiance (distant: of the sun disk). For a delta light, what it delivers instead: the radiant
  /// intensity of a point (radiance x world area, per steradian), the irradiance normal to a parallel beam, or a
  /// line's radiant intensity per unit length broadside on (2 r L; it falls as the sine of the angle to the axis).
  glm::dvec3 radiance{0};
  /// A point (sphere with treatAsPoint), a line (cylinder with treatAsLine) or a parallel beam (distant with
  /// angle 0): sampled with pdf 1 in LightSample::delta, never met by a ray.
  bool delta = false;
  glm::dvec3 position{0};  ///< sphere centre, rect/disk/cylinder centre
  /// distant: towards the light; rect/disk: emitting normal; sphere: the primary axis (local -z) shaping uses.
  glm::dvec3 direction{0, 0, 1};
  ShapingRt shaping;
  /// rect: half-extent vectors; disk: unit in-plane axes; cylinder: axisU its unit axis (local x)
  glm::dvec3 axisU{1, 0, 0}, axisV{0, 1, 0};
  /// Unit local x and y axes in the world (with `direction`, the light's frame: IES horizontal angles).
  glm::dvec3 frameX{1, 0, 0}, frameY{0, 1, 0};
  double radius = 0;        ///< sphere, disk, cylinder
  double halfLength = 0;    ///< cylinder: half its length along axisU
  double cosHalfAngle = 1;  ///< distant
  /// Dome with a texture: the image (radiance = `radiance` x texel) and its sampling distribution;
  /// null for a constant dome.
  std::shared_ptr<const DomeTexture> dome;
  glm::dmat3 domeToWorld{1.0};  ///< rotation of the dome's frame (see DomeTexture) into the world
  /// Light and shadow linking over GeometryContext::primIndex (RenderPass::Execute fills them from LightParams'
  /// excludes): non-zero where the rprim is not lit by / casts no shadow for this light. Empty: none.
  std::vector<char> unlit, unshadowed;
  /// Rect with a texture: radiance = `radiance` x texel. UsdLux puts the image's first texel (its top-left)
  /// at local (+x, +y) and its last at (-x, -y), so a viewer facing the light sees the image upright:
  /// st = ((1 - a) / 2, (1 + b) / 2) at local point a axisU + b axisV, a and b in [-1, 1].
  std::shared_ptr<const Texture> rectImage;
  /// A light that moves over the shutter (movingLights.h rebuilds it at each path's time); null: static.
  std::shared_ptr<const LightMotion> motion;

  /// Builds a light from its parameters and local-to-world transform (UsdLux conventions: rect and
  /// disk emit along their local -z, a distant light shines along -z, a cylinder from its side around its local
  /// x, not its caps). The radiance, as UsdLuxLightAPI
  /// writes it: color (times BlackbodyColor(colorTemperature) when enabled) * intensity * 2^exposure /
  /// sizeFactor, where sizeFactor is 1 without `normalize`, else the world-space area (sphere 4 pi r^2,
  /// disk pi r^2, rect w h, cylinder side 2 pi r l, with the transform's scale), for a distant light of half-angle t pi
  /// sin^2(t) (t <= pi/2; (2 - sin^2 t) pi above; 1 at t = 0), and 1 for a dome. A sphere with treatAsPoint becomes a
  /// point of radiant intensity pi r^2 times that radiance (what the sphere sends any way: at r = 0 nothing
  /// without normalize, L / 4 with it); a cylinder with treatAsLine a line of what the cylinder sends broadside
  /// on, 2 r L per unit length (L / (pi l) with normalize, at any radius). A dome whose params name a
  /// texture uses `dome` if given (the Light sprim builds it once per texture), else loads the file
  /// and builds the distribution here (slow: for tests and one-off callers). Throws
  /// std::runtime_error naming the file if it cannot be read. A rect light takes its texture from
  /// `rectImage` (the Light sprim opens it; null: untextured, whatever params.textureFile says).
  static RenderLight FromParams(const LightParams& params, const glm::dmat4& transform,
                                std::shared_ptr<const DomeTexture> dome = nullptr,
                                std::shared_ptr<const Texture> rectImage = nullptr);
};

/// Whether the light illuminates the rprim of index primIndex (-1, the camera or no geometry: yes).
inline bool Illuminates(const RenderLight& light, int primIndex) {
  return primIndex < 0 || std::size_t(primIndex) >= light.unlit.size() || !light.unlit[std::size_t(primIndex)];
}
/// Whether the rprim of index primIndex blocks this light's shadow rays.
inline bool CastsShadow(const RenderLight& light, int primIndex) {
  return primIndex < 0 || std::size_t(primIndex) >= light.unshadowed.size() ||
         !light.unshadowed[std::size_t(primIndex)];
}

/// A sampled direction towards a light from a shading point.
struct LightSample {
  glm::dvec3 dir{0};       ///< unit, towards the light
  double distance = 0;     ///< to the sampled point (infinity for distant and dome)
  glm::dvec3 radiance{0};  ///< delta: the irradiance normal to dir it delivers at p (pdf 1)
  double pdf = 0;          ///< solid angle; 0 if the light cannot be sampled from here
  bool delta = false;      ///< a point or a parallel beam: no BSDF sample can find it (no MIS)
  /// A sphere so small seen from p (angular radius below 1e-5 rad) that it is sampled in its point-light
  /// limit: `dir` is exactly towards its centre, `distance` the centre's, and radiance / pdf its intensity
  /// over distance^2 (radiance x pi radius^2 / distance^2, to 1e-10).
  bool pointLimit = false;
};

/// The ShapingAPI factor of light emitted along unit `emitDir` (from the light towards the receiver): 0 past
/// the cone angle, the cone softness's smoothstep (1 - smoothstep(angle, smoothStart, cutoff)), times
/// lerp(focusTint, 1, |emitDir . axis|^focus) per channel, times the IES profile's IesShaping. 1 for a light
/// without shaping.
glm::dvec3 EmissionShaping(const RenderLight& light, const glm::dvec3& emitDir);

/// The IES profile's factor for light emitted along unit `localEmitDir`, in the light's local frame (it emits
/// along -z). As hdEmbree (UsdLux's reference implementation) reads a profile: with w = -localEmitDir (towards
/// the light), theta = acos(w.z), so vertical angle 0 lies along the emitting axis, and the horizontal angle
/// phi = atan2(w.y, w.x) in [0, 360) degrees; the profile is looked up at
/// clamp((theta - 180) / profileScale + 180, 0, 180) and multiplied by iesFactor (candela, or a unitless
/// shape with normalize). 1 without a profile.
double IesShaping(const ShapingRt& shaping, const glm::dvec3& localEmitDir);

/// Radiance the light emits from `pointOnLight` along unit `emitDir` (sphere, rect, disk, cylinder; the texture
/// of a textured rect at that point, times EmissionShaping). For a point light, its intensity along emitDir; for
/// a line, the intensity of its whole length were it all at that point (what one uniform sample along it stands
/// for: 2 halfLength x radiance x sin of emitDir's angle to the axis).
glm::dvec3 EmittedRadiance(const RenderLight& light, const glm::dvec3& pointOnLight, const glm::dvec3& emitDir);

/// The outward unit normal of the emitting surface at `pointOnLight` (sphere and cylinder: radial; rect and
/// disk: `direction`).
glm::dvec3 EmitterNormal(const RenderLight& light, const glm::dvec3& pointOnLight);

/// Samples a direction towards the light from point p, from two uniform numbers.
LightSample SampleLight(const RenderLight& light, const glm::dvec3& p, double u1, double u2);

/// If a ray from p along unit dir meets the light's emitting surface before maxDistance (or, for
/// distant and dome, escapes the scene), the radiance it sees and the solid-angle pdf SampleLight
/// would have given that direction. Returns false otherwise.
bool IntersectLight(const RenderLight& light, const glm::dvec3& p, const glm::dvec3& dir, double maxDistance,
                    glm::dvec3* radiance, double* pdf, double* distance);

}  // namespace hdeye
