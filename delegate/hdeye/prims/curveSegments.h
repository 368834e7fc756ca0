#pragma once
// BasisCurves to what Embree intersects: per curve, its control vertices (x, y, z, radius) with the copies a
// periodic curve needs and the phantom end points a pinned one needs, the first vertex of every segment, and
// per-vertex normals for ribbons. Embree's curve types take four consecutive vertices per cubic segment (two
// per linear one) from one index each, so wraps and pins become extra vertices, never extra index logic.
//
// Units: positions and radii in the curves' object space (scene units); widths are diameters, as in UsdGeom.
#include "hdeye/hd/sceneDelegate.h"

#include <vector>

namespace hdeye {

/// The curves' geometry in Embree's layout.
struct CurveSegments {
  std::vector<glm::vec4> vertices;  ///< x, y, z, radius (width / 2), object space
  std::vector<Vec3f> normals;       ///< per vertex (ribbons), or empty
  std::vector<unsigned> segments;   ///< per segment: the index of its first vertex
  std::vector<int> segmentCurves;   ///< per segment: the curve it belongs to
  /// per vertex: the index of the curve point it stands for (a pinned curve's phantom end: that end's point)
  std::vector<unsigned> vertexPoints;
};

/// Vertices a curve of this topology needs at least (2 linear, 4 cubic; 3 for periodic cubic curves).
int MinimumCurveVertices(const BasisCurvesTopology& topology);

/// The number of "varying" values a curve of `n` vertices takes (UsdGeomBasisCurves::ComputeVaryingDataSize's
/// per-curve rule: its segment count, plus one when not periodic).
int VaryingCount(const BasisCurvesTopology& topology, int n);

/// Builds the Embree layout of `topology` over `points`. `widths` (1 component) and `normals` (3 components,
/// empty for round tubes) are constant, uniform (per curve), vertex or varying primvars; an empty widths
/// primvar means width 1. Throws std::runtime_error with a one-line message for: counts that do not add up to
/// the points, a curve with too few vertices (or a bezier curve whose count is not 3 k + 1, 3 k periodic), a
/// primvar whose size does not match its interpolation, a non-finite value or a negative width.
CurveSegments BuildCurveSegments(const BasisCurvesTopology& topology, const std::vector<Vec3f>& points,
                                 const Primvar& widths, const Primvar& normals);

/// Per segment of `segments`, three colours (start, end, start) taken from `pointColors` (3 floats per curve point,
/// as CurvePrimvarAtVertices gives) at the points the segment runs between: GeometryContext::displayColor's layout,
/// whose barycentric lookup at a curve hit (u along the segment) is then (1 - u) start + u end.
std::vector<Vec3f> SegmentEndColors(const BasisCurvesTopology& topology, const CurveSegments& segments,
                                    const std::vector<float>& pointColors);

/// Expands a constant, uniform, vertex or varying primvar of `components` floats to one value per point of the
/// curves (varying values interpolated linearly along each curve's vertices); `what` names it in errors.
std::vector<float> CurvePrimvarAtVertices(const BasisCurvesTopology& topology, const Primvar& primvar, int components,
                                          const char* what);

}  // namespace hdeye
