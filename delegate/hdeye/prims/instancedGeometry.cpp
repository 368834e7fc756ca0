#include "hdeye/prims/instancedGeometry.h"

#include "hdeye/hd/sceneDelegate.h"

namespace hdeye {

void InstancedGeometry::Reset(RenderParam* renderParam, RTCGeometry geometry, GeometryContext* context) {
  Release(renderParam);
  const RTCDevice device = renderParam->Device();
  geometry_ = geometry;
  rtcCommitGeometry(geometry_);
  prototype_ = rtcNewScene(device);
  rtcAttachGeometry(prototype_, geometry_);
  rtcCommitScene(prototype_);
  context->prototypeScene = prototype_;
  instance_ = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(instance_, prototype_);
  instanceContext_.geometry = context;
  rtcSetGeometryUserData(instance_, &instanceContext_);
  instanceId_ = rtcAttachGeometry(renderParam->AcquireSceneForEdit(), instance_);
  SetTransform(renderParam, transform_, context, motion_);
  SetVisible(renderParam, visible_);
}

void InstancedGeometry::SetTransform(RenderParam* renderParam, const Matrix4d& transform, GeometryContext* context,
                                     std::shared_ptr<const TransformMotion> motion) {
  transform_ = transform;
  motion_ = std::move(motion);
  context->normalToWorld = glm::transpose(glm::inverse(glm::dmat3(transform)));
  instanceContext_.normalToWorld = context->normalToWorld;
  instanceContext_.motion = motion_;
  if (!instance_) return;
  renderParam->AcquireSceneForEdit();
  SetInstanceMotion(instance_, transform, motion_.get());
  rtcCommitGeometry(instance_);
}

void InstancedGeometry::SetVisible(RenderParam* renderParam, bool visible) {
  visible_ = visible;
  if (!instance_) return;
  renderParam->AcquireSceneForEdit();
  if (visible)
    rtcEnableGeometry(instance_);
  else
    rtcDisableGeometry(instance_);
  rtcCommitGeometry(instance_);
}

void InstancedGeometry::Release(RenderParam* renderParam) {
  if (instance_) {
    rtcDetachGeometry(renderParam->AcquireSceneForEdit(), instanceId_);
    rtcReleaseGeometry(instance_);
  }
  if (geometry_) rtcReleaseGeometry(geometry_);
  if (prototype_) rtcReleaseScene(prototype_);
  instance_ = geometry_ = nullptr;
  prototype_ = nullptr;
  instanceId_ = RTC_INVALID_GEOMETRY_ID;
}

DirtyBits InstancedRprim::GetInitialDirtyBitsMask() const {
  return dirty::InitRepr | GeometryBits() | dirty::DirtyTransform | dirty::DirtyVisibility | dirty::DirtyMaterialId;
}

void InstancedRprim::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  if (bits & (dirty::InitRepr | GeometryBits())) SyncGeometry(sceneDelegate, renderParam);
  if (bits & (dirty::InitRepr | dirty::DirtyTransform)) {
    const PrimMotion synced = SyncTransformMotion(sceneDelegate, renderParam, Id(), "prim " + Id());
    const TransformMotion* m = synced.motion.get();
    geometry_.SetTransform(
        renderParam, synced.transform, &context_,
        m ? SteppedMotion(m->times, renderParam->GetShutter(), [m](double t) { return m->At(t); }) : nullptr);
  }
  if (bits & (dirty::InitRepr | dirty::DirtyVisibility))
    geometry_.SetVisible(renderParam, sceneDelegate->GetVisible(Id()));
  if (bits & (dirty::InitRepr | dirty::DirtyMaterialId)) materialId_ = sceneDelegate->GetMaterialId(Id());
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
