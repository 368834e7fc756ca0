#pragma once
// What happens to a world ray that meets an eye: the hit moves to the canonical
// frame; the limbus blend decides cornea or sclera; the cornea reflects or refracts (Fresnel, chosen
// stochastically, or both traced with their weights: EyeLighting::splitAtEntry); inside the chamber the path walks
// against the analytic model: the iris gets its direct light from every light through MNEE and scatters diffusely, the
// cornea's inside reflects (total internal reflection included) or lets the path out, the pupil absorbs. Light that
// bounces inside the chamber is kept: the walk continues until the path leaves or is absorbed.
//
// Two doors lead to one walk: ScatterAtEye (an analytic eye: the hit found again in double precision)
// and ScatterAtEyeMesh (an eye mesh: the hit mapped onto the analytic cornea) both end in
// ScatterFromCornea, which owns everything from "a point on the analytic cornea and an incoming
// canonical direction" onward.
#include "hdeye/render/eyeGeometry.h"
#include "hdeye/render/eyeMeshMapping.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/renderSettings.h"

#include <eyelib/iris_chamber_cache.h>

#include <eyelib/function_ref.h>

#include <memory>
#include <optional>
#include <vector>

namespace hdeye {

class EntryTables;  // entryTables.h: EyeLighting only points to one

/// What the eye needs from the renderer: its lights, a world-space shadow test, random numbers.
///
/// The eye draws its random numbers in whole pairs (every event an even count, a 2D sample on one pair): the
/// renderer's low-discrepancy sampler pairs dimensions (2k, 2k + 1) into one stratified 2D point (sampleStream.h).
struct EyeLighting {
  const std::vector<RenderLight>* lights = nullptr;
  /// The fraction of light `light` (an index into *lights) reaching `origin` from along unit `dir` within tFar
  /// (world units): 0 blocked, 1 clear, between for thin walls (an occlusion shell) on the way. The light's
  /// shadow linking decides what blocks it. `leaving`: the analytic eye whose cornea origin leaves outwards (the
  /// ray cannot meet it), or null. A reference: the renderer's callable outlives the lighting.
  eyelib::FunctionRef<double(std::size_t light, const glm::dvec3& origin, const glm::dvec3& dir, double tFar,
                             const EyeGeometry* leaving)>
      transmittance;
  /// The eye's GeometryContext::primIndex: lights linked away from it (Illuminates) give it nothing, MNEE
  /// included.
  int receiver = -1;
  /// The eye's switches (eyeSwitches.h): the lighting reads mnee (off: MNEE is not run; the iris's direct light
  /// comes only from paths that leave the cornea and hit a light) and mneeAllSolutions.
  EyeSwitches switches;
  /// With switches.mnee: which lights MNEE counts (EyeRenderOptions::mneeLights, over *lights); the others reach
  /// the iris only by paths that leave it. Null or of another length: every light.
  const std::vector<bool>* mneeLights = nullptr;
  /// The chamber walk's bound: events inside the anterior chamber before the path is dropped.
  int maxChamberEvents = 64;
  /// MNEE estimates averaged at a walk's first iris vertex (RenderSettings::irisLightSplits).
  int irisLightSplits = 1;
  /// Chamber walks from a walk's first iris vertex (RenderSettings::chamberSplits): the extra ones only gather
  /// iris light, each weighing 1 / chamberSplits with the walk's own from then on.
  int chamberSplits = 1;
  /// With switches.mnee: how the iris gathers chamber light; Cache and ControlVariate need `chamberCache` (null: Path).
  ChamberEstimator chamberEstimator = ChamberEstimator::Path;
  /// The eye's chamber light, on the same MNEE lights (ChamberLightCaches::Get), or null. Not owned: the tracer that
  /// set it holds the cache while it lives (a path copies its lighting at every branch, a shared pointer's count too).
  const eyelib::IrisChamberCache* chamberCache = nullptr;
  /// Where each small light's centre enters this eye, tabulated (the renderer's, for a still eye; a moving light is
  /// never looked up), or null: computed at each iris point. Mutable: tables are fetched when first asked for.
  EntryTables* entryTables = nullptr;
  /// With switches.mnee: the probability MNEE picks each light with (over *lights, MneeLightPick), or null or of
  /// another length: uniformly among the lights it counts.
  const std::vector<double>* mneePick = nullptr;
  /// Trace both the reflection off the cornea and the refraction into it at the entry, with their Fresnel
  /// weights (EyeEvent::reflection beside the walk), instead of choosing one by F: the glint otherwise comes
  /// from 1 path in 1 / F (about 40 at 25 degrees), in steps of a tenth of its value at hundreds of samples.
  bool splitAtEntry = false;
  /// With splitAtEntry: the entry gives its reflection alone and no walk (the event is Absorbed beside it). The
  /// catchlight's sub-samples (RenderSettings::catchlightSamples) estimate only that branch.
  bool reflectionOnly = false;
};

/// Whether MNEE counts light `index` of *lighting.lights for this eye (and paths straight out of the iris
/// must therefore skip it): the one place both sides of the split read, so no light is counted twice or
/// not at all.
inline bool MneeCountsLight(const EyeLighting& lighting, std::size_t index) {
  if (!lighting.switches.mnee) return false;
  // A light linked away from the eye is counted by neither: the path leaving the iris skips it too (the renderer
  // checks Illuminates against the vertex a ray left).
  if (lighting.lights && !Illuminates((*lighting.lights)[index], lighting.receiver)) return false;
  const std::vector<bool>* mask = lighting.mneeLights;
  if (!mask || !lighting.lights || mask->size() != lighting.lights->size()) return true;
  return (*mask)[index];
}

struct EyeEvent {
  enum Kind { Continue, Sclera, Absorbed } kind = Absorbed;
  glm::dvec3 origin{0}, dir{0};  ///< Continue: the next world ray
  glm::dvec3 weight{1};          ///< Continue: multiplies the path throughput
  /// Radiance the walk gathered (iris direct light through MNEE), already weighted by the walk's
  /// own throughput; the renderer multiplies it by the path throughput that reached the eye.
  glm::dvec3 radiance{0};
  /// The path left the eye straight from an iris bounce through one refraction: the lights MNEE counts
  /// (MneeCountsLight) are MNEE's (it already did), so the renderer skips those when the path hits them;
  /// lights MNEE does not count, it must count in full (they have no other estimator at the iris).
  bool skipLightHits = false;
  /// Continue: the ray did not interact (an eye mesh seen from inside); the renderer keeps the path's
  /// light-weighting state as it was.
  bool passThrough = false;
  /// Continue: reflected off the cornea at the entry point (never entered the chamber).
  bool reflectedAtEntry = false;
  /// A second ray leaving the eye: the reflection off the cornea at the entry when EyeLighting::splitAtEntry
  /// traced it beside the walk (whatever the walk's kind); weight 0: none.
  struct Branch {
    glm::dvec3 origin{0}, dir{0};  ///< the world ray
    double weight = 0;             ///< the Fresnel reflectance F (the walk's exit then weighs 1 - F)
  } reflection;
  glm::dvec3 scleraAlbedo{0}, normal{0};  ///< Sclera: shade as a diffuse surface (world normal)
  /// Sclera on an eye mesh: shade the mesh surface itself (its shading normal; `normal` is unset) with
  /// scleraAlbedo, or with its bound material when EyeGeometry::scleraUsesMaterial.
  bool scleraOnSurface = false;
  int internalEvents = 0;       ///< events inside the chamber
  bool walkCapReached = false;  ///< the walk hit its event bound (reported, the path is dropped)
};

/// A path arriving at the analytic cornea from outside, in the canonical frame.
struct CorneaEntry {
  glm::dvec3 point;   ///< mm, on the analytic anterior surface
  glm::dvec3 normal;  ///< unit, outward, the analytic surface's normal at point
  glm::dvec3 dir;     ///< unit, incoming: dot(dir, normal) < 0
};

/// Scatters a world ray (origin, unit direction) that hit `part` of an analytic eye. The entry is the cornea point
/// the eye's intersection found in double precision (`cornea`; Embree reports a user geometry's distance in float,
/// which puts the point microns off the cornea, on either side), or, without one, found again here.
EyeEvent ScatterAtEye(const EyeGeometry& eye, const glm::dvec3& worldOrigin, const glm::dvec3& worldDir,
                      EyeGeometry::Part part, const EyeLighting& lighting, eyelib::FunctionRef<double()> random,
                      const std::optional<CorneaPoint>& cornea = std::nullopt);

/// Scatters a world ray (unit direction) that hit an eye mesh, mapped by EyeMeshHitToCanonical.
/// Off the cornea (past the outer limbus edge, below the iris plane, outside the projection) it is
/// sclera (the mesh surface's). On it, the path continues against the analytic model from the
/// analytic point at the hit's projected (x, y) with the mapped direction (eyeMeshMapping.h). Re-projected
/// hits send every leaving ray (reflection, exit) from the deformed hit point, turned back by the hit's
/// local rotation; baseline hits leave as the analytic eye in the affine frame puts them (a reflection at
/// entry from the mesh point). A hit from inside passes through.
EyeEvent ScatterAtEyeMesh(const EyeGeometry& eye, const EyeMeshHit& hit, const glm::dvec3& worldDir,
                          const EyeLighting& lighting, eyelib::FunctionRef<double()> random);

/// Everything from a point on the analytic cornea onward: the limbus (sclera with its weight's
/// probability), Fresnel reflection or refraction, the chamber walk, the exit. World rays of Continue
/// events come from the analytic geometry through eye.canonicalToWorld.
EyeEvent ScatterFromCornea(const EyeGeometry& eye, const CorneaEntry& entry, const EyeLighting& lighting,
                           eyelib::FunctionRef<double()> random);

/// The probability of MNEE picking each of *lighting.lights at the eye (0 for a light it does not count, and for a
/// dome, which it estimates in every sample), by what each is predicted to bring the iris: its irradiance at the apex,
/// unshadowed, the cornea left out, times 0.1 plus the cosine of its direction off the gaze (clamped at 0: the iris
/// sees through the cornea what is ahead of the eye). A fifth of the probability is spread uniformly, so that a
/// prediction far off (an occluded key, a shaped spot) costs variance, never bias. One light, or lights predicted to
/// bring nothing: uniform.
std::vector<double> MneeLightPick(const EyeGeometry& eye, const EyeLighting& lighting);

/// Irradiance (world units) at iris point x (canonical, mm) through the cornea by MNEE from the lights MNEE counts
/// (MneeCountsLight): every dome among them, plus one of the others chosen by lighting.mneePick (uniformly without
/// it) over its probability; a one-sample estimate of their sum.
glm::dvec3 IrisIrradianceMnee(const EyeGeometry& eye, const glm::dvec3& x, const EyeLighting& lighting,
                              eyelib::FunctionRef<double()> random);

}  // namespace hdeye
