#include "hdeye/prims/curveSegments.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hdeye {

namespace {

using Topology = BasisCurvesTopology;

[[noreturn]] void Fail(const std::string& what) { throw std::runtime_error(what); }

bool Periodic(const Topology& t) { return t.wrap == Topology::Wrap::Periodic; }
bool Pinned(const Topology& t) {
  return t.wrap == Topology::Wrap::Pinned && t.type == Topology::Type::Cubic && t.basis != Topology::Basis::Bezier;
}

/// Segments of one curve of n vertices (n already checked against MinimumCurveVertices).
int SegmentCount(const Topology& t, int n) {
  if (t.type == Topology::Type::Linear) return Periodic(t) ? n : n - 1;
  if (t.basis == Topology::Basis::Bezier) return Periodic(t) ? n / 3 : (n - 1) / 3;
  if (Periodic(t)) return n;
  return Pinned(t) ? n - 1 : n - 3;
}

std::size_t ElementCount(const Topology& t, Interpolation interpolation) {
  std::size_t total = 0;
  for (int n : t.curveVertexCounts) {
    if (interpolation == Interpolation::Vertex) total += std::size_t(n);
    if (interpolation == Interpolation::Varying) total += std::size_t(VaryingCount(t, n));
  }
  if (interpolation == Interpolation::Constant) return 1;
  if (interpolation == Interpolation::Uniform) return t.curveVertexCounts.size();
  return total;
}

}  // namespace

int MinimumCurveVertices(const BasisCurvesTopology& t) {
  if (t.type == Topology::Type::Linear) return 2;
  if (Periodic(t)) return 3;
  return Pinned(t) ? 2 : 4;
}

int VaryingCount(const BasisCurvesTopology& t, int n) {
  if (t.type == Topology::Type::Linear) return n;
  return SegmentCount(t, n) + (Periodic(t) ? 0 : 1);
}

std::vector<float> CurvePrimvarAtVertices(const BasisCurvesTopology& t, const Primvar& primvar, int components,
                                          const char* what) {
  if (primvar.components != components)
    Fail(std::string(what) + " has " + std::to_string(primvar.components) + " components, need " +
         std::to_string(components));
  if (primvar.interpolation == Interpolation::FaceVarying)
    Fail(std::string(what) + ": faceVarying is not a curve interpolation");
  const std::size_t expected = ElementCount(t, primvar.interpolation);
  if (primvar.values.size() != expected * std::size_t(components))
    Fail(std::string(what) + " needs " + std::to_string(expected) + " values for its interpolation, got " +
         std::to_string(primvar.values.size() / std::size_t(components)));
  for (float v : primvar.values)
    if (!std::isfinite(v)) Fail(std::string(what) + " holds a value that is not finite");

  std::vector<float> out;
  std::size_t varyingBase = 0, vertexBase = 0;
  for (std::size_t c = 0; c < t.curveVertexCounts.size(); ++c) {
    const int n = t.curveVertexCounts[c];
    const int m = primvar.interpolation == Interpolation::Varying ? VaryingCount(t, n) : 0;
    for (int j = 0; j < n; ++j) {
      const float* value = nullptr;
      float blended[4];
      switch (primvar.interpolation) {
        case Interpolation::Constant: value = primvar.values.data(); break;
        case Interpolation::Uniform: value = &primvar.values[c * components]; break;
        case Interpolation::Vertex: value = &primvar.values[(vertexBase + j) * components]; break;
        default: {
          // Varying values sit at segment ends; spread them evenly over the control vertices.
          const double span = Periodic(t) ? double(m) : double(m - 1);
          const double at = n > 1 ? j * span / (Periodic(t) ? n : n - 1) : 0.0;
          const int i0 = std::min(int(at), m - 1), i1 = Periodic(t) ? (i0 + 1) % m : std::min(i0 + 1, m - 1);
          const float w = float(at - i0);
          for (int k = 0; k < components; ++k)
            blended[k] = (1 - w) * primvar.values[(varyingBase + i0) * components + k] +
                         w * primvar.values[(varyingBase + i1) * components + k];
          value = blended;
        }
      }
      out.insert(out.end(), value, value + components);
    }
    vertexBase += std::size_t(n);
    varyingBase += std::size_t(m);
  }
  return out;
}

CurveSegments BuildCurveSegments(const BasisCurvesTopology& t, const std::vector<Vec3f>& points, const Primvar& widths,
                                 const Primvar& normals) {
  long long total = 0;
  for (std::size_t c = 0; c < t.curveVertexCounts.size(); ++c) {
    const int n = t.curveVertexCounts[c];
    if (n < MinimumCurveVertices(t))
      Fail("curve " + std::to_string(c) + " has " + std::to_string(n) + " vertices, need at least " +
           std::to_string(MinimumCurveVertices(t)));
    if (t.type == Topology::Type::Cubic && t.basis == Topology::Basis::Bezier && (Periodic(t) ? n % 3 : (n - 1) % 3))
      Fail("bezier curve " + std::to_string(c) + " has " + std::to_string(n) + " vertices, need " +
           (Periodic(t) ? "3 k" : "3 k + 1"));
    total += n;
  }
  if (t.curveVertexCounts.empty()) Fail("no curves");
  if (total != static_cast<long long>(points.size()))
    Fail("curveVertexCounts add up to " + std::to_string(total) + " but there are " + std::to_string(points.size()) +
         " points");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z))
      Fail("point " + std::to_string(i) + " is not finite");

  const std::vector<float> width =
      widths.Empty() ? std::vector<float>(points.size(), 1.0f) : CurvePrimvarAtVertices(t, widths, 1, "widths");
  for (float w : width)
    if (w < 0) Fail("widths holds a negative width");
  const std::vector<float> normal =
      normals.Empty() ? std::vector<float>{} : CurvePrimvarAtVertices(t, normals, 3, "normals");

  CurveSegments out;
  std::size_t base = 0;
  for (std::size_t c = 0; c < t.curveVertexCounts.size(); ++c) {
    const int n = t.curveVertexCounts[c];
    const unsigned first = unsigned(out.vertices.size());
    auto at = [&](int j) { return glm::vec3(points[base + std::size_t(j)]); };
    auto push = [&](const glm::vec3& p, int j) {  // a vertex at p standing for the curve's point j
      out.vertices.push_back(glm::vec4(p, 0.5f * width[base + std::size_t(j)]));
      out.vertexPoints.push_back(unsigned(base + std::size_t(j)));
      if (!normal.empty())
        out.normals.push_back(Vec3f(normal[3 * (base + j)], normal[3 * (base + j) + 1], normal[3 * (base + j) + 2]));
    };
    // Pinned: a phantom point mirrored through each end makes the uniform segment start (and end) there.
    if (Pinned(t)) push(2.0f * at(0) - at(1), 0);
    for (int j = 0; j < n; ++j) push(at(j), j);
    if (Pinned(t)) push(2.0f * at(n - 1) - at(n - 2), n - 1);
    if (Periodic(t)) {
      const int copies = t.type == Topology::Type::Linear || t.basis == Topology::Basis::Bezier ? 1 : 3;
      for (int j = 0; j < copies; ++j) push(at(j), j);
    }
    const int step = t.type == Topology::Type::Cubic && t.basis == Topology::Basis::Bezier ? 3 : 1;
    for (int s = 0; s < SegmentCount(t, n); ++s) {
      out.segments.push_back(first + unsigned(s * step));
      out.segmentCurves.push_back(int(c));
    }
    base += std::size_t(n);
  }
  return out;
}

std::vector<Vec3f> SegmentEndColors(const BasisCurvesTopology& t, const CurveSegments& s,
                                    const std::vector<float>& pointColors) {
  // The points a segment runs between: a linear one's two, a bezier one's end control points, and for bspline and
  // catmullRom the middle two of its four (the curve passes through or near them).
  const bool cubic = t.type == Topology::Type::Cubic;
  const unsigned from = cubic && t.basis != Topology::Basis::Bezier ? 1 : 0;
  const unsigned to = !cubic ? 1 : t.basis == Topology::Basis::Bezier ? 3 : 2;
  auto color = [&](unsigned vertex) {
    const std::size_t p = 3 * std::size_t(s.vertexPoints[vertex]);
    return Vec3f(pointColors[p], pointColors[p + 1], pointColors[p + 2]);
  };
  std::vector<Vec3f> out;
  out.reserve(3 * s.segments.size());
  for (unsigned first : s.segments) {
    const Vec3f start = color(first + from), end = color(first + to);
    out.insert(out.end(), {start, end, start});
  }
  return out;
}

}  // namespace hdeye
