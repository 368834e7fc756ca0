#include "hdeye/prims/points.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hdeye {

DirtyBits Points::GetInitialDirtyBitsMask() const {
  return dirty::InitRepr | dirty::DirtyPoints | dirty::DirtyTransform | dirty::DirtyPrimvar | dirty::DirtyVisibility |
         dirty::DirtyMaterialId;
}

void Points::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  if (bits & (dirty::InitRepr | dirty::DirtyPoints | dirty::DirtyPrimvar)) SyncGeometry(sceneDelegate, renderParam);
  if (bits & (dirty::InitRepr | dirty::DirtyTransform))
    geometry_.SetTransform(renderParam, sceneDelegate->GetTransform(Id()), &context_);
  if (bits & (dirty::InitRepr | dirty::DirtyVisibility)) geometry_.SetVisible(renderParam, sceneDelegate->GetVisible(Id()));
  if (bits & (dirty::InitRepr | dirty::DirtyMaterialId)) materialId_ = sceneDelegate->GetMaterialId(Id());
  *dirtyBits = dirty::Clean;
}

void Points::SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) {
  auto fail = [&](const std::string& what) { throw std::runtime_error("points " + Id() + ": " + what); };
  const std::vector<Vec3f> points = sceneDelegate->GetPoints(Id());
  const Primvar widths = sceneDelegate->GetPrimvar(Id(), "widths");
  if (points.empty()) fail("no points");
  const bool perPoint = !widths.Empty() && widths.interpolation != Interpolation::Constant;
  if (!widths.Empty() && (widths.components != 1 || widths.values.size() != (perPoint ? points.size() : 1)))
    fail("widths needs " + std::to_string(perPoint ? points.size() : 1) + " values, got " +
         std::to_string(widths.values.size()));
  const RTCGeometry g = rtcNewGeometry(renderParam->Device(), RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* vertices = static_cast<glm::vec4*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, sizeof(glm::vec4), points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float width = widths.Empty() ? 1.0f : widths.values[perPoint ? i : 0];
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z) ||
        !std::isfinite(width) || width < 0) {
      rtcReleaseGeometry(g);
      fail("point " + std::to_string(i) + " or its width is not finite, or the width is negative");
    }
    vertices[i] = glm::vec4(points[i], 0.5f * width);
  }
  geometry_.Reset(renderParam, g, &context_);
}

}  // namespace hdeye
