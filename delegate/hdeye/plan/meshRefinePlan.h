#pragma once
// The render plan's subdivision level for every Catmull-Clark mesh that is not an eye: the eye meshes' screen-size
// rule (docs/render_plan.md, sweep refine: level 0 under PlanRules::refinePixelsLevel1, one level per doubling,
// at most refineMaxLevel, capped by --complexity) applied to the mesh's projected bounding sphere, the largest
// over its instances. The rule was measured on eye meshes; applying it to other meshes assumes a mesh's outline
// and shading need no more refinement per pixel than an eye's do.
//
// While a plan is pending (RenderParam::SetMeshLevelsAwaitPlan, which RenderPass::Plan sets), a mesh synced for the
// first time refines to level 0 only; the plan measures it and raises the meshes that need more, so memory peaks
// at what the picture needs, not at the --complexity level of every mesh.
#include "hdeye/hd/types.h"
#include "hdeye/render/cameraView.h"

#include <string>
#include <vector>

namespace hdeye {

class RenderIndex;
struct PlanRules;
struct PlanOverrides;

/// One subdivision mesh's size on screen and its planned level.
struct MeshPlan {
  PrimId prim;
  double pixels = 0;    ///< projected diameter of its bounding sphere, pixels (largest over its instances)
  int instances = 1;    ///< instances measured
  int sceneLevel = 0;   ///< the scene delegate's level (--complexity)
  int refineLevel = 0;  ///< what it renders: min(the rule's level, sceneLevel)
  std::string why;
};

/// Projected diameter (pixels) of a world-space sphere (centre, radius in scene units) in a width x height image:
/// the image diagonal when the sphere reaches the camera plane, 0 when it is wholly behind it.
double ProjectedSpherePixels(const CameraView& camera, int width, int height, const glm::dvec3& centre, double radius);

/// The screen-size rule: level 0 under rules.refinePixelsLevel1 pixels, one more per doubling, at most
/// rules.refineMaxLevel, then at most `ceiling`. `why` (may be null) gets the reason.
int RefineLevelForPixels(double pixels, const PlanRules& rules, int ceiling, std::string* why);

/// Plans every non-eye mesh of the synced index whose scene level is above 0.
std::vector<MeshPlan> PlanMeshRefinement(const RenderIndex& index, const CameraView& camera, int width, int height,
                                         const PlanOverrides& overrides, const PlanRules& rules);

/// Gives each planned mesh its level (its topology is marked dirty when that changes what it renders).
void ApplyMeshRefinement(const std::vector<MeshPlan>& meshes, RenderIndex* index);

/// Forgets every mesh's planned level: meshes render their scene level again (re-refining where that differs).
void ClearMeshRefinement(RenderIndex* index);

}  // namespace hdeye
