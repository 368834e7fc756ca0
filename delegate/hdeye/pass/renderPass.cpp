#include "hdeye/pass/renderPass.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/prims/camera.h"
#include "hdeye/prims/light.h"
#include "hdeye/prims/material.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/render/renderContext.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace hdeye {

namespace {

AovBuffers BindBuffers(const RenderIndex& index, const std::vector<AovBinding>& bindings) {
  AovBuffers aovs;
  for (const AovBinding& b : bindings) {
    auto* buffer = dynamic_cast<RenderBuffer*>(index.GetBprim(b.renderBufferId));
    if (!buffer) throw std::runtime_error("render pass: render buffer " + b.renderBufferId + " not found");
    AccumulationBuffer** slot = b.aovName == "color"       ? &aovs.color
                                : b.aovName == "albedo"    ? &aovs.albedo
                                : b.aovName == "normal"    ? &aovs.normal
                                : b.aovName == "depth"     ? &aovs.depth
                                : b.aovName == "primId"    ? &aovs.primId
                                : b.aovName == "irisMnee"  ? &aovs.irisMnee
                                : b.aovName == "glint"     ? &aovs.glint
                                : b.aovName == "iris"      ? &aovs.iris
                                : b.aovName == "sclera"    ? &aovs.sclera
                                : b.aovName == "nonEye"    ? &aovs.nonEye
                                : b.aovName == "limbalArc" ? &aovs.limbalArc
                                : b.aovName == "hitId"     ? &aovs.hitId
                                                           : nullptr;
    if (!slot) throw std::runtime_error("render pass: unknown AOV '" + b.aovName + "'");
    *slot = buffer;
  }
  return aovs;
}

/// The material sprim `id` as the renderer shades it; the fallback material when there is none.
SurfaceMaterial Resolve(RenderIndex& index, const PrimId& id) {
  const auto* material = dynamic_cast<const Material*>(index.GetSprim(id));
  if (!material) return SurfaceMaterial{};
  const MaterialTextures& textures = material->Textures();
  const bool textured = std::any_of(textures.begin(), textures.end(), [](const BoundTexture& t) { return t.texture; });
  return SurfaceMaterial{material->Params(), textured ? &textures : nullptr, true};
}

/// Flags, over every rprim index, the rprims named in `excludes` (ids of prims not in the index are skipped:
/// the scene delegate may name prims that are not rendered). Leaves `flags` empty when none is named.
void MarkLinked(const std::vector<PrimId>& excludes, const std::map<PrimId, int>& primIndices, int count,
                std::vector<char>* flags) {
  flags->clear();
  for (const PrimId& id : excludes) {
    const auto found = primIndices.find(id);
    if (found == primIndices.end()) continue;
    flags->resize(std::size_t(count), 0);
    (*flags)[std::size_t(found->second)] = 1;
  }
}

/// Sets the render's shutter from the camera's parameters (read from its scene delegate, as its sync will) before the
/// index syncs, so prims build their motion over it. A new shutter marks every rprim, instancer and sprim's transform
/// and points dirty: their motion is built over the shutter.
void SyncShutter(RenderIndex& index, const PrimId& cameraId, RenderParam* renderParam) {
  const auto entry = index.Sprims().find(cameraId);
  if (entry == index.Sprims().end() || !dynamic_cast<const Camera*>(entry->second.prim.get())) return;
  const CameraParams params = entry->second.sceneDelegate->GetCameraParams(cameraId);
  const Shutter shutter{params.shutterOpen, params.shutterClose};
  if (!std::isfinite(shutter.open) || !std::isfinite(shutter.close) || shutter.close < shutter.open)
    return;  // sync says
  if (shutter == renderParam->GetShutter()) return;
  renderParam->SetShutter(shutter);
  index.GetChangeTracker().MarkAllDirty(dirty::DirtyTransform | dirty::DirtyPoints | dirty::DirtyInstancer);
}

}  // namespace

RenderStats RenderPass::Execute(const PrimId& cameraId, const std::vector<AovBinding>& bindings,
                                const ProgressiveControl& control) {
  SyncShutter(*index_, cameraId, index_->GetRenderDelegate()->GetRenderParam());
  index_->SyncAll();
  // The index was made with this delegate (HdEmbreeRenderPass reaches its render param the same way).
  auto* delegate = static_cast<RenderDelegate*>(index_->GetRenderDelegate());
  if (delegate->GetRenderParam()->SceneVersion() != committedVersion_) {
    rtcCommitScene(delegate->RootScene());
    committedVersion_ = delegate->GetRenderParam()->SceneVersion();
  }

  const auto* camera = dynamic_cast<const Camera*>(index_->GetSprim(cameraId));
  if (!camera) throw std::runtime_error("render pass: camera " + cameraId + " not found");

  // Resolve each rprim's material and primId for the renderer.
  int primIndex = 0;
  std::map<PrimId, int> primIndices;
  primIdsByIndex_.clear();
  bool cutouts = false, textured = false, eyes = false;
  for (const auto& [id, entry] : index_->Rprims()) {
    GeometryContext* context = entry.prim->Context();
    if (!context) continue;
    eyes = eyes || context->eye || context->meshEye;
    primIndices[id] = context->primIndex = primIndex++;
    primIdsByIndex_.push_back(id);
    const SurfaceMaterial bound = Resolve(*index_, entry.prim->MaterialId());
    context->surface = bound;
    context->subsetMaterials.clear();
    if (const auto* mesh = dynamic_cast<const Mesh*>(entry.prim.get()))
      for (const PrimId& subsetMaterial : mesh->SubsetMaterialIds())
        context->subsetMaterials.push_back(subsetMaterial.empty() ? bound : Resolve(*index_, subsetMaterial));
    cutouts = cutouts || bound.params.opacityThreshold > 0;
    textured = textured || bound.textures;
    for (const SurfaceMaterial& subset : context->subsetMaterials) {
      cutouts = cutouts || subset.params.opacityThreshold > 0;
      textured = textured || subset.textures;
    }
  }

  std::vector<RenderLight> lights;
  for (GatheredLight& gathered : GatherLights(*index_)) {
    MarkLinked(gathered.prim->Params().lightLinkExcludes, primIndices, primIndex, &gathered.light.unlit);
    MarkLinked(gathered.prim->Params().shadowLinkExcludes, primIndices, primIndex, &gathered.light.unshadowed);
    lights.push_back(std::move(gathered.light));
  }
  renderer_.SetCutouts(cutouts);
  renderer_.SetTextured(textured);
  renderer_.SetEyes(eyes);
  renderer_.SetSceneVersion(committedVersion_);
  return renderer_.Render(delegate->RootScene(), camera->View(), lights, delegate->Settings(),
                          BindBuffers(*index_, bindings), control);
}

RenderPlan RenderPass::Plan(const PrimId& cameraId, int width, int height, const PlanOverrides& overrides,
                            const PlanRules& rules) {
  // Meshes synced now for the first time wait at level 0 for the plan's level (plan/meshRefinePlan.h).
  index_->GetRenderDelegate()->GetRenderParam()->SetMeshLevelsAwaitPlan(true);
  SyncShutter(*index_, cameraId, index_->GetRenderDelegate()->GetRenderParam());
  index_->SyncAll();
  return MakeRenderPlan(*index_, cameraId, width, height, overrides, rules);
}

}  // namespace hdeye
