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
  SetTransform(renderParam, transform_, context);
  SetVisible(renderParam, visible_);
}

void InstancedGeometry::SetTransform(RenderParam* renderParam, const Matrix4d& transform, GeometryContext* context) {
  transform_ = transform;
  context->normalToWorld = glm::transpose(glm::inverse(glm::dmat3(transform)));
  instanceContext_.normalToWorld = context->normalToWorld;
  if (!instance_) return;
  const glm::mat4 m(transform);
  renderParam->AcquireSceneForEdit();
  rtcSetGeometryTransform(instance_, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &m[0][0]);
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
  if (bits & (dirty::InitRepr | dirty::DirtyTransform))
    geometry_.SetTransform(renderParam, sceneDelegate->GetTransform(Id()), &context_);
  if (bits & (dirty::InitRepr | dirty::DirtyVisibility))
    geometry_.SetVisible(renderParam, sceneDelegate->GetVisible(Id()));
  if (bits & (dirty::InitRepr | dirty::DirtyMaterialId)) materialId_ = sceneDelegate->GetMaterialId(Id());
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
