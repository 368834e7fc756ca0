#pragma once
// Mesh primvars (UsdGeom interpolation: constant, uniform, vertex, varying, faceVarying) checked against
// a mesh's topology and expanded to what the renderer reads: one value per corner of every rendered
// triangle, so a hit interpolates any primvar the same way (the barycentric weights of its corners).
// Subdivided meshes refine vertex and varying primvars through the vertex stencils and face-varying
// ones through an OpenSubdiv face-varying channel; uniform primvars follow each refined face's parent.
#include "hdeye/hd/sceneDelegate.h"

#include <string>
#include <vector>

namespace hdeye {

class SubdivRefiner;

/// How the rendered triangles relate to the authored mesh. Polygon meshes are fan-triangulated
/// authored faces; subdivided meshes, fan-triangulated refined quads.
struct TriangleLayout {
  std::vector<int> vertices;  ///< 3 per triangle: rendered points (refined points for subdivided meshes)
  std::vector<int> corners;   ///< 3 per triangle: rendered face corners (authored, or refined quad 4 f + k)
  std::vector<int> faces;     ///< 1 per triangle: the authored face it lies in
};

/// Fan-triangulates faces (counts >= 3 over `indices`); `parents` maps each face to its authored face
/// (empty: faces are the authored ones).
TriangleLayout TriangulateFaces(const std::vector<int>& counts, const std::vector<int>& indices,
                                const std::vector<int>& parents);

/// Throws std::runtime_error "primvar NAME: ..." (one line; the mesh adds its id) unless `primvar` holds
/// `components` floats per element, as many elements as its interpolation needs on this topology over
/// `pointCount` points, all finite.
void ValidatePrimvar(const Primvar& primvar, const std::string& name, int components, const MeshTopology& topology,
                     int pointCount);

/// A validated primvar's values at every rendered triangle corner (`components` floats each, corner
/// order). `refiner` is null for polygon meshes.
std::vector<float> PrimvarAtCorners(const Primvar& primvar, const TriangleLayout& layout, const SubdivRefiner* refiner);

}  // namespace hdeye
