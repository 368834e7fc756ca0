#pragma once
// Whether a mesh is an open surface: some edge belongs to one face only. Points are welded by exact position
// first, so the duplicated seam points DCC exports write for UV seams do not make a closed mesh look open.
#include "hdeye/params/primParams.h"

#include <vector>

namespace hdeye {

/// faceVertexCounts / faceVertexIndices over `points` (control points, object space): true when an edge of the
/// welded mesh is used by exactly one face. Indices must already be checked against points.size().
bool HasBoundaryEdges(const std::vector<int>& faceVertexCounts, const std::vector<int>& faceVertexIndices,
                      const std::vector<Vec3f>& points);

}  // namespace hdeye
