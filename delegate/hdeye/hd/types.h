#pragma once
// Value types of the scene side: prim ids and mesh topology (the math aliases and the per-prim parameters
// the renderer also reads are in render/params.h).
#include "hdeye/render/params.h"

#include <string>
#include <vector>

namespace hdeye {

/// A prim's path in the scene (SdfPath's role), e.g. "/World/Eye_L".
using PrimId = std::string;

/// Mesh connectivity (HdMeshTopology's role), in UsdGeomMesh's layout.
/// XXX: creases, corners and holes are not carried yet; every edge is smooth.
struct MeshTopology {
  std::vector<int> faceVertexCounts;   ///< vertices per face: 3, 4 or n (>= 3)
  std::vector<int> faceVertexIndices;  ///< sum(faceVertexCounts) indices into the points
  /// Catmull-Clark refinement level; 0 renders the control mesh as polygons.
  int refineLevel = 0;
  /// UsdGeom orientation "leftHanded": faces wind clockwise seen from outside, so the computed
  /// (smooth or limit) normals are flipped to stay outward. Authored normals are used as given.
  bool leftHanded = false;
};

}  // namespace hdeye
