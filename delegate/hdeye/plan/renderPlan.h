#pragma once
// The render plan (docs/render_plan.md): after sync and before rendering, decide for
// each eye everything the artist did not author (MNEE per light, the all-solutions search, chamber
// depth, sclera scattering and the limbal arc, subdivision level, precision) from what the scene
// shows: the eye's size on screen, whether it is in view, and each light's solid angle and direction
// as seen from the eye. Every decision carries a one-line reason; anything the user set explicitly
// (an authored schema value, a render setting or a command-line flag, gathered in PlanOverrides) wins
// and the reason says so ("authored" / "flag").
//
// Every threshold is in PlanRules, each with the sweep it comes from (bench/bench_plan.py,
// docs/render_plan.md). Python turns a plan into the JSON eyerecord prints (eyerender/plan.py).
//
// Application: ApplyRenderPlan writes each eye's decisions into that eye rprim's EyeRenderOptions
// (eyeRenderOptions.h), which the renderer reads from the eye it is shading: MNEE per light, the
// all-solutions search, the chamber walk's bound, the sclera walk and the limbal arc. Two eyes in one
// frame render each with its own plan; a dome and a key at one eye split between BSDF sampling and MNEE,
// each light counted by exactly one of them. The global RenderSettings switches stay the defaults of eyes
// no plan reached (and of renders without a plan); flags reach the plan through PlanOverrides and win there.
// Eye meshes' refineLevel is applied too (the mesh re-refines when its level changes: a topology change for that
// mesh only). Reported, not applied: precision (one arithmetic exists; the plan says when float would do).
#include "hdeye/hd/types.h"
#include "hdeye/plan/meshRefinePlan.h"
#include "hdeye/render/cameraView.h"
#include "hdeye/render/eyeGeometry.h"
#include "hdeye/render/eyeRenderOptions.h"
#include "hdeye/render/renderLight.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hdeye {

class RenderIndex;
struct RenderSettings;

/// The planner's thresholds. Each number was measured by the sweep named beside it (bench/bench_plan.py); the
/// measurements, and why each number follows from them, are in docs/render_plan.md under that sweep's name.
struct PlanRules {
  /// Pixels: eyes whose 15.08 mm iris circle projects smaller get no MNEE. 0: MNEE at any size (sweep 1).
  double mneeMinPixels = 0;
  /// Steradians: a light whose solid angle seen from the eye exceeds this is left to BSDF sampling with MIS
  /// (sweep 2); mneeMaxSolidAngleSrGrazing for lights at least grazingAngleDeg (degrees) off the gaze (sweep 2
  /// at 45-75 deg).
  double mneeMaxSolidAngleSr = 1.0;
  double mneeMaxSolidAngleSrGrazing = 0.2;
  double grazingAngleDeg = 65;
  /// A dome goes to MNEE (estimated in every sample) when its radiance contrast over the eye's front hemisphere
  /// (LightFacts::radianceContrast) is at least this; a smoother dome is left to BSDF sampling (sweep dome-contrast:
  /// over the whole eye MNEE pays from about 2.2 with a key, 2.3 alone; over the iris alone it pays at every contrast).
  double mneeMinDomeContrast = 2.2;
  /// All-solutions MNEE (every refraction path) only for an MNEE light at least allSolutionsMinAngleDeg
  /// (degrees) off the gaze, where second paths exist (sweep 3), on eyes at least allSolutionsMinPixels wide
  /// (pixels; sweep allsol-size).
  double allSolutionsMinAngleDeg = 80;
  double allSolutionsMinPixels = 200;
  /// Chamber events followed per path (EyeRenderOptions::maxChamberEvents) for every eye: the full walk (sweep
  /// chamber).
  int chamberEvents = 64;
  /// The chamber-light cache's grid (EyeRenderOptions::chamberCacheRings): a ring per chamberCachePixelsPerRing
  /// pixels of the iris circle's resolved diameter (2.5: about a ring per pixel of the iris annulus on screen),
  /// rounded up to a multiple of 4, between chamberCacheMinRings and chamberCacheMaxRings (the default grid, from
  /// 120 px). A build costs MNEE at 3 rings^2 nodes (sweep chamber-cache).
  double chamberCachePixelsPerRing = 2.5;
  int chamberCacheMinRings = 12;
  int chamberCacheMaxRings = 48;
  /// Pixels: eye meshes whose iris circle is at least this wide walk their sclera (random-walk SSS); smaller
  /// ones get a Lambertian sclera (sweep sclera).
  double sssMinPixels = 2.5;
  /// Pixels: the limbal arc (teleportation cylinder) needs the projected limbus band ((outer - inner limbus
  /// diameter) / 2) at least this wide. 0: no band condition (sweep sclera).
  double sssMinLimbusPixels = 0;
  /// Degrees: the limbal arc only with some light at least this far off the gaze. 0: the arc goes with the walk
  /// (sweeps sclera and dome-arc).
  double limbalArcMinLightAngleDeg = 0;
  /// Pixels: eye meshes subdivide one level per doubling of the eye's size above this, up to refineMaxLevel
  /// (Catmull-Clark level), capped by the --complexity ceiling and the mesh's populate level (sweep refine).
  double refinePixelsLevel1 = 64;
  int refineMaxLevel = 2;
  /// Precision, reported only (eyes are traced in double; there is no float eye path): float would be enough
  /// where the analytic intersection's worst float hit error (mm, measured in docs/intersection_benchmark.md)
  /// is under floatMaxErrorPixels of a pixel (a stated criterion, not a sweep: docs/render_plan.md).
  double floatHitErrorMm = 3.0e-4;
  double floatMaxErrorPixels = 0.01;
};

/// What the user set explicitly: each set value wins over the planner. Flags and render settings are
/// render-wide; authored values are per eye prim and win over flags for that eye.
struct PlanOverrides {
  std::optional<bool> mnee;              ///< flag: --no-mnee / --mnee, or RenderSettings set by hand
  std::optional<bool> mneeAllSolutions;  ///< flag: --mnee-all-solutions
  std::optional<bool> scleraScattering;  ///< flag / setting: random-walk sclera (true) or diffuse (false)
  std::optional<bool> limbalArc;         ///< flag
  /// Events the chamber walk follows per path (EyeRenderOptions::maxChamberEvents), >= 1: set by hand (the
  /// chamber sweep of bench/bench_plan.py drives it through this).
  std::optional<int> chamberEvents;
  int refineLevelCeiling = 3;  ///< --complexity: the planner's subdivision level never exceeds it
  /// Schema values authored on an eye prim (HasAuthoredValue, not the fallback).
  struct Authored {
    std::optional<bool> limbalArc;  ///< eye:limbalArc
  };
  std::map<PrimId, Authored> authored;
};

/// How the iris gets a light's direct light.
enum class LightStrategy {
  Mnee,  ///< manifold next event estimation through the cornea
  Bsdf,  ///< BSDF sampling with MIS: paths that leave the cornea and hit the light
  None,  ///< the light cannot reach the iris
};

/// How an eye's sclera is shaded.
enum class ScleraModel {
  RandomWalk,  ///< path-traced random-walk subsurface scattering (eye meshes)
  Diffuse,     ///< a Lambertian surface
  None,        ///< no sclera volume to walk (analytic eyes)
};

/// The names the plan's JSON and summary lines use: "mnee", "bsdf", "none"; "randomWalk", "diffuse", "none";
/// "sphere", "distant", "rect", "disk", "dome".
const char* ToString(LightStrategy strategy);
const char* ToString(ScleraModel model);
const char* ToString(LightType type);

/// One light as one eye sees it, and what the eye does with it.
struct LightFacts {
  PrimId light;
  LightType kind = LightType::Sphere;
  double solidAngleSr = 0;        ///< subtended at the iris centre, steradians (dome: 4 pi)
  double angleOffGazeDeg = -1;    ///< gaze to the light's centre, degrees; -1 for a dome (no direction)
  double angularRadiusDeg = 180;  ///< half the angle the light subtends, degrees
  bool reachesIris = true;        ///< some part above the rim plane (else the sclera hides it: MNEE finds nothing)
  /// Dome: E[L^2] / E[L]^2 of its luminance over cosine-distributed directions about the gaze (1: uniform; a
  /// window 20 times brighter than the sky around it: about 4). How much a direction the iris's BSDF samples misses
  /// or finds the bright part decides the BSDF estimate's noise; MNEE samples the dome by its texture. 1 otherwise.
  double radianceContrast = 1;
  LightStrategy strategy = LightStrategy::Bsdf;
  std::string why;
};

/// An eye's facts and decisions. Each decision names its reason in `why` (same key).
struct EyePlan {
  PrimId prim;
  std::string geometry;  ///< analyticEye or eyeMesh
  /// Projected diameter of the 15.08 mm iris/limbus circle, pixels (the longest chord of its image;
  /// 0 when behind the camera).
  double pixels = 0;
  bool inView = false;        ///< some of the circle projects inside the image, in front of the camera
  bool behindCamera = false;  ///< all of it behind the camera plane
  double viewAngleDeg = 0;    ///< gaze to the direction from the eye to the camera, degrees (0: looking at it)
  double limbusPixels = 0;    ///< the limbus band's projected width, pixels
  /// Depth of field: the circle of confusion's diameter at the iris centre's depth, pixels (thin lens:
  /// A f |D - F| / (D F) on the film, A the aperture, F the focus distance, D the eye's depth; 0 for a pinhole).
  double blurPixels = 0;
  /// `pixels` as detail: the iris circle's size in blur disks, pixels / max(1, blurPixels). The size rules
  /// (all solutions, sclera walk, limbal arc band, subdivision level, float footprint) read this; MNEE, which
  /// brings the caustic's energy whatever blurs it, reads `pixels`.
  double resolvedPixels = 0;
  std::vector<LightFacts> lights;

  /// The eye's switches (eyeSwitches.h), as ApplyRenderPlan gives them to the eye: mnee (MNEE for at least one
  /// light), mneeAllSolutions, scleraScattering (sss is RandomWalk) and limbalArc (the teleportation cylinder).
  EyeSwitches switches{false, false, false, false};
  /// Chamber events followed per path (the walk's bound inside the anterior chamber): applied as
  /// EyeRenderOptions::maxChamberEvents.
  int chamberEvents = 64;
  int chamberCacheRings = 32;  ///< rings of the chamber-light cache's grid (EyeRenderOptions::chamberCacheRings)
  ScleraModel sss = ScleraModel::Diffuse;  ///< the sclera's model, as reported (switches.scleraScattering: RandomWalk)
  int refineLevel = -1;                    ///< eye meshes: planned Catmull-Clark level; -1 analytic (no mesh)
  /// Millimetres of the eye per resolved pixel: the 15.08 mm iris circle over `resolvedPixels` (the blur disk
  /// widens it; infinite when not projected).
  double pixelFootprintMm = 0;
  /// Float's measured worst hit error is under PlanRules::floatMaxErrorPixels of a pixel here: float would be
  /// enough for this eye's intersections. Reported only: the renderer has no float eye path.
  bool floatWouldSuffice = false;
  std::map<std::string, std::string> why;  ///< decision name -> short reason

  /// The switches ApplyRenderPlan gives this eye. `lightOrder`: the render's light list (light prim ids in
  /// the order RenderPass::Execute hands them to the renderer); a light the plan did not measure keeps MNEE
  /// (the renderer's behaviour without a plan).
  EyeRenderOptions RenderOptions(const std::vector<PrimId>& lightOrder) const;
};

struct RenderPlan {
  int width = 0, height = 0;  ///< image pixels the plan was made for
  PrimId camera;
  std::vector<EyePlan> eyes;
  /// Every non-eye subdivision mesh's level by its size on screen (meshRefinePlan.h); applied with the eyes.
  std::vector<MeshPlan> meshes;
  /// The global switches ApplyRenderPlan sets as RenderSettings::eyeSwitches: on if any eye's plan needs the
  /// feature (limbalArc: on unless a flag says off, so each unplanned eye follows its own eye:limbalArc). They are the
  /// defaults for eyes the plan does not cover (none, when the plan was made for the scene it is applied to); every
  /// planned eye renders with its own switches.
  EyeSwitches switches{true, false, false, true};
  std::map<std::string, std::string> why;  ///< reasons for the global values
  /// One human-readable line per eye (and one for the globals when there is no eye), and one counting the
  /// subdivision meshes per planned level.
  std::vector<std::string> SummaryLines() const;
};

/// Projected facts of an eye seen by `camera` in a width x height image (no lights).
EyePlan MeasureEye(const PrimId& prim, const std::string& geometry, const EyeGeometry& eye, const CameraView& camera,
                   int width, int height);

/// A light as the eye sees it: solid angle, direction off the gaze, whether it can reach the iris.
LightFacts MeasureLight(const PrimId& lightId, const RenderLight& light, const EyeGeometry& eye);

/// MeasureEye where the eye is largest on screen over the camera's open shutter (measured at the shutter's ends and
/// at the eye's and camera's motion samples inside it); MeasureEye itself for a closed shutter or nothing moving.
EyePlan MeasureEyeOverShutter(const PrimId& prim, const std::string& geometry, const EyeGeometry& eye,
                              const CameraView& camera, int width, int height);
/// Fills the eye's decisions and reasons from its facts (MeasureEye, MeasureLight into eye->lights),
/// the rules and the overrides.
void DecideEye(EyePlan* eye, const PlanRules& rules, const PlanOverrides& overrides);

/// The plan's global switches (RenderPlan::switches) and their reasons, from its eyes' decisions and the flags.
void DecideGlobals(RenderPlan* plan, const PlanOverrides& overrides);

/// The plan for every eye rprim of a synced index, seen by the camera sprim `cameraId` in a width x
/// height image. Throws std::runtime_error if the camera is missing or the size is not positive.
RenderPlan MakeRenderPlan(const RenderIndex& index, const PrimId& cameraId, int width, int height,
                          const PlanOverrides& overrides, const PlanRules& rules = {});

/// Applies the plan: every eye rprim of `index` the plan covers gets its EyeRenderOptions (EyePlan::RenderOptions,
/// lights in the index's order: the renderer's); eye rprims it does not cover are reset to unplanned (the
/// global switches). Then sets the global switches as `settings`' eyeSwitches, the defaults. maxDepth is left alone: it
/// bounds world bounces for the whole frame, not the eye's chamber walk. Call it after the plan's sync and before
/// Execute: Execute's sync keeps the options (they live in the rprims' contexts).
void ApplyRenderPlan(const RenderPlan& plan, RenderIndex* index, RenderSettings* settings);

/// Only the global switches (no per-eye options): for a settings object with no render index to reach.
void ApplyRenderPlan(const RenderPlan& plan, RenderSettings* settings);

/// Resets every eye rprim of `index` to unplanned: renders use the global switches again (--no-auto-plan).
void ClearRenderPlan(RenderIndex* index);

/// The light prim ids of `index` in the order RenderPass::Execute lists lights for the renderer.
std::vector<PrimId> RenderLightOrder(const RenderIndex& index);

}  // namespace hdeye
