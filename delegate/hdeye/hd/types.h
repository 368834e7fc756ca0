#pragma once
// Value types of the scene side: prim ids and mesh topology (the math aliases and the per-prim parameters
// the renderer also reads are in params/primParams.h).
#include "hdeye/params/primParams.h"

#include <string>
#include <vector>

namespace hdeye {

/// A prim's path in the scene (SdfPath's role), e.g. "/World/Eye_L".
using PrimId = std::string;

/// The subdivision scheme of a mesh rendered at refineLevel > 0 (UsdGeom subdivisionScheme; "none" is
/// refineLevel 0). Loop needs every face to be a triangle.
enum class SubdivScheme { CatmullClark, Loop, Bilinear };

/// UsdGeomMesh's subdivision tags (PxOsdSubdivTags' role), with USD's token values as enumerators. Sharpness is
/// OpenSubdiv's unitless crease sharpness: 0 smooth, 10 (and above) infinitely sharp.
struct SubdivTags {
  /// interpolateBoundary: none (boundary faces are not rendered), edgeOnly, edgeAndCorner (UsdGeom's default).
  enum class Boundary { None, EdgeOnly, EdgeAndCorner } interpolateBoundary = Boundary::EdgeAndCorner;
  /// faceVaryingLinearInterpolation (UsdGeom's default cornersPlus1).
  enum class FaceVaryingLinear {
    None,
    CornersOnly,
    CornersPlus1,
    CornersPlus2,
    Boundaries,
    All
  } faceVaryingLinearInterpolation = FaceVaryingLinear::CornersPlus1;
  /// triangleSubdivisionRule: catmullClark (UsdGeom's default) or smooth (Catmull-Clark only).
  enum class TriangleRule { CatmullClark, Smooth } triangleSubdivisionRule = TriangleRule::CatmullClark;
  /// creaseIndices holds the creases' vertex chains back to back, creaseLengths[i] (>= 2) vertices each;
  /// creaseSharpnesses holds one value per crease or one per crease edge (sum of creaseLengths[i] - 1).
  std::vector<int> creaseIndices, creaseLengths;
  std::vector<float> creaseSharpnesses;
  /// cornerIndices: points made sharp, cornerSharpnesses[i] each (same length).
  std::vector<int> cornerIndices;
  std::vector<float> cornerSharpnesses;

  bool Empty() const { return creaseIndices.empty() && cornerIndices.empty(); }
};

/// Faces of a mesh bound to a material of their own (a UsdGeomSubset of the materialBind family; Hydra's
/// HdGeomSubset). Faces in several subsets take the first; faces in none the mesh's material.
struct GeomSubset {
  PrimId materialId;             ///< empty: the mesh's own material
  std::vector<int> faceIndices;  ///< authored faces, each in [0, faceVertexCounts.size())
};

/// Mesh connectivity (HdMeshTopology's role), in UsdGeomMesh's layout.
struct MeshTopology {
  std::vector<int> faceVertexCounts;   ///< vertices per face: 3, 4 or n (>= 3)
  std::vector<int> faceVertexIndices;  ///< sum(faceVertexCounts) indices into the points
  /// Subdivision refinement level; 0 renders the control mesh as polygons.
  int refineLevel = 0;
  SubdivScheme scheme = SubdivScheme::CatmullClark;  ///< used when refineLevel > 0
  SubdivTags subdivTags;                             ///< used when refineLevel > 0
  /// Faces not rendered (UsdGeom holeIndices), at any level; each in [0, faceVertexCounts.size()).
  std::vector<int> holeIndices;
  /// Per-face materials; empty: the whole mesh renders with its bound material.
  std::vector<GeomSubset> geomSubsets;
  /// UsdGeom orientation "leftHanded": faces wind clockwise seen from outside, so the computed
  /// (smooth or limit) normals are flipped to stay outward. Authored normals are used as given.
  bool leftHanded = false;
};

/// BasisCurves connectivity and evaluation (HdBasisCurvesTopology's role), with UsdGeomBasisCurves' tokens.
struct BasisCurvesTopology {
  enum class Type { Linear, Cubic } type = Type::Cubic;
  enum class Basis { Bezier, Bspline, CatmullRom } basis = Basis::Bezier;  ///< cubic only
  /// nonperiodic: open; periodic: closed (the last vertices join the first); pinned: open, passing through its
  /// end points (bspline and catmullRom; the same as nonperiodic for bezier and linear).
  enum class Wrap { Nonperiodic, Periodic, Pinned } wrap = Wrap::Nonperiodic;
  std::vector<int> curveVertexCounts;  ///< vertices per curve; they add up to the point count
};

}  // namespace hdeye
