#include "hdeye/plan/meshRefinePlan.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/plan/renderPlan.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderDelegate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hdeye {

namespace {

std::string Pixels(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// A plain mesh of the index (not an eye: eye meshes are planned with their eye).
Mesh* PlainMesh(const RenderIndex::Entry<Rprim>& entry) {
  return entry.type == primTypes::kMesh ? dynamic_cast<Mesh*>(entry.prim.get()) : nullptr;
}

}  // namespace

double ProjectedSpherePixels(const CameraView& camera, int width, int height, const glm::dvec3& centre, double radius) {
  const glm::dvec3 c(glm::inverse(camera.transform) * glm::dvec4(centre, 1));
  const CameraParams& cp = camera.params;
  const double halfW = cp.horizontalAperture / 2;  // film half-width (mm, or scene units when orthographic)
  if (cp.orthographic) return radius / halfW * width;
  const double depth = -c.z;  // the camera looks down its -z
  if (depth <= -radius) return 0;
  if (depth <= radius) return std::hypot(double(width), double(height));
  return radius * cp.focalLength / (depth * halfW) * width;
}

int RefineLevelForPixels(double pixels, const PlanRules& rules, int ceiling, std::string* why) {
  int level = 0;
  if (pixels >= rules.refinePixelsLevel1) level = 1 + int(std::floor(std::log2(pixels / rules.refinePixelsLevel1)));
  level = std::min(level, rules.refineMaxLevel);
  const int planned = std::min(level, ceiling);
  if (why)
    *why = Pixels(pixels) + " px -> level " + std::to_string(level) +
           (planned < level ? ", held at the --complexity ceiling " + std::to_string(ceiling) : std::string()) +
           ": one level per doubling from " + Pixels(rules.refinePixelsLevel1) + " px, at most " +
           std::to_string(rules.refineMaxLevel) + " (sweep refine, measured on eye meshes)";
  return planned;
}

std::vector<MeshPlan> PlanMeshRefinement(const RenderIndex& index, const CameraView& camera, int width, int height,
                                         const PlanOverrides& overrides, const PlanRules& rules) {
  std::vector<MeshPlan> plans;
  for (const auto& [id, entry] : index.Rprims()) {
    const Mesh* mesh = PlainMesh(entry);
    if (!mesh || mesh->SceneRefineLevel() <= 0 || mesh->Points().empty()) continue;
    // The bounding sphere of the rendered points (object space), carried by each instance: its centre moved, its
    // radius scaled by the longest column of the linear part (exact for rotation and scale, an estimate under shear).
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const Vec3f& p : mesh->Points()) lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
    const glm::dvec3 centre = (lo + hi) / 2.0;
    const double radius = glm::length(hi - lo) / 2;
    MeshPlan plan;
    plan.prim = id;
    plan.sceneLevel = mesh->SceneRefineLevel();
    plan.instances = int(mesh->InstanceWorldTransforms().size());
    for (const Matrix4d& m : mesh->InstanceWorldTransforms()) {
      const double scale =
          std::max({glm::length(glm::dvec3(m[0])), glm::length(glm::dvec3(m[1])), glm::length(glm::dvec3(m[2]))});
      plan.pixels = std::max(plan.pixels, ProjectedSpherePixels(camera, width, height,
                                                                glm::dvec3(m * glm::dvec4(centre, 1)), radius * scale));
    }
    plan.refineLevel =
        std::min(plan.sceneLevel, RefineLevelForPixels(plan.pixels, rules, overrides.refineLevelCeiling, &plan.why));
    plans.push_back(std::move(plan));
  }
  return plans;
}

void ApplyMeshRefinement(const std::vector<MeshPlan>& meshes, RenderIndex* index) {
  for (const MeshPlan& plan : meshes) {
    auto* mesh = dynamic_cast<Mesh*>(index->GetRprim(plan.prim));
    if (!mesh) continue;
    mesh->SetPlannedRefineLevel(plan.refineLevel);
    if (mesh->RefineLevelFor(mesh->SceneRefineLevel()) != mesh->RefineLevel())
      index->GetChangeTracker().MarkDirty(plan.prim, dirty::DirtyTopology);
  }
}

void ClearMeshRefinement(RenderIndex* index) {
  for (const auto& [id, entry] : index->Rprims()) {
    Mesh* mesh = PlainMesh(entry);
    if (!mesh) continue;
    mesh->ClearPlannedRefineLevel();
    if (mesh->SceneRefineLevel() >= 0 && mesh->RefineLevelFor(mesh->SceneRefineLevel()) != mesh->RefineLevel())
      index->GetChangeTracker().MarkDirty(id, dirty::DirtyTopology);
  }
}

}  // namespace hdeye
