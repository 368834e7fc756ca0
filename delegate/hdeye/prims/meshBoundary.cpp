#include "hdeye/prims/meshBoundary.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace hdeye {

bool HasBoundaryEdges(const std::vector<int>& faceVertexCounts, const std::vector<int>& faceVertexIndices,
                      const std::vector<Vec3f>& points) {
  // Welded id per point: the first point at the same exact position.
  std::map<std::tuple<float, float, float>, int> firstAt;
  std::vector<int> weld(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    weld[i] = firstAt.emplace(std::make_tuple(points[i].x, points[i].y, points[i].z), int(i)).first->second;
  std::unordered_map<std::uint64_t, int> uses;
  std::size_t start = 0;
  for (const int n : faceVertexCounts) {
    for (int k = 0; k < n; ++k) {
      const int a = weld[faceVertexIndices[start + k]], b = weld[faceVertexIndices[start + (k + 1) % n]];
      if (a == b) continue;  // a collapsed edge bounds nothing
      ++uses[(std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b))];
    }
    start += std::size_t(n);
  }
  return std::any_of(uses.begin(), uses.end(), [](const auto& edge) { return edge.second == 1; });
}

}  // namespace hdeye
