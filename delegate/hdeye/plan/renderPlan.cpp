#include "hdeye/plan/renderPlan.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/prims/camera.h"
#include "hdeye/prims/light.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/render/renderContext.h"

#include <eyelib/eye_constants.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace hdeye {

namespace {

/// `v` to `digits` significant digits for the plan's lines and JSON; null when it is not finite.
std::string Num(double v, int digits = 4) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace

const char* ToString(LightType type) {
  switch (type) {
    case LightType::Sphere: return "sphere";
    case LightType::Distant: return "distant";
    case LightType::Rect: return "rect";
    case LightType::Disk: return "disk";
    case LightType::Dome: return "dome";
    case LightType::Cylinder: return "cylinder";
  }
  return "?";
}

const char* ToString(LightStrategy strategy) {
  switch (strategy) {
    case LightStrategy::Mnee: return "mnee";
    case LightStrategy::Bsdf: return "bsdf";
    case LightStrategy::None: return "none";
  }
  return "?";
}

const char* ToString(ScleraModel model) {
  switch (model) {
    case ScleraModel::RandomWalk: return "randomWalk";
    case ScleraModel::Diffuse: return "diffuse";
    case ScleraModel::None: return "none";
  }
  return "?";
}

namespace {

/// A decision and its one-line reason.
template <class T> struct Decision {
  T value;
  std::string why;
};

/// Why the camera cannot see the eye's iris, or empty when it can.
std::string HiddenReason(const EyePlan& e) {
  if (e.behindCamera) return "behind the camera";
  if (!e.inView) return "out of view";
  if (!(e.viewAngleDeg < 90)) return "iris faces away from the camera (" + Num(e.viewAngleDeg, 3) + " deg)";
  return "";
}

/// How the iris gets light l's direct light: MNEE for small lights (the bound by angle off the gaze: sweep 2).
Decision<LightStrategy> DecideLightStrategy(const LightFacts& l, const EyePlan& e, const std::string& hidden,
                                            const PlanRules& rules, const PlanOverrides& ov) {
  if (!l.reachesIris)
    return {LightStrategy::None,
            "below the rim plane (" + Num(l.angleOffGazeDeg, 3) + " deg off the gaze): the sclera hides it"};
  if (ov.mnee)
    return {*ov.mnee ? LightStrategy::Mnee : LightStrategy::Bsdf, *ov.mnee ? "flag: MNEE on" : "flag: --no-mnee"};
  if (!hidden.empty()) return {LightStrategy::Bsdf, hidden};
  if (e.pixels < rules.mneeMinPixels)
    return {LightStrategy::Bsdf,
            "eye " + Num(e.pixels, 3) + " px < " + Num(rules.mneeMinPixels, 3) + " px: path tracing is cheaper"};
  if (l.kind == LightType::Dome) {
    const std::string contrast = "4pi sr, radiance contrast " + Num(l.radianceContrast, 3);
    if (l.radianceContrast >= rules.mneeMinDomeContrast)
      return {LightStrategy::Mnee,
              contrast + " >= " + Num(rules.mneeMinDomeContrast, 3) + ": MNEE in every sample (sweep dome-contrast)"};
    return {LightStrategy::Bsdf,
            contrast + " < " + Num(rules.mneeMinDomeContrast, 3) + ": BSDF sampling with MIS (sweep dome-contrast)"};
  }
  const bool grazing = l.angleOffGazeDeg >= rules.grazingAngleDeg;
  const double limit = grazing ? rules.mneeMaxSolidAngleSrGrazing : rules.mneeMaxSolidAngleSr;
  const std::string size = Num(l.solidAngleSr, 3) + " sr";
  const std::string at = " at " + Num(l.angleOffGazeDeg, 3) + " deg" + (grazing ? " (>= " : " (< ") +
                         Num(rules.grazingAngleDeg, 3) + " deg)";
  if (l.solidAngleSr > limit)
    return {LightStrategy::Bsdf, size + " > " + Num(limit, 3) + " sr" + at + ": BSDF sampling with MIS (sweep 2)"};
  return {LightStrategy::Mnee, size + " <= " + Num(limit, 3) + " sr" + at + ": MNEE (sweep 2)"};
}

/// Every light's strategy (into e->lights), and whether the eye runs MNEE at all, with every light's reason.
Decision<bool> DecideMnee(EyePlan* e, const std::string& hidden, const PlanRules& rules, const PlanOverrides& ov) {
  std::string perLight;
  int mneeLights = 0, bsdfLights = 0;
  for (LightFacts& l : e->lights) {
    Decision<LightStrategy> d = DecideLightStrategy(l, *e, hidden, rules, ov);
    l.strategy = d.value, l.why = std::move(d.why);
    mneeLights += l.strategy == LightStrategy::Mnee;
    bsdfLights += l.strategy == LightStrategy::Bsdf;
    perLight += (perLight.empty() ? "" : "; ") + l.light + ": " + ToString(l.strategy) + " (" + l.why + ")";
  }
  std::string why = !e->lights.empty() ? perLight : ov.mnee ? "flag (no lights)" : "no lights";
  if (mneeLights > 0 && bsdfLights > 0)
    why +=
        "; applied per light: MNEE counts its lights, paths leaving the iris count the others "
        "(each light by one of the two)";
  return {mneeLights > 0, why};
}

/// All-solutions MNEE: only where second refraction paths carry measurable light (sweeps 3 and allsol-size).
Decision<bool> DecideAllSolutions(const EyePlan& e, const PlanRules& rules, const PlanOverrides& ov) {
  if (ov.mneeAllSolutions) return {*ov.mneeAllSolutions, std::string("flag: ") + (*ov.mneeAllSolutions ? "on" : "off")};
  if (!e.switches.mnee) return {false, "no MNEE"};
  const LightFacts* grazing = nullptr;
  for (const LightFacts& l : e.lights)
    if (l.strategy == LightStrategy::Mnee && l.angleOffGazeDeg >= rules.allSolutionsMinAngleDeg) grazing = &l;
  if (grazing && e.resolvedPixels >= rules.allSolutionsMinPixels)
    return {true, grazing->light + " at " + Num(grazing->angleOffGazeDeg, 3) +
                      " deg >= " + Num(rules.allSolutionsMinAngleDeg, 3) + " deg on a " + Num(e.resolvedPixels, 4) +
                      " px eye: caustic fold (sweep allsol-size: one path misses up to 47% in a pixel from 200 px)"};
  if (grazing)
    return {false, "grazing light but eye " + Num(e.resolvedPixels, 4) + " px < " +
                       Num(rules.allSolutionsMinPixels, 4) +
                       " px: one path per sample is cheaper for the same error (sweep allsol-size)"};
  return {false, "no MNEE light at >= " + Num(rules.allSolutionsMinAngleDeg, 3) +
                     " deg: one path per sample (second paths carry < 0.2% of the iris light)"};
}

/// The chamber walk's bound: the full walk (sweep chamber). Throws std::invalid_argument for a flag below 1.
Decision<int> DecideChamberEvents(const PlanRules& rules, const PlanOverrides& ov) {
  if (ov.chamberEvents) {
    if (*ov.chamberEvents < 1)
      throw std::invalid_argument("render plan: chamber events " + std::to_string(*ov.chamberEvents) + " < 1");
    return {*ov.chamberEvents, "flag: " + std::to_string(*ov.chamberEvents) + " events"};
  }
  return {rules.chamberEvents, "full walk (" + std::to_string(rules.chamberEvents) +
                                   " events): cutting it saves no measurable time and loses light below 8 events "
                                   "(sweep chamber: 2 events lose 1.55% side-lit, 2.3% front-lit; 8 lose 0.02-0.03%)"};
}

/// The chamber-light cache's rings by the eye's size on screen: its build (mostly MNEE at 3 rings^2 nodes) is paid per
/// eye and frame, which a crowd of small eyes must not pay at full resolution.
Decision<int> DecideChamberCacheRings(const EyePlan& e, const PlanRules& rules) {
  const int wanted = int(std::ceil(std::max(0.0, e.resolvedPixels) / rules.chamberCachePixelsPerRing / 4)) * 4;
  const int rings = std::clamp(wanted, rules.chamberCacheMinRings, rules.chamberCacheMaxRings);
  return {rings, std::to_string(rings) + " x " + std::to_string(3 * rings) + " nodes: a ring per " +
                     Num(rules.chamberCachePixelsPerRing, 3) + " px of the " + Num(e.resolvedPixels, 4) +
                     " px iris circle, " + std::to_string(rules.chamberCacheMinRings) + " to " +
                     std::to_string(rules.chamberCacheMaxRings) +
                     " (sweep chamber-cache: worst bias at a sharp shadow edge 7 % of the chamber light at 12 rings, "
                     "2.5 % at 24, about 1 % at 32 and 48; scene B's floor 0.19 % at 32, 0.12 % at 48)"};
}

/// The sclera: a random walk on eye meshes large enough on screen (sweep sclera); analytic eyes have no volume.
Decision<ScleraModel> DecideSclera(const EyePlan& e, const std::string& hidden, const PlanRules& rules,
                                   const PlanOverrides& ov) {
  if (e.geometry != primTypes::kEyeMesh)
    return {ScleraModel::None, "analytic eye: no sclera volume (the renderer walks eye meshes only)"};
  if (ov.scleraScattering) {
    const ScleraModel model = *ov.scleraScattering ? ScleraModel::RandomWalk : ScleraModel::Diffuse;
    return {model, std::string("flag: ") + ToString(model)};
  }
  if (!hidden.empty()) return {ScleraModel::Diffuse, hidden};
  if (e.resolvedPixels >= rules.sssMinPixels)
    return {ScleraModel::RandomWalk,
            "eye " + Num(e.resolvedPixels, 3) + " px >= " + Num(rules.sssMinPixels, 3) +
                " px: a Lambertian sclera is visibly off (sweep sclera: its equal-time MSE 1.6-6.7x the walk's "
                "at 2.5 px, 2.0-10.5x at 3 px, 1.4-3.3x from 4 to 32 px)"};
  return {ScleraModel::Diffuse,
          "eye " + Num(e.resolvedPixels, 3) + " px < " + Num(rules.sssMinPixels, 3) +
              " px: a Lambertian sclera is within the walk's equal-time noise (sweep sclera at 2 px: its MSE "
              "0.15-0.70x the walk's front-lit, 1.1-12x side-lit, on 4 eye pixels)"};
}

/// The limbal arc, applied per eye in place of the eye's EyeParams::limbalArc: with the sclera walk (sweeps
/// sclera and dome-arc), unless the artist authored eye:limbalArc or a flag says otherwise.
Decision<bool> DecideLimbalArc(const EyePlan& e, const PlanRules& rules, const PlanOverrides& ov) {
  const auto authored = ov.authored.find(e.prim);
  if (authored != ov.authored.end() && authored->second.limbalArc) {
    const bool on = *authored->second.limbalArc;
    return {on, std::string("authored: eye:limbalArc = ") + (on ? "true" : "false")};
  }
  if (ov.limbalArc) return {*ov.limbalArc, std::string("flag: ") + (*ov.limbalArc ? "on" : "off")};
  if (e.sss != ScleraModel::RandomWalk) return {false, "no sclera walk"};
  if (e.limbusPixels < rules.sssMinLimbusPixels)
    return {false, "limbus band " + Num(e.limbusPixels, 3) + " px < " + Num(rules.sssMinLimbusPixels, 3) + " px"};
  if (rules.limbalArcMinLightAngleDeg <= 0)
    return {true,
            "with the sclera walk: without it the eye's equal-time MSE is 1.3-4.5x (side) and "
            "1.2-1.8x (front) from 8 px, at no measurable cost (sweep sclera); under a dome alone 1.1-1.4x, "
            "losing 5-6% of the eye's light (sweep dome-arc)"};
  const LightFacts* side = nullptr;
  for (const LightFacts& l : e.lights)
    if (l.reachesIris && l.kind != LightType::Dome && l.angleOffGazeDeg >= rules.limbalArcMinLightAngleDeg) side = &l;
  if (!side) return {false, "no side light: no shadowed limbus side"};
  return {true, side->light + " at " + Num(side->angleOffGazeDeg, 3) + " deg: a shadowed limbus side"};
}

/// Eye meshes' Catmull-Clark level, applied: one level per doubling of the eye's size, capped (sweep refine).
/// The mesh renders min(this, its populate level) and re-refines when it changes (EyeMesh::RefineLevelFor).
Decision<int> DecideRefineLevel(const EyePlan& e, const PlanRules& rules, const PlanOverrides& ov) {
  if (e.geometry != primTypes::kEyeMesh) return {-1, "analytic eye: no mesh"};
  int level = 0;
  if (e.resolvedPixels >= rules.refinePixelsLevel1)
    level = 1 + int(std::floor(std::log2(e.resolvedPixels / rules.refinePixelsLevel1)));
  const bool capped = level > rules.refineMaxLevel;
  level = std::min(level, rules.refineMaxLevel);
  const bool held = level > ov.refineLevelCeiling;
  return {std::min(level, ov.refineLevelCeiling),
          Num(e.resolvedPixels, 4) + " px -> level " + std::to_string(level) +
              (held ? ", held at the --complexity ceiling " : " (ceiling ") + std::to_string(ov.refineLevelCeiling) +
              (held ? "" : ")") + ": one level per doubling from " + Num(rules.refinePixelsLevel1, 3) +
              " px, at most level " + std::to_string(rules.refineMaxLevel) +
              " (sweep refine: level 0 matches level 3 in image error below it; level 2 needed at 200 px" +
              (capped ? "; level 3 never changed the outline or image vs level 2 from 200 to 1600 px)" : ")")};
}

/// Whether float would be enough for the eye's intersections (reported only: the renderer traces eyes in double).
Decision<bool> DecideFloatWouldSuffice(const EyePlan& e, const PlanRules& rules) {
  const double floatErrorPixels = rules.floatHitErrorMm / e.pixelFootprintMm;
  const bool enough = floatErrorPixels <= rules.floatMaxErrorPixels;
  return {enough, "double (no float eye path); float's worst hit error " + Num(rules.floatHitErrorMm * 1000, 2) +
                      " um (docs/intersection_benchmark.md) is " + Num(floatErrorPixels, 2) + " px at " +
                      Num(e.pixelFootprintMm, 3) + " mm/px: float " +
                      (enough ? "would be enough (<= " : "would not be enough (> ") +
                      Num(rules.floatMaxErrorPixels, 2) + " px)"};
}

/// Stores a decision's value in *field and its reason under `name`.
template <class T, class U> void Record(EyePlan* e, T* field, const char* name, Decision<U> decision) {
  *field = decision.value;
  e->why[name] = std::move(decision.why);
}

}  // namespace

void DecideEye(EyePlan* e, const PlanRules& rules, const PlanOverrides& ov) {
  const std::string hidden = HiddenReason(*e);
  Record(e, &e->switches.mnee, "mnee", DecideMnee(e, hidden, rules, ov));
  Record(e, &e->switches.mneeAllSolutions, "mneeAllSolutions", DecideAllSolutions(*e, rules, ov));
  Record(e, &e->chamberEvents, "chamberEvents", DecideChamberEvents(rules, ov));
  Record(e, &e->chamberCacheRings, "chamberCacheRings", DecideChamberCacheRings(*e, rules));
  Record(e, &e->sss, "sss", DecideSclera(*e, hidden, rules, ov));
  e->switches.scleraScattering = e->sss == ScleraModel::RandomWalk;
  Record(e, &e->switches.limbalArc, "limbalArc", DecideLimbalArc(*e, rules, ov));
  Record(e, &e->refineLevel, "refineLevel", DecideRefineLevel(*e, rules, ov));
  e->pixelFootprintMm = e->resolvedPixels > 0 ? eyelib::paper::kRimRadius * 2 / e->resolvedPixels
                                              : std::numeric_limits<double>::infinity();
  Record(e, &e->floatWouldSuffice, "precision", DecideFloatWouldSuffice(*e, rules));
}

RenderPlan MakeRenderPlan(const RenderIndex& index, const PrimId& cameraId, int width, int height,
                          const PlanOverrides& overrides, const PlanRules& rules) {
  if (width < 1 || height < 1)
    throw std::runtime_error("render plan: image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " is not positive");
  const auto* camera = dynamic_cast<const Camera*>(index.GetSprim(cameraId));
  if (!camera) throw std::runtime_error("render plan: camera " + cameraId + " not found");
  RenderPlan plan;
  plan.width = width, plan.height = height, plan.camera = cameraId;

  const std::vector<GatheredLight> lights = GatherLights(index);

  for (const auto& [id, entry] : index.Rprims()) {
    if (entry.type != primTypes::kAnalyticEye && entry.type != primTypes::kEyeMesh) continue;
    GeometryContext* context = entry.prim->Context();
    const EyeGeometry* eye = context ? (context->eye ? context->eye : context->meshEye) : nullptr;
    if (!eye) continue;  // not synced yet
    EyePlan e = MeasureEyeOverShutter(id, entry.type, *eye, camera->View(), width, height);
    if (entry.sceneDelegate && !entry.sceneDelegate->GetVisible(id)) e.inView = false;
    for (const GatheredLight& light : lights) e.lights.push_back(MeasureLight(light.id, light.light, *eye));
    DecideEye(&e, rules, overrides);
    plan.eyes.push_back(std::move(e));
  }

  plan.meshes = PlanMeshRefinement(index, camera->View(), width, height, overrides, rules);
  DecideGlobals(&plan, overrides);
  return plan;
}

namespace {

/// Any planned eye's value of `field`.
template <class F> bool AnyEye(const RenderPlan& plan, F field) {
  return std::any_of(plan.eyes.begin(), plan.eyes.end(), field);
}

}  // namespace

void DecideGlobals(RenderPlan* plan, const PlanOverrides& overrides) {
  const std::string scope = plan->eyes.size() <= 1
                                ? ""
                                : " (default for eyes without a plan: on if any eye needs it; each planned eye "
                                  "renders with its own)";
  EyeSwitches& s = plan->switches;
  if (overrides.mnee) {
    s.mnee = *overrides.mnee;
    plan->why["mnee"] = "flag";
  } else if (plan->eyes.empty()) {
    s.mnee = false;
    plan->why["mnee"] = "no eyes";
  } else {
    s.mnee = AnyEye(*plan, [](const EyePlan& e) { return e.switches.mnee; });
    plan->why["mnee"] = "from the eyes' plans" + scope;
  }
  if (overrides.mneeAllSolutions) {
    s.mneeAllSolutions = *overrides.mneeAllSolutions;
    plan->why["mneeAllSolutions"] = "flag";
  } else {
    s.mneeAllSolutions = s.mnee && AnyEye(*plan, [](const EyePlan& e) { return e.switches.mneeAllSolutions; });
    plan->why["mneeAllSolutions"] = plan->eyes.empty() ? "no eyes" : "from the eyes' plans" + scope;
  }
  if (overrides.scleraScattering) {
    s.scleraScattering = *overrides.scleraScattering;
    plan->why["scleraScattering"] = "flag";
  } else {
    s.scleraScattering = AnyEye(*plan, [](const EyePlan& e) { return e.switches.scleraScattering; });
    plan->why["scleraScattering"] = plan->eyes.empty() ? "no eyes" : "from the eye meshes' plans" + scope;
  }
  // The limbal arc has no global decision: an eye without a plan follows its own eye:limbalArc, unless a flag says.
  s.limbalArc = overrides.limbalArc.value_or(true);
}

EyeRenderOptions EyePlan::RenderOptions(const std::vector<PrimId>& lightOrder) const {
  EyeRenderOptions o;
  o.planned = true;
  o.switches = switches;
  o.mneeLights.reserve(lightOrder.size());
  for (const PrimId& id : lightOrder) {
    const auto l = std::find_if(lights.begin(), lights.end(), [&](const LightFacts& f) { return f.light == id; });
    // Unmeasured (added after planning): MNEE, as without a plan. "none" (below the rim plane): not MNEE's,
    // so a path leaving the iris still counts it if it finds it -- the partition stays complete.
    o.mneeLights.push_back(l == lights.end() ? true : l->strategy == LightStrategy::Mnee);
  }
  o.maxChamberEvents = chamberEvents;
  o.chamberCacheRings = chamberCacheRings;
  o.refineLevel = refineLevel;  // -1 for analytic eyes: nothing to refine
  return o;
}

std::vector<PrimId> RenderLightOrder(const RenderIndex& index) {
  std::vector<PrimId> order;  // the renderer's light list's (GatherLights, as RenderPass::Execute hands it)
  for (const GatheredLight& light : GatherLights(index)) order.push_back(light.id);
  return order;
}

namespace {

/// Gives an eye rprim its options. The switches are read per ray; a refinement level is geometry: when the
/// mesh would now render another level than it does, its topology is marked dirty (only this mesh's), and the
/// next sync (Execute's) re-refines it. A mesh not synced yet refines with the options at its first sync.
void SetEyeOptions(RenderIndex* index, const PrimId& id, Rprim* prim, const EyeRenderOptions& options) {
  GeometryContext* context = prim->Context();
  if (!context) return;
  context->eyeOptions = options;
  auto* mesh = dynamic_cast<Mesh*>(prim);
  if (mesh && mesh->SceneRefineLevel() >= 0 && mesh->RefineLevelFor(mesh->SceneRefineLevel()) != mesh->RefineLevel())
    index->GetChangeTracker().MarkDirty(id, dirty::DirtyTopology);
}

}  // namespace

void ApplyRenderPlan(const RenderPlan& plan, RenderIndex* index, RenderSettings* settings) {
  const std::vector<PrimId> lightOrder = RenderLightOrder(*index);
  for (const auto& [id, entry] : index->Rprims()) {
    if (entry.type != primTypes::kAnalyticEye && entry.type != primTypes::kEyeMesh) continue;
    const auto e = std::find_if(plan.eyes.begin(), plan.eyes.end(), [&](const EyePlan& p) { return p.prim == id; });
    SetEyeOptions(index, id, entry.prim.get(),
                  e == plan.eyes.end() ? EyeRenderOptions{} : e->RenderOptions(lightOrder));
  }
  ApplyMeshRefinement(plan.meshes, index);
  ApplyRenderPlan(plan, settings);
}

void ApplyRenderPlan(const RenderPlan& plan, RenderSettings* settings) { settings->eyeSwitches = plan.switches; }

void ClearRenderPlan(RenderIndex* index) {
  // Unplanned eye meshes go back to the scene's level (--complexity), re-refining if the plan had lowered it.
  for (const auto& [id, entry] : index->Rprims()) SetEyeOptions(index, id, entry.prim.get(), EyeRenderOptions{});
  ClearMeshRefinement(index);
  index->GetRenderDelegate()->GetRenderParam()->SetMeshLevelsAwaitPlan(false);
}

std::vector<std::string> RenderPlan::SummaryLines() const {
  std::vector<std::string> lines;
  for (const EyePlan& e : eyes) {
    std::string mneeLights;
    for (const LightFacts& l : e.lights)
      if (l.strategy == LightStrategy::Mnee)
        mneeLights += (mneeLights.empty() ? "" : ",") + l.light.substr(l.light.rfind('/') + 1);
    std::string line = "plan " + e.prim + ": " + Num(e.pixels, 4) + " px" +
                       (e.blurPixels > 1 ? " (blur " + Num(e.blurPixels, 3) + " px)" : "") +
                       (e.behindCamera ? " (behind camera)"
                        : e.inView     ? ""
                                       : " (out of view)") +
                       ", mnee " + (e.switches.mnee ? "on [" + mneeLights + "]" : std::string("off")) +
                       ", all solutions " + (e.switches.mneeAllSolutions ? "on" : "off") + ", sss " + ToString(e.sss) +
                       ", limbal arc " + (e.switches.limbalArc ? "on" : "off") + ", chamber " +
                       std::to_string(e.chamberEvents) + ", cache " + std::to_string(e.chamberCacheRings) + " rings";
    if (e.refineLevel >= 0) line += ", subdiv " + std::to_string(e.refineLevel);
    lines.push_back(line);
  }
  if (eyes.empty()) lines.push_back("plan: no eyes in the scene");
  if (!meshes.empty()) {
    std::map<int, int> perLevel;
    for (const MeshPlan& m : meshes) ++perLevel[m.refineLevel];
    std::string line = "plan meshes: " + std::to_string(meshes.size()) + " subdivision meshes by size on screen:";
    for (const auto& [level, count] : perLevel)
      line += " level " + std::to_string(level) + " x" + std::to_string(count);
    lines.push_back(line);
  }
  return lines;
}

}  // namespace hdeye
