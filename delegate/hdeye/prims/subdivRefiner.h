#pragma once
// hdeye::SubdivRefiner: uniform subdivision (Catmull-Clark, Loop or bilinear, with the mesh's creases, corners,
// holes and boundary rules) of a mesh's topology, done once, plus the
// precomputed stencils that map coarse points (and any vertex primvar) to refined points every frame.
//
// This is the OpenSubdiv side of HdRprim mesh sync: DirtyTopology builds a new SubdivRefiner,
// DirtyPoints / DirtyPrimvar only call Evaluate*(), which never re-refine.
//
// Units: none of its own. Refined points, limit positions and primvars come out in whatever units the
// coarse values went in (mm in the canonical eye frame, scene units in world space); normals are unit.
#include "hdeye/hd/types.h"

#include <opensubdiv/version.h>

#include <glm/vec3.hpp>

#include <memory>
#include <vector>

namespace OpenSubdiv {
namespace OPENSUBDIV_VERSION {
namespace Far {
class TopologyRefiner;
class StencilTable;
}  // namespace Far
}  // namespace OPENSUBDIV_VERSION
}  // namespace OpenSubdiv

namespace hdeye {

/// A mesh topology refined uniformly under its scheme and subdivision tags (MeshTopology::scheme, subdivTags,
/// holeIndices, through OpenSubdiv's TopologyDescriptor and Sdc::Options), owning the OpenSubdiv refiner and
/// stencil table it built. Move-only.
class SubdivRefiner {
 public:
  /// Deepest level accepted. OpenSubdiv stores levels in 4 bits (15), but faces grow as 4^level and
  /// counts are ints: a 1000-face mesh at level 10 already has 10^9 faces.
  static constexpr int kMaxLevel = 10;

  /// Refines `coarse` (over `coarsePointCount` points) uniformly to `level` in [1, kMaxLevel] and builds
  /// the stencil table of the refined points. Throws std::invalid_argument with a one-line message naming
  /// the problem for: no faces, a face with fewer than 3 vertices, counts that do not add up to the number
  /// of indices, an index negative or not below coarsePointCount, a level out of range, a hole outside the
  /// faces, a loop mesh with a face that is not a triangle, or malformed creases or corners (lengths that do
  /// not add up, indices out of range, a sharpness count that is neither per crease nor per edge, NaN).
  /// Crease edges that are not edges of the mesh are ignored.
  SubdivRefiner(const MeshTopology& coarse, int coarsePointCount, int level);
  ~SubdivRefiner();
  SubdivRefiner(SubdivRefiner&&) noexcept;
  SubdivRefiner& operator=(SubdivRefiner&&) noexcept;

  /// The refinement level given at construction.
  int Level() const { return _level; }
  /// Number of coarse points the topology indexes (what Evaluate*() expect as input).
  int CoarsePointCount() const { return _coarsePointCount; }
  /// Number of points of the refined mesh at Level().
  int RefinedPointCount() const { return _refinedPointCount; }

  /// Vertices per refined face: 4 (Catmull-Clark turns an n-gon into n quads, bilinear too), 3 for loop.
  int RefinedFaceSize() const { return _faceSize; }
  /// The rendered faces of the refined mesh: RefinedFaceSize() indices per face into the refined points, same
  /// winding as the coarse faces. Faces inside holes are left out.
  const std::vector<int>& RefinedFaceIndices() const { return _faceIndices; }
  /// For each rendered refined face, the index of the coarse face it lies in (uniform primvars, materials).
  const std::vector<int>& RefinedFaceParents() const { return _faceParents; }

  /// Refined points from coarse points through the stencil table (a weighted sum per refined point; no
  /// re-refinement). `coarse` must hold CoarsePointCount() points, else std::invalid_argument is thrown;
  /// `refined` is resized to RefinedPointCount().
  void EvaluatePoints(const std::vector<glm::vec3>& coarse, std::vector<glm::vec3>* refined) const;

  /// The same for any vertex-interpolated primvar of `width` floats per element (rest positions,
  /// colours): `coarse` holds CoarsePointCount() * width floats, `refined` has room for
  /// RefinedPointCount() * width. The caller owns both buffers. Throws std::invalid_argument for
  /// width < 1 or null buffers.
  void EvaluatePrimvar(const float* coarse, int width, float* refined) const;

  /// Limit-surface positions and unit normals at the refined vertices, for smooth shading: refined
  /// points from the stencils, then pushed to the limit with OpenSubdiv's limit masks (the refiner is
  /// kept for this). Normals follow the faces' winding (outward for counter-clockwise faces seen from
  /// outside); a vertex where the limit tangents are parallel gets a zero normal. Both outputs are
  /// resized to RefinedPointCount(). Throws std::invalid_argument if `coarse` has the wrong size.
  void EvaluateLimit(const std::vector<glm::vec3>& coarse, std::vector<glm::vec3>* positions,
                     std::vector<glm::vec3>* normals) const;

  /// A face-varying primvar (`width` floats per coarse face corner, in faceVertexIndices order, indices
  /// expanded) refined through an OpenSubdiv face-varying channel and pushed to the limit, so it matches
  /// the limit positions the mesh renders: `width` floats per rendered refined face corner, in
  /// RefinedFaceIndices() order. Corners that share a point and hold identical values share one
  /// face-varying value; corners of one point with different values are a seam and stay apart, so a
  /// UV layout's islands never blend. Linear interpolation rule: the topology's faceVaryingLinearInterpolation.
  /// The channel's topology depends on the values, so this refines a second topology each call (a
  /// DirtyPrimvar cost, never a per-frame one). Throws std::invalid_argument for a wrong size or width.
  std::vector<float> EvaluateFaceVarying(const std::vector<float>& coarseCornerValues, int width) const;

 private:
  void BuildRefinedFaces();

  int _level = 0;
  MeshTopology _coarse;  ///< kept for face-varying channels, which need the coarse faces again
  int _coarsePointCount = 0;
  int _refinedPointCount = 0;
  int _faceSize = 4;
  std::vector<int> _faceIndices;
  std::vector<int> _faceParents;
  std::vector<int> _renderedFaces;  ///< last-level face index of each rendered face (holes skipped)
  std::unique_ptr<const OpenSubdiv::Far::TopologyRefiner> _refiner;  ///< all levels, full last level
  std::unique_ptr<const OpenSubdiv::Far::StencilTable> _stencils;    ///< coarse -> last-level points
};

}  // namespace hdeye
