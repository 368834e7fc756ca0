#pragma once
// Value types shared by the delegate. World units are whatever the scene uses (USD: usually cm or m);
// eyes carry their own transform into eyelib's canonical millimetre frame.
#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace hdeye {

/// A prim's path in the scene (SdfPath's role), e.g. "/World/Eye_L".
using PrimId = std::string;

using Matrix4d = glm::dmat4;  ///< column vectors: world = M * local
using Vec3f = glm::vec3;
using Vec2f = glm::vec2;

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
