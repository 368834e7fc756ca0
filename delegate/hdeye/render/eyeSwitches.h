#pragma once
// The eye's render switches: one record, one name per switch, that every layer passes along as it is -- the render
// settings (the switches of eyes no plan was applied to), each eye's plan (EyePlan) and what it applies to the eye
// (EyeRenderOptions), the plan's global switches (RenderPlan), and the renderer's lighting of the eye it shades
// (EyeLighting). The USD attribute (eye:limbalArc), the CLI flags (--no-mnee, --mnee, --mnee-all-solutions) and the
// plan's overrides (PlanOverrides, one optional per switch of the same name) set them.

namespace hdeye {

struct EyeSwitches {
  /// MNEE (the iris's direct light through the cornea) for at least one light. Off: every light reaches the iris
  /// only by paths that refract out of the cornea and happen to hit it (plain path tracing, for A/B comparisons).
  bool mnee = true;
  bool mneeAllSolutions = false;  ///< MNEE searches every refraction path to a light (caustic folds)
  /// Eye meshes: the sclera is a path-traced random-walk volume. Off: a Lambertian surface. Analytic eyes never walk.
  bool scleraScattering = true;
  /// Eye meshes: the walk's teleportation cylinder (the limbal arc). In the render settings, for eyes without a plan,
  /// it applies where the eye's own EyeParams::limbalArc also asks for it.
  bool limbalArc = true;

  bool operator==(const EyeSwitches& o) const {
    return mnee == o.mnee && mneeAllSolutions == o.mneeAllSolutions && scleraScattering == o.scleraScattering &&
           limbalArc == o.limbalArc;
  }
  bool operator!=(const EyeSwitches& o) const { return !(*this == o); }
};

}  // namespace hdeye
