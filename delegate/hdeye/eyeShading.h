#pragma once
// What happens to a world ray that meets an eye, following DESIGN.md: the hit moves to the canonical
// frame; the limbus blend decides cornea or sclera; the cornea reflects or refracts (Fresnel, chosen
// stochastically); inside the chamber the path walks against the analytic model: the iris gets its
// direct light from every light through MNEE and scatters diffusely, the cornea's inside reflects
// (total internal reflection included) or lets the path out, the pupil absorbs. Light that bounces
// inside the chamber is kept: the walk continues until the path leaves or is absorbed.
#include "hdeye/eyeGeometry.h"
#include "hdeye/renderLight.h"

#include <functional>
#include <vector>

namespace hdeye {

/// What the eye needs from the renderer: its lights, a world-space occlusion test, random numbers.
struct EyeLighting {
  const std::vector<RenderLight>* lights = nullptr;
  std::function<bool(const glm::dvec3& origin, const glm::dvec3& dir, double tFar)> occluded;
  bool allSolutions = false;  ///< MNEE searches for every refraction path (caustic folds)
};

struct EyeEvent {
  enum Kind { Continue, Sclera, Absorbed } kind = Absorbed;
  glm::dvec3 origin{0}, dir{0};  ///< Continue: the next world ray
  glm::dvec3 weight{1};          ///< Continue: multiplies the path throughput
  /// Radiance the walk gathered (iris direct light through MNEE), already weighted by the walk's
  /// own throughput; the renderer multiplies it by the path throughput that reached the eye.
  glm::dvec3 radiance{0};
  /// The path left the eye straight from an iris bounce through one refraction: the lights it may hit
  /// next are MNEE's to count (it already did), so the renderer skips them.
  bool skipLightHits = false;
  glm::dvec3 scleraAlbedo{0}, normal{0};  ///< Sclera: shade as a diffuse surface (world normal)
  int internalEvents = 0;        ///< events inside the chamber
  bool walkCapReached = false;   ///< the walk hit its event bound (reported, the path is dropped)
};

/// Scatters a world ray (origin, unit direction) that hit `part` of the eye. The hit is found again
/// in the canonical frame in double precision: Embree reports a user geometry's distance in float,
/// which puts the point microns off the cornea, on either side.
EyeEvent ScatterAtEye(const EyeGeometry& eye, const glm::dvec3& worldOrigin, const glm::dvec3& worldDir,
                      EyeGeometry::Part part, const EyeLighting& lighting, const std::function<double()>& random);

/// Irradiance (world units) at iris point x (canonical, mm) from one light chosen uniformly, through
/// the cornea by MNEE: a one-sample estimate.
glm::dvec3 IrisIrradianceMnee(const EyeGeometry& eye, const glm::dvec3& x, const EyeLighting& lighting,
                              const std::function<double()>& random);

}  // namespace hdeye
