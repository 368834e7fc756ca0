#include "hdeye/prims/basisCurves.h"

#include "hdeye/prims/curveSegments.h"

#include <stdexcept>

namespace hdeye {

namespace {

RTCGeometryType EmbreeType(const BasisCurvesTopology& t, bool ribbon) {
  using T = BasisCurvesTopology;
  if (t.type == T::Type::Linear)
    return ribbon ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BEZIER_CURVE : RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE;
  switch (t.basis) {
    case T::Basis::Bspline:
      return ribbon ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BSPLINE_CURVE : RTC_GEOMETRY_TYPE_ROUND_BSPLINE_CURVE;
    case T::Basis::CatmullRom:
      return ribbon ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_CATMULL_ROM_CURVE : RTC_GEOMETRY_TYPE_ROUND_CATMULL_ROM_CURVE;
    case T::Basis::Bezier: break;
  }
  return ribbon ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BEZIER_CURVE : RTC_GEOMETRY_TYPE_ROUND_BEZIER_CURVE;
}

/// Linear segments as cubic bezier ones (control points at the thirds), for ribbons: Embree has no
/// normal-oriented linear curve.
void LinearToBezier(CurveSegments* s) {
  CurveSegments out;
  for (std::size_t k = 0; k < s->segments.size(); ++k) {
    const unsigned a = s->segments[k], b = a + 1;
    out.segments.push_back(unsigned(out.vertices.size()));
    out.segmentCurves.push_back(s->segmentCurves[k]);
    for (int i = 0; i < 4; ++i) {
      const float w = float(i) / 3.0f;
      out.vertices.push_back((1 - w) * s->vertices[a] + w * s->vertices[b]);
      out.normals.push_back(glm::normalize((1 - w) * s->normals[a] + w * s->normals[b] + Vec3f(1e-30f)));
    }
  }
  *s = std::move(out);
}

}  // namespace

void BasisCurves::SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) {
  const BasisCurvesTopology topology = sceneDelegate->GetBasisCurvesTopology(Id());
  CurveSegments s;
  try {
    s = BuildCurveSegments(topology, sceneDelegate->GetPoints(Id()), sceneDelegate->GetPrimvar(Id(), "widths"),
                           sceneDelegate->GetPrimvar(Id(), "normals"));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("curves " + Id() + ": " + e.what());
  }
  displayColor_.clear();
  if (const Primvar color = sceneDelegate->GetPrimvar(Id(), "displayColor"); !color.Empty()) {
    try {  // Segment colours are read before LinearToBezier, which keeps the segments but not vertexPoints.
      displayColor_ = SegmentEndColors(topology, s, CurvePrimvarAtVertices(topology, color, 3, "displayColor"));
    } catch (const std::runtime_error& e) {
      renderParam->Warn("curves " + Id() + ": " + e.what() + " (ignored)");
    }
  }
  ContextData().displayColor = displayColor_.empty() ? nullptr : &displayColor_;
  const bool ribbon = !s.normals.empty();
  if (ribbon && topology.type == BasisCurvesTopology::Type::Linear) LinearToBezier(&s);
  const RTCGeometry g = rtcNewGeometry(renderParam->Device(), EmbreeType(topology, ribbon));
  auto* vertices = static_cast<glm::vec4*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, sizeof(glm::vec4), s.vertices.size()));
  std::copy(s.vertices.begin(), s.vertices.end(), vertices);
  auto* index = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), s.segments.size()));
  std::copy(s.segments.begin(), s.segments.end(), index);
  if (ribbon) {
    auto* normals = static_cast<Vec3f*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3f), s.normals.size()));
    std::copy(s.normals.begin(), s.normals.end(), normals);
  }
  segmentCount_ = int(s.segments.size());
  Geometry().Reset(renderParam, g, &ContextData());
}

}  // namespace hdeye
