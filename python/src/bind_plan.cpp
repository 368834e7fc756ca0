// The render plan: what the user set (PlanOverrides), the thresholds (PlanRules), and the plan with its per-eye and
// per-light decisions as read-only structs (python/eyerender/plan.py writes them as JSON).
#include "bindings.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/plan/renderPlan.h"
#include "hdeye/render/renderSettings.h"

#include <nanobind/stl/map.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

namespace hdeye::python {

namespace {

/// What the plan is given: the user's overrides and the planner's thresholds.
void BindPlanInputs(nb::module_& m) {
  nb::class_<PlanOverrides>(m, "PlanOverrides",
                            "What the user set explicitly (flags, render settings, authored schema values): wins over "
                            "the render plan. None: the planner decides.")
      .def(nb::init<>())
      .def_rw("mnee", &PlanOverrides::mnee, nb::arg("value").none())
      .def_rw("mnee_all_solutions", &PlanOverrides::mneeAllSolutions, nb::arg("value").none())
      .def_rw("sclera_scattering", &PlanOverrides::scleraScattering, nb::arg("value").none())
      .def_rw("limbal_arc", &PlanOverrides::limbalArc, nb::arg("value").none())
      .def_rw("chamber_events", &PlanOverrides::chamberEvents, nb::arg("value").none(),
              "events the chamber walk follows per path (>= 1); None: the planner decides")
      .def_rw("refine_level_ceiling", &PlanOverrides::refineLevelCeiling, "the --complexity level")
      .def(
          "set_authored_limbal_arc",
          [](PlanOverrides& o, const PrimId& prim, bool value) { o.authored[prim].limbalArc = value; }, nb::arg("prim"),
          nb::arg("value"), "eye:limbalArc authored on the eye prim `prim`.");

  nb::class_<PlanRules>(m, "PlanRules", "The render plan's thresholds (docs/render_plan.md).")
      .def(nb::init<>())
      .def_rw("mnee_min_pixels", &PlanRules::mneeMinPixels, "pixels")
      .def_rw("mnee_max_solid_angle_sr", &PlanRules::mneeMaxSolidAngleSr, "steradians")
      .def_rw("mnee_max_solid_angle_sr_grazing", &PlanRules::mneeMaxSolidAngleSrGrazing, "steradians")
      .def_rw("grazing_angle_deg", &PlanRules::grazingAngleDeg, "degrees")
      .def_rw("mnee_min_dome_contrast", &PlanRules::mneeMinDomeContrast, "E[L^2] / E[L]^2, unitless")
      .def_rw("all_solutions_min_angle_deg", &PlanRules::allSolutionsMinAngleDeg, "degrees")
      .def_rw("all_solutions_min_pixels", &PlanRules::allSolutionsMinPixels, "pixels")
      .def_rw("chamber_events", &PlanRules::chamberEvents, "events per path")
      .def_rw("chamber_cache_pixels_per_ring", &PlanRules::chamberCachePixelsPerRing, "pixels of iris circle per ring")
      .def_rw("chamber_cache_min_rings", &PlanRules::chamberCacheMinRings)
      .def_rw("chamber_cache_max_rings", &PlanRules::chamberCacheMaxRings)
      .def_rw("sss_min_pixels", &PlanRules::sssMinPixels, "pixels")
      .def_rw("sss_min_limbus_pixels", &PlanRules::sssMinLimbusPixels, "pixels")
      .def_rw("limbal_arc_min_light_angle_deg", &PlanRules::limbalArcMinLightAngleDeg, "degrees")
      .def_rw("refine_pixels_level1", &PlanRules::refinePixelsLevel1, "pixels")
      .def_rw("refine_max_level", &PlanRules::refineMaxLevel, "Catmull-Clark level")
      .def_rw("float_hit_error_mm", &PlanRules::floatHitErrorMm, "mm")
      .def_rw("float_max_error_pixels", &PlanRules::floatMaxErrorPixels, "pixels");
}

/// The plan's enumerations (light kinds, strategies, sclera models) and their names.
void BindPlanEnums(nb::module_& m) {
  nb::enum_<LightType>(m, "LightType", "The light kinds the delegate renders.")
      .value("SPHERE", LightType::Sphere)
      .value("DISTANT", LightType::Distant)
      .value("RECT", LightType::Rect)
      .value("DISK", LightType::Disk)
      .value("CYLINDER", LightType::Cylinder)
      .value("DOME", LightType::Dome);
  nb::enum_<LightStrategy>(m, "LightStrategy", "How the iris gets a light's direct light.")
      .value("MNEE", LightStrategy::Mnee, "manifold next event estimation through the cornea")
      .value("BSDF", LightStrategy::Bsdf, "BSDF sampling with MIS: paths that leave the cornea and hit the light")
      .value("NONE", LightStrategy::None, "the light cannot reach the iris");
  nb::enum_<ScleraModel>(m, "ScleraModel", "How an eye's sclera is shaded.")
      .value("RANDOM_WALK", ScleraModel::RandomWalk, "path-traced random-walk subsurface scattering")
      .value("DIFFUSE", ScleraModel::Diffuse, "a Lambertian surface")
      .value("NONE", ScleraModel::None, "no sclera volume to walk (analytic eyes)");
  m.def("to_string", nb::overload_cast<LightStrategy>(&ToString), nb::arg("value"),
        "The plan's name of a strategy, sclera model or light kind (\"mnee\", \"randomWalk\", \"dome\", ...).");
  m.def("to_string", nb::overload_cast<ScleraModel>(&ToString), nb::arg("value"));
  m.def("to_string", nb::overload_cast<LightType>(&ToString), nb::arg("value"));
}

/// The plan's per-eye parts: each light as the eye sees it, the eye's facts and decisions, the meshes' levels.
void BindPlanParts(nb::module_& m) {
  nb::class_<LightFacts>(m, "LightFacts", "One light as one eye sees it, and what the eye does with it.")
      .def_ro("light", &LightFacts::light, "the light's prim id")
      .def_ro("kind", &LightFacts::kind)
      .def_ro("solid_angle_sr", &LightFacts::solidAngleSr, "subtended at the iris centre, steradians")
      .def_ro("angle_off_gaze_deg", &LightFacts::angleOffGazeDeg, "degrees; -1 for a dome (no direction)")
      .def_ro("angular_radius_deg", &LightFacts::angularRadiusDeg, "half the angle the light subtends, degrees")
      .def_ro("reaches_iris", &LightFacts::reachesIris)
      .def_ro("radiance_contrast", &LightFacts::radianceContrast, "dome: E[L^2] / E[L]^2 about the gaze; 1 otherwise")
      .def_ro("strategy", &LightFacts::strategy)
      .def_ro("why", &LightFacts::why);

  nb::class_<EyePlan>(m, "EyePlan", "An eye's facts and decisions; `why` maps each decision to its reason.")
      .def_ro("prim", &EyePlan::prim)
      .def_ro("geometry", &EyePlan::geometry, "the rprim type: analyticEye or eyeMesh")
      .def_ro("pixels", &EyePlan::pixels, "projected diameter of the 15.08 mm iris circle, pixels")
      .def_ro("in_view", &EyePlan::inView)
      .def_ro("behind_camera", &EyePlan::behindCamera)
      .def_ro("view_angle_deg", &EyePlan::viewAngleDeg, "gaze to the direction to the camera, degrees")
      .def_ro("limbus_pixels", &EyePlan::limbusPixels, "the limbus band's projected width, pixels")
      .def_ro("blur_pixels", &EyePlan::blurPixels, "circle of confusion at the iris, pixels (0: in focus)")
      .def_ro("resolved_pixels", &EyePlan::resolvedPixels, "pixels / max(1, blur_pixels)")
      .def_ro("lights", &EyePlan::lights)
      .def_ro("switches", &EyePlan::switches, "the switches the plan gives the eye (EyeSwitches)")
      .def_prop_ro(
          "mnee", [](const EyePlan& e) { return e.switches.mnee; }, "switches.mnee")
      .def_prop_ro(
          "mnee_all_solutions", [](const EyePlan& e) { return e.switches.mneeAllSolutions; },
          "switches.mnee_all_solutions")
      .def_ro("chamber_events", &EyePlan::chamberEvents)
      .def_ro("chamber_cache_rings", &EyePlan::chamberCacheRings, "rings of the chamber-light cache's grid")
      .def_ro("sss", &EyePlan::sss)
      .def_prop_ro(
          "limbal_arc", [](const EyePlan& e) { return e.switches.limbalArc; }, "switches.limbal_arc")
      .def_ro("refine_level", &EyePlan::refineLevel, "planned Catmull-Clark level; -1 for analytic eyes")
      .def_ro("pixel_footprint_mm", &EyePlan::pixelFootprintMm, "mm of the eye per pixel")
      .def_ro("float_would_suffice", &EyePlan::floatWouldSuffice)
      .def_ro("why", &EyePlan::why);

  nb::class_<MeshPlan>(m, "MeshPlan", "A subdivision mesh's size on screen and its planned level.")
      .def_ro("prim", &MeshPlan::prim)
      .def_ro("pixels", &MeshPlan::pixels, "projected bounding-sphere diameter, pixels (largest over instances)")
      .def_ro("instances", &MeshPlan::instances)
      .def_ro("scene_level", &MeshPlan::sceneLevel, "the --complexity level")
      .def_ro("refine_level", &MeshPlan::refineLevel, "the level it renders")
      .def_ro("why", &MeshPlan::why);
}

/// The plan itself, applying it, and clearing it from an index.
void BindRenderPlan(nb::module_& m) {
  nb::class_<RenderPlan>(m, "RenderPlan", "What the render plan decided, per eye, with reasons.")
      .def_ro("width", &RenderPlan::width)
      .def_ro("height", &RenderPlan::height)
      .def_ro("camera", &RenderPlan::camera)
      .def_ro("eyes", &RenderPlan::eyes)
      .def_ro("meshes", &RenderPlan::meshes, "non-eye subdivision meshes: size on screen, planned level")
      .def_ro("why", &RenderPlan::why, "reasons for the global switches")
      .def("summary_lines", &RenderPlan::SummaryLines, "One line per eye, for printing at render start.")
      .def(
          "apply",
          [](const RenderPlan& p, RenderSettings& s, RenderIndex* index) {
            if (index)
              ApplyRenderPlan(p, index, &s);
            else
              ApplyRenderPlan(p, &s);
          },
          nb::arg("settings"), nb::arg("index").none() = nb::none(),
          "Applies the plan: with the render index, each eye rprim gets its own switches (MNEE per light, all "
          "solutions, chamber bound, sclera walk, limbal arc); the plan's global switches become the settings' "
          "eye_switches, the defaults for eyes without a plan. Without the index, "
          "only the global switches.")
      .def_ro("switches", &RenderPlan::switches,
              "the global switches (EyeSwitches) apply sets as the settings' eye_switches: the defaults for eyes "
              "without a plan")
      .def_prop_ro(
          "mnee", [](const RenderPlan& p) { return p.switches.mnee; }, "switches.mnee")
      .def_prop_ro(
          "mnee_all_solutions", [](const RenderPlan& p) { return p.switches.mneeAllSolutions; },
          "switches.mnee_all_solutions")
      .def_prop_ro(
          "sclera_scattering", [](const RenderPlan& p) { return p.switches.scleraScattering; },
          "switches.sclera_scattering");

  m.def(
      "clear_render_plan", [](RenderIndex& index) { ClearRenderPlan(&index); }, nb::arg("index"),
      "Resets every eye of the index to unplanned: renders use the settings' global switches.");
}

}  // namespace

void BindPlan(nb::module_& m) {
  BindPlanInputs(m);
  BindPlanEnums(m);
  BindPlanParts(m);
  BindRenderPlan(m);
}

}  // namespace hdeye::python
