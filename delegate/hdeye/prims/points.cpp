#include "hdeye/prims/points.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hdeye {

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
  // displayColor, constant or per point, as 3 equal corner values per point (GeometryContext::displayColor).
  displayColor_.clear();
  const Primvar color = sceneDelegate->GetPrimvar(Id(), "displayColor");
  const bool colorPerPoint = color.interpolation != Interpolation::Constant;
  if (!color.Empty() && (color.components != 3 || color.values.size() != 3 * (colorPerPoint ? points.size() : 1))) {
    renderParam->Warn("points " + Id() + ": displayColor needs " + std::to_string(colorPerPoint ? points.size() : 1) +
                      " colours (ignored)");
  } else if (!color.Empty()) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const float* c = &color.values[3 * (colorPerPoint ? i : 0)];
      displayColor_.insert(displayColor_.end(), 3, Vec3f(c[0], c[1], c[2]));
    }
  }
  ContextData().displayColor = displayColor_.empty() ? nullptr : &displayColor_;
  Geometry().Reset(renderParam, g, &ContextData());
}

}  // namespace hdeye
