#pragma once
// A polygon mesh rprim (HdMesh's role): triangles, quads and n-gons, optionally subdivided (Catmull-Clark,
// Loop, bilinear, with creases, corners, holes) through OpenSubdiv, with per-face materials from geomSubsets,
// held in Embree as one prototype scene under instances in the root scene: one instance when drawn once, one per
// instance of its instancer (GetInstancerId) otherwise, all over the same prototype scene, so memory grows with
// the prototypes, not with the instances. Topology is refined once; when only points change, the stencils
// re-evaluate them and the Embree vertex buffer is updated in place; a transform or instancer change only
// touches the instances.
//
// Smooth shading: every points change also recomputes per-vertex normals for the renderer
// (GeometryContext::vertexNormals). Refined meshes render the limit surface: the vertices are the limit
// positions of the refined points and the normals the limit normals there, so the Embree triangles are
// inscribed in the surface the normals describe (the refined points lie off it, inside a convex hull, and
// pairing them with limit normals would shade one surface and silhouette another). Polygon meshes get
// Hd_SmoothNormals' normals: per face corner, the cross product of its two edges, summed per point.
// Left-handed meshes get them flipped. Authored "normals" replace them on polygon meshes only
// (subdivided meshes keep their limit normals, as Hydra does).
//
// Primvars (DirtyPrimvar): "st", "displayColor" and "normals" are expanded to rendered triangle corners
// (meshPrimvars.h); "rest" (vertex) is refined to the limit like the points, for eyes on meshes.
#include "hdeye/hd/prim.h"
#include "hdeye/prims/meshPrimvars.h"
#include "hdeye/prims/motionSync.h"
#include "hdeye/render/renderContext.h"

#include <embree3/rtcore.h>

#include <memory>
#include <vector>

namespace hdeye {

class SubdivRefiner;

/// What Sync did, counted, so tests can check that dirty bits drive exactly the work they should.
struct MeshSyncStats {
  int topologyBuilds = 0;      ///< Embree geometry (re)created
  int refinements = 0;         ///< OpenSubdiv topology refinements
  int stencilEvaluations = 0;  ///< refined points re-evaluated from control points
  int pointUploads = 0;        ///< Embree vertex buffer updates
  int normalEvaluations = 0;   ///< per-vertex shading normals recomputed (limit or smooth normals)
  int transformUpdates = 0;
  int primvarSyncs = 0;            ///< primvars re-read and re-expanded (DirtyPrimvar or new topology)
  int faceVaryingRefinements = 0;  ///< face-varying channels refined (subdivided meshes)
  /// Topology syncs that rendered another refinement level than the previous one (a render plan's level change
  /// on an eye mesh, or new scene topology with another level).
  int refineLevelChanges = 0;
  int instanceSyncs = 0;   ///< the Embree instances rebuilt or moved (transform, instancer or visibility change)
  int instancesDrawn = 0;  ///< Embree instances now in the root scene (instances with a singular transform are not)
};

/// Not final: EyeMesh is a Mesh that also carries an eye.
class Mesh : public Rprim {
 public:
  explicit Mesh(PrimId id);
  ~Mesh() override;

  DirtyBits GetInitialDirtyBitsMask() const override;
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  void Finalize(RenderParam* renderParam) override;

  const MeshSyncStats& Stats() const { return stats_; }
  /// The rendered points and their shading normals, object space (for tests and debugging).
  const std::vector<Vec3f>& Points() const { return points_; }
  const std::vector<Vec3f>& Normals() const { return normals_; }
  PrimId MaterialId() const override { return materialId_; }
  /// The materials of the topology's geomSubsets, in order (an empty id: the mesh's own material); the render
  /// pass resolves them into Context()->subsetMaterials, which Context()->triangleSubsets indexes.
  const std::vector<PrimId>& SubsetMaterialIds() const { return subsetMaterialIds_; }
  GeometryContext* Context() override { return &context_; }
  int TriangleCount() const { return int(triangles_.size() / 3); }
  /// The subdivision level rendered now (0: the control polygons), and the level the scene delegate's
  /// topology asked for at the last topology sync; they differ when RefineLevelFor lowers it (eye meshes).
  int RefineLevel() const { return topology_.refineLevel; }
  int SceneRefineLevel() const { return sceneRefineLevel_; }
  /// The level this mesh renders for a scene topology of level `sceneLevel`. Mesh: capped by its planned level
  /// (0 while a pending plan has not reached it). EyeMesh: capped by its render plan (EyeRenderOptions::refineLevel).
  /// Public so that the plan can tell whether applying it changes the rendered level, i.e. whether the mesh's topology
  /// is dirty.
  virtual int RefineLevelFor(int sceneLevel);
  /// The render plan's level for this mesh (plan/meshRefinePlan.h): it then renders min(scene level, level).
  void SetPlannedRefineLevel(int level) { plannedRefineLevel_ = level, awaitingPlan_ = false; }
  void ClearPlannedRefineLevel() { plannedRefineLevel_ = -1, awaitingPlan_ = false; }
  int PlannedRefineLevel() const { return plannedRefineLevel_; }
  /// Primvars as the renderer reads them, per rendered triangle corner (empty when not authored).
  const std::vector<Vec2f>& St() const { return st_; }
  const std::vector<Vec3f>& AuthoredNormals() const { return cornerNormals_; }
  /// Rest positions per rendered point, object space (empty when not authored).
  const std::vector<Vec3f>& RestPoints() const { return rest_; }
  const TriangleLayout& Layout() const { return layout_; }
  /// The prototype scene (object space, this mesh's triangles only; committed after every points upload),
  /// or null before the first sync. Also in Context()->prototypeScene, where the renderer reads it.
  RTCScene PrototypeScene() const { return prototype_; }
  /// The instancer drawing this mesh, or empty; and the object-to-world transform of each instance drawn (one,
  /// the mesh's own, when not instanced).
  const PrimId& InstancerId() const { return instancerId_; }
  const std::vector<Matrix4d>& InstanceWorldTransforms() const { return instanceWorlds_; }
  /// A mesh drawn once: its object-to-world motion over the open shutter, on Embree's steps; null when it does not
  /// move (or is instanced).
  const std::shared_ptr<const TransformMotion>& WorldMotion() const { return worldMotion_; }
  /// The Embree time steps of the points (1: no deformation blur).
  int PointTimeSteps() const { return int(uploadedSteps_); }

 protected:
  const Matrix4d& Transform() const { return transform_; }
  /// Called when a new Embree triangle geometry is made (new topology), before it is committed:
  /// subclasses install what they need on it (EyeMesh: its inside-hit filters).
  virtual void ConfigureTriangles(RTCGeometry /*triangles*/) {}

 private:
  void SyncTopology(SceneDelegate* sceneDelegate, RenderParam* renderParam, const std::vector<Vec3f>& control);
  void SyncSubsets();
  void SyncPoints(const std::vector<Vec3f>& control);
  void SyncPrimvars(SceneDelegate* sceneDelegate, RenderParam* renderParam);
  /// The rendered points of every time step after the first (deformation blur), into laterSteps_.
  void SyncLaterSteps(const PointSteps& steps);
  void UploadPoints();
  /// Rebuilds or moves the Embree instances: the mesh's transform, times its instancer's instance transforms.
  void SyncInstances(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits bits, bool topologyDirty);
  void ReleaseInstances(RenderParam* renderParam);
  void ReleaseGeometry(RenderParam* renderParam);

  MeshTopology topology_;        ///< as rendered: refineLevel is RefineLevelFor(the scene's level)
  int sceneRefineLevel_ = -1;    ///< the scene delegate's refineLevel at the last topology sync; -1 before it
  int plannedRefineLevel_ = -1;  ///< the render plan's level, or -1
  bool awaitingPlan_ = false;    ///< synced while a plan was pending and not planned yet: level 0 until it is
  int controlPointCount_ = 0;
  std::unique_ptr<SubdivRefiner> refiner_;
  std::vector<Vec3f> points_;   ///< the rendered points (limit positions if refined), object space
  std::vector<Vec3f> normals_;  ///< unit shading normal per rendered point, object space
  std::vector<int> triangles_;  ///< 3 indices per rendered triangle (layout_.vertices)
  TriangleLayout layout_;
  std::vector<Vec3f> displayColor_;   ///< per rendered triangle corner, or empty
  std::vector<Vec2f> st_;             ///< per rendered triangle corner, or empty
  std::vector<Vec3f> cornerNormals_;  ///< authored normals per rendered triangle corner (polygon meshes), or empty
  std::vector<Vec3f> rest_;           ///< rest positions per rendered point (limit, if refined), or empty
  std::vector<PrimId> subsetMaterialIds_;
  std::vector<int> triangleSubsets_;  ///< per rendered triangle: its face's geomSubset, or -1
  Matrix4d transform_{1.0};
  std::shared_ptr<const TransformMotion> transformMotion_;  ///< the authored motion over the open shutter, or null
  std::shared_ptr<const TransformMotion> worldMotion_;      ///< see WorldMotion
  std::vector<std::vector<Vec3f>> laterSteps_;  ///< rendered points at time steps 1.. (deformation blur), object space
  std::vector<std::vector<Vec3f>> laterNormals_;  ///< their shading normals (GeometryContext::laterStepNormals)
  unsigned uploadedSteps_ = 1;                    ///< vertex buffer slots of triangleGeometry_
  PrimId materialId_;

  RTCScene prototype_ = nullptr;
  RTCGeometry triangleGeometry_ = nullptr;
  PrimId instancerId_;
  bool visible_ = true;
  std::vector<Matrix4d> instanceWorlds_;           ///< object to world per drawn instance
  std::vector<RTCGeometry> instances_;             ///< Embree instances of prototype_, one per drawn instance
  std::vector<unsigned> instanceIds_;              ///< their ids in the root scene
  std::vector<InstanceContext> instanceContexts_;  ///< their user data (sized once per rebuild: never reallocated)
  GeometryContext context_;
  MeshSyncStats stats_;
};

}  // namespace hdeye
