#pragma once
// The render plan (DESIGN.md, "Deciding what to model"): after sync and before rendering, decide for
// each eye everything the artist did not author (MNEE per light, the all-solutions search, chamber
// depth, sclera scattering and the limbal arc, subdivision level, precision) from what the scene
// shows: the eye's size on screen, whether it is in view, and each light's solid angle and direction
// as seen from the eye. Every decision carries a one-line reason; anything the user set explicitly
// (an authored schema value, a render setting or a command-line flag, gathered in PlanOverrides) wins
// and the reason says so ("authored" / "flag").
//
// Every threshold is in PlanRules, each with the sweep it comes from (bench/bench_plan.py,
// docs/render_plan.md). Rules whose sweep has not been run are marked provisional, in the code and in
// the reasons the plan prints.
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

/// The planner's thresholds. Units in each comment; where each number comes from in docs/render_plan.md.
struct PlanRules {
  /// Eyes whose 15.08 mm iris circle projects smaller than this (pixels) get no MNEE. 0: MNEE at any size.
  /// Sweep 1 measured MNEE 12-40x more efficient than path tracing on the eye's pixels from 46 px down to
  /// 1.6 px (a 3e-4 sr key), at the same time per frame: a tiny eye does not justify dropping it.
  double mneeMinPixels = 0;
  /// A light whose solid angle seen from the eye exceeds this (steradians) is left to BSDF sampling with MIS.
  /// Sweep 2 (efficiency MNEE / path tracing on the eye's pixels): at 30 deg off the gaze x29 at 0.02 sr, x3.3
  /// at 0.2, x1.7 at 0.84, then x0.80 at 2.1, x0.74 at 4.3 and x0.28 for a dome (4 pi sr); at 75 deg x4.7 at
  /// 0.02 sr, x1.03 at 0.2, x0.78 at 0.84, x0.51 at 2.1. So: 1 sr near the gaze, 0.2 sr at grazing angles.
  /// The edge between them (sweep 2 at 45-75 deg, 64 spp): at 45 deg x1.59 at 0.84 sr, x0.94 at 2.1; at 60 deg
  /// still x1.20 at 0.84 sr and x1.01 at 1.38 (the 1 sr bound holds there); at 65 deg x2.13 at 0.2 sr and even
  /// (x0.97-1.02) from 0.46 to 1.38 sr; at 70 deg x1.31 at 0.2, x1.08 at 0.46, x0.83 at 0.84; at 75 deg x0.91-0.94
  /// from 0.2 to 0.84. So the grazing bound starts at 65 deg (it was a provisional 60, where MNEE still paid at 0.84 sr).
  double mneeMaxSolidAngleSr = 1.0;
  double mneeMaxSolidAngleSrGrazing = 0.2;  ///< sr, for lights at least grazingAngleDeg off the gaze
  double grazingAngleDeg = 65;              ///< degrees (sweep 2 at 60, 65, 70, 75 deg)
  /// All-solutions MNEE (every refraction path) only for lights at least this far off the gaze (degrees) --
  /// where second paths exist (the ellipsoid-cone junction fold under grazing light) -- and on eyes at least
  /// `allSolutionsMinPixels` wide. Sweep 3: at 0-85 deg one path per sample was 1.3-2.0x more efficient, and
  /// the all-solutions image differed in mean by +0.03% (60 deg) and +0.08% (85 deg) only (docs/mnee_benchmark.md:
  /// second paths carry 0.05-0.19% of the iris flux, most at 85 deg). Sweep allsol-size (close-ups framed on the
  /// fold, 32 spp): at 89 deg one path's equal-time efficiency is 1.22x all-solutions' at 100 px, 0.94x at 200,
  /// 0.55x at 400, 0.31x at 800; it misses 0.7-4.8% of the close-up's light there, up to 37-47% in a pixel, 2-16%
  /// of the pixels by more than 5%: a bias no budget removes. At 80 deg one path stays 1.15-2.1x more efficient
  /// at 32 spp but misses up to 34% in a pixel (4.8% of the pixels by more than 5% at 400 px). So 200 px.
  double allSolutionsMinAngleDeg = 80;
  double allSolutionsMinPixels = 200;
  /// Chamber events followed per path (EyeRenderOptions::maxChamberEvents) for every eye. Sweep chamber (analytic
  /// eye, 46 px, 2 mm key, same seed against the 64-event walk): bound 1-2 lose 1.55% (side, 75 deg) and 2.3%
  /// (front, 15 deg) of the eye's light, 4 loses 0.22% / 0.34%, 8 loses 0.02% / 0.03%, 16 nothing; time per sample is the
  /// same from 4 to 64 events within the machine's noise (the walk ends by itself: exit, pupil, or the iris's
  /// albedo), so no bound pays: the full walk. (Events 1-2 are also every path that carries a dome to the iris.)
  int chamberEvents = 64;
  /// Sclera random-walk SSS on eye meshes whose iris circle is at least this wide (pixels); below it, a
  /// Lambertian sclera. Sweep sclera (eye.usda, 64 px frames, equal time, key at 70 and 15 deg): Lambert's
  /// eye MSE against the full model's reference was 1.09x (side) and 0.15x (front) the walk's at 2 px -- within
  /// noise -- and 2.7x / 1.4x at 4 px, 2.1-3.3x from 8 to 32 px. The band between (sweep sclera at 2, 2.5, 3 and
  /// 4 px, 16 and 64 spp): at 3 px Lambert's equal-time MSE is 2.6x / 2.0x (16 spp) and 10.5x / 3.1x (64 spp) the
  /// walk's, at 2.5 px 1.8x / 1.6x and 6.7x / 5.1x (side / front); at 2 px it is mixed (side 1.1-12x, front
  /// 0.15-0.70x: Lambert closer). So 2.5 px, the smallest size where the walk won every case (was a provisional 3).
  double sssMinPixels = 2.5;
  /// The limbal arc (teleportation cylinder) needs the limbus band ((outer - inner limbus diameter) / 2,
  /// projected) at least this wide, pixels. 0: no band condition. Sweep sclera: the arc mattered on eyes whose
  /// band is 0.13 px (an 8 px eye): it lights the whole shadowed sclera, not only the band.
  double sssMinLimbusPixels = 0;
  /// The limbal arc only with some light at least this far off the gaze (degrees); 0: the arc goes with the
  /// walk. Sweep sclera: without the cylinder the eye's equal-time MSE was 1.3-4.5x the full model's side-lit
  /// (70 deg) and 1.2-1.8x front-lit (15 deg) from 8 px up, at the same samples per second: no light direction
  /// where dropping it pays was found. Sweep dome-arc (a dome alone, no key): without the cylinder the eye loses
  /// 5.3-6.3% of its light and its equal-time MSE is 1.11x (8 px), 1.19x (32 px), 1.37x (a 128 px limbus
  /// close-up) the full model's, at the same samples per second: no light condition either.
  double limbalArcMinLightAngleDeg = 0;
  /// Subdivision of eye meshes: one level per doubling of the eye's size above this many pixels, capped by
  /// the --complexity ceiling and the mesh's populate level. Sweep refine (eye.usda, 64 px frames): level 0's
  /// eye error equalled level 3's within noise at 16 and 64 px; its outline was off by 3 px (summed coverage)
  /// at 16 px, 6 px at 64 px, 34 px at 200 px, where level 1 was off by 2 px and level 2 by 0. Refinement to
  /// level 3 costs 0.26-0.62 s per sync against 0.03 s at level 0 (197 k vs 3 k triangles).
  double refinePixelsLevel1 = 64;
  /// The planner never asks for more than this level. Sweep refine at 256, 400, 800 and 1600 px (64 spp, reference
  /// level 3 at 1024 spp): level 2's outline equals level 3's (0 px at 256 and 400 px, where the frame holds the
  /// eyeball's outline; level 1 is 2 px / 0 px off) and its image too (eye bias -1.42 vs -1.37%, +0.18 vs +0.09%,
  /// rRMSE equal to 0.001), while level 3 costs 4x the triangles and 0.2-0.3 s per sync. So level 2 is the cap
  /// (was a provisional step to level 3 at 256 px).
  int refineMaxLevel = 2;
  bool sssProvisional = false, limbalArcProvisional = false, refineProvisional = false;
  /// Precision. Eyes are traced in double: there is no float eye path, and the plan adds none. It reports
  /// whether float WOULD be enough: the analytic intersection's worst float hit-position error, measured
  /// against double over 200 000 rays per cornea model (docs/intersection_benchmark.md: 0.207 um
  /// ellipsoid-cone, 0.3 um paraboloid; p99 0.0054 um), against the eye's pixel footprint. The tolerance (a
  /// hundredth of a pixel: a silhouette or highlight moved by it changes a pixel's coverage by at most 1%,
  /// below the sweeps' noise) is a stated criterion, not a sweep; the benchmark covers camera-ray hits on the
  /// anterior surface, not MNEE's Newton solve or the chamber walk.
  double floatHitErrorMm = 3.0e-4;   ///< mm, the worst of the two models' worst float position errors
  double floatMaxErrorPixels = 0.01;  ///< pixels
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
  int refineLevelCeiling = 3;            ///< --complexity: the planner's subdivision level never exceeds it
  /// Schema values authored on an eye prim (HasAuthoredValue, not the fallback).
  struct Authored {
    std::optional<bool> limbalArc;  ///< eye:limbalArc
  };
  std::map<PrimId, Authored> authored;
};

/// One light as one eye sees it, and what the eye does with it.
struct LightFacts {
  PrimId light;
  std::string kind;               ///< sphere, distant, rect, disk, dome
  double solidAngleSr = 0;        ///< subtended at the iris centre, steradians (dome: 4 pi)
  double angleOffGazeDeg = -1;    ///< gaze to the light's centre, degrees; -1 for a dome (no direction)
  double angularRadiusDeg = 180;  ///< half the angle the light subtends, degrees
  bool reachesIris = true;        ///< some part above the rim plane (else the sclera hides it: MNEE finds nothing)
  /// "mnee" (manifold NEE through the cornea) or "bsdf" (BSDF sampling with MIS: paths that leave the
  /// cornea and hit the light) or "none" (the light cannot reach the iris).
  std::string strategy = "bsdf";
  std::string why;
};

/// An eye's facts and decisions. Each decision names its reason in `why` (same key).
struct EyePlan {
  PrimId prim;
  std::string geometry;        ///< analyticEye or eyeMesh
  /// Projected diameter of the 15.08 mm iris/limbus circle, pixels (the longest chord of its image;
  /// 0 when behind the camera).
  double pixels = 0;
  bool inView = false;         ///< some of the circle projects inside the image, in front of the camera
  bool behindCamera = false;   ///< all of it behind the camera plane
  double viewAngleDeg = 0;     ///< gaze to the direction from the eye to the camera, degrees (0: looking at it)
  double limbusPixels = 0;     ///< the limbus band's projected width, pixels
  std::vector<LightFacts> lights;

  bool mnee = false;           ///< MNEE for at least one light
  bool mneeAllSolutions = false;
  /// Chamber events followed per path (the walk's bound inside the anterior chamber): applied as
  /// EyeRenderOptions::maxChamberEvents.
  int chamberEvents = 64;
  std::string sss = "diffuse";  ///< "randomWalk" (path-traced sclera SSS) or "diffuse" (Lambert)
  bool limbalArc = false;       ///< the teleportation cylinder in the sclera walk
  int refineLevel = -1;         ///< eye meshes: planned Catmull-Clark level; -1 analytic (no mesh)
  std::string precision = "double";  ///< the eye's analytic intersection and MNEE arithmetic (always double)
  /// Millimetres of the eye per pixel: the 15.08 mm iris circle over `pixels` (infinite when not projected).
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
  /// The global switches ApplyRenderPlan also sets: on if any eye's plan needs the feature. They are the
  /// defaults for eyes the plan does not cover (none, when the plan was made for the scene it is applied
  /// to); every planned eye renders with its own switches.
  bool mnee = true, mneeAllSolutions = false;
  bool scleraScattering = false;  ///< RenderSettings::scleraScattering (eye meshes' sclera walk)
  std::map<std::string, std::string> why;  ///< reasons for the global values
  /// "perEye": ApplyRenderPlan with the render index gives each eye its own decisions, per light for MNEE.
  std::string application = "perEye";

  /// The plan as one JSON object: {"camera", "width", "height", "application", "applied": {...},
  /// "why": {...}, "eyes": [{"prim", "pixels", "mnee", "sss", "limbalArc", "why", ...}]}.
  std::string ToJson() const;
  /// One human-readable line per eye (and one for the globals when there is no eye).
  std::vector<std::string> SummaryLines() const;
};

/// Projected facts of an eye seen by `camera` in a width x height image (no lights).
EyePlan MeasureEye(const PrimId& prim, const std::string& geometry, const EyeGeometry& eye,
                   const CameraView& camera, int width, int height);

/// A light as the eye sees it: solid angle, direction off the gaze, whether it can reach the iris.
LightFacts MeasureLight(const PrimId& lightId, const RenderLight& light, const EyeGeometry& eye);

/// Fills the eye's decisions and reasons from its facts (MeasureEye, MeasureLight into eye->lights),
/// the rules and the overrides.
void DecideEye(EyePlan* eye, const PlanRules& rules, const PlanOverrides& overrides);

/// The plan for every eye rprim of a synced index, seen by the camera sprim `cameraId` in a width x
/// height image. Throws std::runtime_error if the camera is missing or the size is not positive.
RenderPlan MakeRenderPlan(const RenderIndex& index, const PrimId& cameraId, int width, int height,
                          const PlanOverrides& overrides, const PlanRules& rules = {});

/// Applies the plan: every eye rprim of `index` the plan covers gets its EyeRenderOptions (EyePlan::RenderOptions,
/// lights in the index's order: the renderer's); eye rprims it does not cover are reset to unplanned (the
/// global switches). Then sets the global switches of `settings` (mnee, mneeAllSolutions, scleraScattering)
/// as the defaults. maxDepth is left alone: it bounds world bounces for the whole frame, not the eye's chamber
/// walk. Call it after the plan's sync and before Execute: Execute's sync keeps the options (they live in
/// the rprims' contexts).
void ApplyRenderPlan(const RenderPlan& plan, RenderIndex* index, RenderSettings* settings);

/// Only the global switches (no per-eye options): for a settings object with no render index to reach.
void ApplyRenderPlan(const RenderPlan& plan, RenderSettings* settings);

/// Resets every eye rprim of `index` to unplanned: renders use the global switches again (--no-auto-plan).
void ClearRenderPlan(RenderIndex* index);

/// The light prim ids of `index` in the order RenderPass::Execute lists lights for the renderer.
std::vector<PrimId> RenderLightOrder(const RenderIndex& index);

/// `s` as a JSON string literal (quotes, backslashes and control characters escaped).
std::string JsonQuote(const std::string& s);

}  // namespace hdeye
