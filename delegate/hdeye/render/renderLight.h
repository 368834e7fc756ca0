#pragma once
// Lights as the renderer sees them, in world space, with sampling and evaluation (each sampling
// routine has its pdf beside it). Radiance in the scene's radiometric units.
#include "hdeye/render/distribution2d.h"
#include "hdeye/render/params.h"
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

struct RenderLight {
  LightType type = LightType::Sphere;
  glm::dvec3 radiance{0};    ///< emitted radiance (distant: of the sun disk)
  glm::dvec3 position{0};    ///< sphere centre, rect/disk centre
  glm::dvec3 direction{0, 0, 1};  ///< distant: towards the light; rect/disk: emitting normal
  glm::dvec3 axisU{1, 0, 0}, axisV{0, 1, 0};  ///< rect: half-extent vectors; disk: unit in-plane axes
  double radius = 0;         ///< sphere, disk
  double cosHalfAngle = 1;   ///< distant
  /// Dome with a texture: the image (radiance = `radiance` x texel) and its sampling distribution;
  /// null for a constant dome.
  std::shared_ptr<const DomeTexture> dome;
  glm::dmat3 domeToWorld{1.0};  ///< rotation of the dome's frame (see DomeTexture) into the world
  /// Rect with a texture: radiance = `radiance` x texel. UsdLux puts the image's first texel (its top-left)
  /// at local (+x, +y) and its last at (-x, -y), so a viewer facing the light sees the image upright:
  /// st = ((1 - a) / 2, (1 + b) / 2) at local point a axisU + b axisV, a and b in [-1, 1].
  std::shared_ptr<const Texture> rectImage;

  /// Builds a light from its parameters and local-to-world transform (UsdLux conventions: rect and
  /// disk emit along their local -z, a distant light shines along -z). A dome whose params name a
  /// texture uses `dome` if given (the Light sprim builds it once per texture), else loads the file
  /// and builds the distribution here (slow: for tests and one-off callers). Throws
  /// std::runtime_error naming the file if it cannot be read. A rect light takes its texture from
  /// `rectImage` (the Light sprim opens it; null: untextured, whatever params.textureFile says).
  static RenderLight FromParams(const LightParams& params, const glm::dmat4& transform,
                                std::shared_ptr<const DomeTexture> dome = nullptr,
                                std::shared_ptr<const Texture> rectImage = nullptr);
};

/// A sampled direction towards a light from a shading point.
struct LightSample {
  glm::dvec3 dir{0};         ///< unit, towards the light
  double distance = 0;       ///< to the sampled point (infinity for distant and dome)
  glm::dvec3 radiance{0};
  double pdf = 0;            ///< solid angle; 0 if the light cannot be sampled from here
  /// A sphere so small seen from p (angular radius below 1e-5 rad) that it is sampled in its point-light
  /// limit: `dir` is exactly towards its centre, `distance` the centre's, and radiance / pdf its intensity
  /// over distance^2 (radiance x pi radius^2 / distance^2, to 1e-10).
  bool pointLimit = false;
};

/// Samples a direction towards the light from point p, from two uniform numbers.
LightSample SampleLight(const RenderLight& light, const glm::dvec3& p, double u1, double u2);

/// If a ray from p along unit dir meets the light's emitting surface before maxDistance (or, for
/// distant and dome, escapes the scene), the radiance it sees and the solid-angle pdf SampleLight
/// would have given that direction. Returns false otherwise.
bool IntersectLight(const RenderLight& light, const glm::dvec3& p, const glm::dvec3& dir, double maxDistance,
                    glm::dvec3* radiance, double* pdf, double* distance);

}  // namespace hdeye
