#pragma once
// What the render plan (renderPlan.h) switches per eye: the renderer reads these from the eye it is
// shading. Each eye rprim (analyticEye, eyeMesh) owns one in its GeometryContext, which survives sync
// (EyeGeometry is rebuilt at every sync, the context is not); ApplyRenderPlan writes it before each render.
// An eye no plan was applied to (`planned` false) renders with RenderSettings' global switches and its
// own EyeParams::limbalArc: what `--no-auto-plan` renders.
#include "hdeye/render/eyeSwitches.h"

#include <vector>

namespace hdeye {

struct EyeRenderOptions {
  /// Set by ApplyRenderPlan; false: the renderer ignores the fields below and uses RenderSettings.
  bool planned = false;
  /// The eye's switches (EyePlan::switches as planned).
  EyeSwitches switches;
  /// Per light, over the render's light list (RenderPass::Execute: the index's light sprims in id order, the
  /// order the plan measured them in): true where MNEE counts the light, false where paths leaving the iris
  /// must count it. Empty, or of another length than the light list (a light added without re-planning):
  /// MNEE for every light (when switches.mnee). Each light is counted by exactly one of the two, never both.
  std::vector<bool> mneeLights;
  /// Events a camera path may take inside the anterior chamber before it is dropped (reported in
  /// EyeEvent::walkCapReached). 64: the full walk (sweep chamber, docs/render_plan.md).
  int maxChamberEvents = 64;
  /// Rings of the eye's chamber-light cache grid (ChamberCacheGrid; three sectors per ring), when the render uses
  /// the cache (RenderSettings::chamberEstimator). 0: the renderer's default grid (48 rings).
  int chamberCacheRings = 0;
  /// Eye meshes: the planned Catmull-Clark level. The mesh renders min(this, the level the scene gave it at
  /// populate: --complexity for catmullClark meshes, 0 for "none"), so the plan can only lower it. -1: the scene's
  /// level. Unlike the switches above, which the renderer reads per ray, a level is geometry: ApplyRenderPlan
  /// marks the mesh DirtyTopology when its rendered level would change, and the mesh re-refines at the next sync.
  int refineLevel = -1;
};

}  // namespace hdeye
