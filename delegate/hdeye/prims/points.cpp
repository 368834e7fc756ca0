#include "hdeye/prims/points.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hdeye {

namespace {

/// Whether a points primvar holds one value per point (any interpolation but constant), and how many it needs.
bool PerPoint(const Primvar& p) { return p.interpolation != Interpolation::Constant; }
std::size_t NeededValues(const Primvar& p, std::size_t points) { return PerPoint(p) ? points : 1; }

}  // namespace

void Points::SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) {
  auto fail = [&](const std::string& what) { throw std::runtime_error("points " + Id() + ": " + what); };
  const std::vector<Vec3f> points = sceneDelegate->GetPoints(Id());
  const Primvar widths = sceneDelegate->GetPrimvar(Id(), "widths");
  if (points.empty()) fail("no points");
  const bool perPoint = !widths.Empty() && PerPoint(widths);
  if (!widths.Empty() && (widths.components != 1 || widths.values.size() != NeededValues(widths, points.size())))
    fail("widths needs " + std::to_string(NeededValues(widths, points.size())) + " values, got " +
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
  if (!color.Empty() && (color.components != 3 || color.values.size() != 3 * NeededValues(color, points.size()))) {
    renderParam->Warn("points " + Id() + ": displayColor needs " + std::to_string(NeededValues(color, points.size())) +
                      " colours (ignored)");
  } else if (!color.Empty()) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const float* c = &color.values[3 * (PerPoint(color) ? i : 0)];
      displayColor_.insert(displayColor_.end(), 3, Vec3f(c[0], c[1], c[2]));
    }
  }
  ContextData().displayColor = displayColor_.empty() ? nullptr : &displayColor_;
  Geometry().Reset(renderParam, g, &ContextData());
}

}  // namespace hdeye
