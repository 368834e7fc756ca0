// Rendering: the render settings, the render delegate that holds them, the render pass (run with the GIL released,
// taken back only for the pass callback) and what it reports.
#include "bindings.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/pass/renderPass.h"
#include "hdeye/prims/renderDelegate.h"

#include <nanobind/operators.h>
#include <nanobind/stl/function.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

namespace hdeye::python {

namespace {

/// A stop request another thread can make while a render runs (the render reads it between passes).
struct StopFlag {
  std::atomic<bool> requested{false};
};

/// RenderPass.render: the progressive loop with the GIL released; the callback (a Python callable taking a
/// PassProgress, returning False to stop) runs on this thread with the GIL taken back. An exception it raises stops
/// the render and is raised again here.
RenderStats RenderProgressively(RenderPass& pass, const PrimId& camera,
                                const std::vector<std::pair<std::string, PrimId>>& bindings, nb::object callback,
                                StopFlag* stop, double passSeconds, int firstPassStride) {
  std::vector<AovBinding> b;
  for (const auto& [aov, buffer] : bindings) b.push_back({aov, buffer});
  ProgressiveControl control;
  control.passSeconds = passSeconds;
  control.firstPassStride = firstPassStride;
  control.stop = stop ? &stop->requested : nullptr;
  bool failed = false;
  if (!callback.is_none())
    control.onPass = [&](const PassProgress& progress) {
      nb::gil_scoped_acquire gil;
      try {
        nb::object keepGoing = callback(progress);
        return keepGoing.is_none() || nb::cast<bool>(keepGoing);
      } catch (nb::python_error& e) {
        e.restore();  // raised again below, once the render has returned
        failed = true;
        return false;
      }
    };
  RenderStats stats;
  {
    nb::gil_scoped_release release;
    stats = pass.Execute(camera, b, control);
  }
  if (failed) throw nb::python_error();
  return stats;
}

/// A RenderSettings property that is the switch `field` of its eye_switches (the same record, not a copy).
template <bool EyeSwitches::*field>
void EyeSwitchProperty(nb::class_<RenderSettings>& c, const char* name, const char* doc) {
  c.def_prop_rw(
      name, [](const RenderSettings& s) { return s.eyeSwitches.*field; },
      [](RenderSettings& s, bool value) { s.eyeSwitches.*field = value; }, doc);
}

/// EyeSwitches: the eye's render switches, one record with one name per switch (eyeSwitches.h).
void BindEyeSwitches(nb::module_& m) {
  nb::class_<EyeSwitches>(m, "EyeSwitches",
                          "The eye's render switches: one record that the settings, each eye's plan and the plan's "
                          "globals carry (eyeSwitches.h).")
      .def(nb::init<>())
      .def_rw("mnee", &EyeSwitches::mnee, "MNEE for the iris's direct light (off: path tracing through the cornea)")
      .def_rw("mnee_all_solutions", &EyeSwitches::mneeAllSolutions, "MNEE searches every refraction path")
      .def_rw("sclera_scattering", &EyeSwitches::scleraScattering,
              "eye meshes: random-walk sclera subsurface scattering (off: Lambertian sclera)")
      .def_rw("limbal_arc", &EyeSwitches::limbalArc,
              "eye meshes: the limbal-arc teleportation cylinder (settings: where the eye's eye:limbalArc asks too)")
      .def(nb::self == nb::self)
      .def(nb::self != nb::self);
}

/// RenderSettings, field by field (the settings a render pass reads).
void BindRenderSettings(nb::module_& m) {
  nb::class_<RenderSettings> settings(m, "RenderSettings");
  settings.def(nb::init<>())
      .def_rw("samples_per_pixel", &RenderSettings::samplesPerPixel)
      .def_rw("time_limit_seconds", &RenderSettings::timeLimitSeconds)
      .def_rw("seed", &RenderSettings::seed)
      .def_rw("threads", &RenderSettings::threads)
      .def_rw("max_depth", &RenderSettings::maxDepth)
      .def_rw("first_sample", &RenderSettings::firstSample)
      .def_rw("mis", &RenderSettings::mis)
      .def_rw("eye_switches", &RenderSettings::eyeSwitches,
              "the switches of eyes no render plan was applied to (a plan sets its global switches here)")
      .def_prop_rw(
          "chamber_estimator", [](const RenderSettings& s) { return ChamberEstimatorName(s.chamberEstimator); },
          [](RenderSettings& s, const std::string& name) {
            const std::optional<ChamberEstimator> e = ParseChamberEstimator(name);
            if (!e)
              throw nb::value_error(("chamber_estimator: '" + name + "' is not path, cache or controlVariate").c_str());
            s.chamberEstimator = *e;
          },
          "how the iris gathers chamber light: path, cache or controlVariate (docs/iris_benchmark.md)")
      .def_rw("dome_light_camera_visibility", &RenderSettings::domeLightCameraVisibility,
              "camera rays see dome lights (eyerecord: --enableDomeLightVisibility)")
      .def_rw("texture_filtering", &RenderSettings::textureFiltering,
              "filter textures over each ray's footprint (off: finest level, point sampled)")
      .def_rw("texture_footprint_scale", &RenderSettings::textureFootprintScale,
              "the camera's ray cone as a fraction of a pixel")
      .def_rw("pixel_aspect_ratio", &RenderSettings::pixelAspectRatio,
              "a pixel's width over its height (UsdRender's pixelAspectRatio; 1: square)")
      .def_rw("time_strata", &RenderSettings::timeStrata,
              "motion blur: 0 a continuous time per path; N the centres of N shutter strata (sample s at s mod N)")
      .def_prop_rw(
          "sampler",
          [](const RenderSettings& s) {
            return std::string(s.sampler == SamplerKind::ZSobol ? "zsobol" : "independent");
          },
          [](RenderSettings& s, const std::string& name) {
            if (name == "zsobol")
              s.sampler = SamplerKind::ZSobol;
            else if (name == "independent")
              s.sampler = SamplerKind::Independent;
            else
              throw nb::value_error(("sampler must be 'zsobol' or 'independent', not '" + name + "'").c_str());
          },
          "where paths' random numbers come from: 'zsobol' (stratified per pixel) or 'independent' (hashed)")
      .def_rw("iris_light_splits", &RenderSettings::irisLightSplits,
              "eyes: MNEE estimates averaged at a path's first iris vertex")
      .def_rw("chamber_splits", &RenderSettings::chamberSplits,
              "eyes: chamber walks continued from a path's first iris vertex")
      .def_rw("catchlight_samples", &RenderSettings::catchlightSamples,
              "eyes: reflection-only camera paths per sample at a catchlight's edge pixels (1: none)");
  EyeSwitchProperty<&EyeSwitches::mnee>(settings, "mnee", "eye_switches.mnee");
  EyeSwitchProperty<&EyeSwitches::mneeAllSolutions>(settings, "mnee_all_solutions", "eye_switches.mnee_all_solutions");
  EyeSwitchProperty<&EyeSwitches::scleraScattering>(settings, "sclera_scattering", "eye_switches.sclera_scattering");
}

/// What a render reports: its stats, the progress between passes, the stop flag, the pass schedule.
void BindRenderProgress(nb::module_& m) {
  nb::class_<RenderStats>(m, "RenderStats")
      .def_ro("samples", &RenderStats::samples)
      .def_ro("rays", &RenderStats::rays)
      .def_ro("seconds", &RenderStats::seconds)
      .def_ro("passes", &RenderStats::passes)
      .def_ro("non_finite_samples", &RenderStats::nonFiniteSamples)
      .def_ro("capped_walks", &RenderStats::cappedWalks, "sclera walks dropped at their step cap")
      .def_ro("time_limit_reached", &RenderStats::timeLimitReached)
      .def_ro("first_pass_seconds", &RenderStats::firstPassSeconds, "seconds to the end of the first pass")
      .def_ro("catchlight_pixels", &RenderStats::catchlightPixels,
              "pixels at a catchlight's edge, sampled with catchlight_samples sub-samples")
      .def_ro("catchlight_seconds", &RenderStats::catchlightSeconds, "seconds spent finding them")
      .def_ro("preview_seconds", &RenderStats::previewSeconds,
              "seconds to the first stage of a first pass in stages (first_pass_stride), 0 without")
      .def_ro("stopped", &RenderStats::stopped, "a stop request or the callback ended the render early");

  nb::class_<PassProgress>(m, "PassProgress")
      .def_ro("samples_done", &PassProgress::samplesDone)
      .def_ro("samples_total", &PassProgress::samplesTotal)
      .def_ro("pass_samples", &PassProgress::passSamples)
      .def_ro("seconds", &PassProgress::seconds)
      .def_ro("first_pass_seconds", &PassProgress::firstPassSeconds)
      .def_ro("stride", &PassProgress::stride,
              "1, or during a first pass in stages: the pixels with x and y multiples of it have their sample")
      .def_ro("preview_seconds", &PassProgress::previewSeconds);

  nb::class_<StopFlag>(m, "StopFlag", "A stop request, set from any thread, honoured between passes.")
      .def(nb::init<>())
      .def("request", [](StopFlag& f) { f.requested = true; })
      .def("clear", [](StopFlag& f) { f.requested = false; })
      .def_prop_ro("requested", [](const StopFlag& f) { return f.requested.load(); });

  m.def("next_pass_samples", &NextPassSamples, nb::arg("remaining"), nb::arg("last_pass"),
        nb::arg("seconds_per_sample"), nb::arg("pass_seconds"), nb::arg("time_left"),
        "The samples per pixel of the progressive loop's next pass (renderer.h NextPassSamples).");
}

/// The render delegate and the render pass that renders (and plans) through it.
void BindRenderPass(nb::module_& m) {
  nb::class_<RenderDelegate>(m, "RenderDelegate")
      .def(nb::init<>())
      .def_prop_ro(
          "settings", [](RenderDelegate& d) -> RenderSettings& { return d.Settings(); },
          nb::rv_policy::reference_internal)
      .def(
          "warnings", [](RenderDelegate& d) { return d.GetRenderParam()->Warnings(); },
          "Problems found at sync that did not stop the render (textures that cannot be read, primvars dropped), one "
          "line each.")
      .def_static("supported_rprim_types", &RenderDelegate::SupportedRprimTypes)
      .def_static("supported_sprim_types", &RenderDelegate::SupportedSprimTypes);

  nb::class_<RenderPass>(m, "RenderPass")
      .def(nb::init<RenderIndex*>(), nb::keep_alive<1, 2>())
      .def(
          "execute",
          [](RenderPass& pass, const PrimId& camera, const std::vector<std::pair<std::string, PrimId>>& bindings) {
            std::vector<AovBinding> b;
            for (const auto& [aov, buffer] : bindings) b.push_back({aov, buffer});
            return pass.Execute(camera, b);
          },
          nb::arg("camera_id"), nb::arg("bindings"), nb::call_guard<nb::gil_scoped_release>(),
          "Syncs the index and renders settings.samples_per_pixel samples from settings.first_sample into the "
          "bound buffers (which accumulate). bindings: [(aov name, render buffer id)].")
      .def("render", &RenderProgressively, nb::arg("camera_id"), nb::arg("bindings"),
           nb::arg("callback").none() = nb::none(), nb::arg("stop").none() = nb::none(), nb::arg("pass_seconds") = 0.25,
           nb::arg("first_pass_stride") = 1,
           "Syncs the index once and renders settings.samples_per_pixel samples from settings.first_sample in "
           "passes, stopping early at settings.time_limit_seconds, when `stop` is requested or when callback("
           "PassProgress) returns False. The callback runs between passes on this thread; the GIL is released "
           "while passes render. first_pass_stride (a power of two): the first pass renders a grid of this stride "
           "first, then the finer ones, with the callback after each stage (PassProgress.stride).")
      .def("plan", &RenderPass::Plan, nb::arg("camera_id"), nb::arg("width"), nb::arg("height"), nb::arg("overrides"),
           nb::arg("rules") = PlanRules{}, nb::call_guard<nb::gil_scoped_release>(),
           "Syncs the index and returns the render plan for the camera and image size, without rendering.")
      .def("prim_ids_by_index", &RenderPass::PrimIdsByIndex,
           "The rprim id of each primIndex (the primId and hitId AOVs' values) of the last execute, in order.");
}

}  // namespace

void BindRender(nb::module_& m) {
  BindEyeSwitches(m);
  BindRenderSettings(m);
  BindRenderProgress(m);
  BindRenderPass(m);
}

}  // namespace hdeye::python
