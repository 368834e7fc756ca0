#include "hdeye/prims/renderDelegate.h"

#include "hdeye/prims/analyticEye.h"
#include "hdeye/prims/basisCurves.h"
#include "hdeye/prims/camera.h"
#include "hdeye/prims/eyeMesh.h"
#include "hdeye/prims/light.h"
#include "hdeye/prims/material.h"
#include "hdeye/prims/mesh.h"
#include "hdeye/prims/points.h"
#include "hdeye/prims/renderBuffer.h"

#include <cstdio>
#include <stdexcept>

namespace hdeye {

namespace {
void ReportEmbreeError(void*, RTCError code, const char* message) {
  std::fprintf(stderr, "hdeye: Embree error %d: %s\n", int(code), message ? message : "");
}
}  // namespace

RenderDelegate::RenderDelegate() {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("hdeye: could not create an Embree device");
  rtcSetDeviceErrorFunction(device_, ReportEmbreeError, nullptr);
  scene_ = rtcNewScene(device_);
  // Dynamic: meshes move per frame; robust: watertight traversal for grazing eye rays.
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_LOW);
  renderParam_ = std::make_unique<RenderParam>(device_, scene_);
}

RenderDelegate::~RenderDelegate() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

const std::vector<std::string>& RenderDelegate::SupportedRprimTypes() {
  static const std::vector<std::string> types = {primTypes::kMesh, primTypes::kAnalyticEye, primTypes::kEyeMesh,
                                                 primTypes::kBasisCurves, primTypes::kPoints};
  return types;
}
const std::vector<std::string>& RenderDelegate::SupportedSprimTypes() {
  static const std::vector<std::string> types = {
      primTypes::kCamera,    primTypes::kSphereLight, primTypes::kDistantLight,  primTypes::kRectLight,
      primTypes::kDiskLight, primTypes::kDomeLight,   primTypes::kCylinderLight, primTypes::kMaterial};
  return types;
}
const std::vector<std::string>& RenderDelegate::SupportedBprimTypes() {
  static const std::vector<std::string> types = {primTypes::kRenderBuffer};
  return types;
}

std::unique_ptr<Rprim> RenderDelegate::CreateRprim(const std::string& type, const PrimId& id) {
  if (type == primTypes::kMesh) return std::make_unique<Mesh>(id);
  if (type == primTypes::kAnalyticEye) return std::make_unique<AnalyticEye>(id);
  if (type == primTypes::kEyeMesh) return std::make_unique<EyeMesh>(id);
  if (type == primTypes::kBasisCurves) return std::make_unique<BasisCurves>(id);
  if (type == primTypes::kPoints) return std::make_unique<Points>(id);
  return nullptr;
}

std::unique_ptr<Sprim> RenderDelegate::CreateSprim(const std::string& type, const PrimId& id) {
  if (type == primTypes::kCamera) return std::make_unique<Camera>(id);
  if (type == primTypes::kMaterial) return std::make_unique<Material>(id);
  if (type == primTypes::kSphereLight) return std::make_unique<Light>(id, LightType::Sphere);
  if (type == primTypes::kDistantLight) return std::make_unique<Light>(id, LightType::Distant);
  if (type == primTypes::kRectLight) return std::make_unique<Light>(id, LightType::Rect);
  if (type == primTypes::kDiskLight) return std::make_unique<Light>(id, LightType::Disk);
  if (type == primTypes::kDomeLight) return std::make_unique<Light>(id, LightType::Dome);
  if (type == primTypes::kCylinderLight) return std::make_unique<Light>(id, LightType::Cylinder);
  return nullptr;
}

std::unique_ptr<Bprim> RenderDelegate::CreateBprim(const std::string& type, const PrimId& id) {
  if (type == primTypes::kRenderBuffer) return std::make_unique<RenderBuffer>(id);
  return nullptr;
}

}  // namespace hdeye
