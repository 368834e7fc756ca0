#pragma once
// A scene delegate that holds its scene in memory (Hd_UnitTestDelegate's role): C++ programs and
// tests build a scene with it, change it between frames with the Set* calls, which mark exactly the
// matching dirty bits, and render it through the render index.
#include "hdeye/hd/sceneDelegate.h"

#include <map>
#include <set>
#include <string>

namespace hdeye {

class RenderIndex;

class InMemorySceneDelegate final : public SceneDelegate {
 public:
  explicit InMemorySceneDelegate(RenderIndex* renderIndex) : index_(renderIndex) {}

  /// instancerId: the instancer (AddInstancer, added first) whose instances draw this mesh, at
  /// instanceTransform * transform each; empty: drawn once at `transform`.
  void AddMesh(const PrimId& id, const MeshTopology& topology, const std::vector<Vec3f>& points,
               const Matrix4d& transform = Matrix4d(1.0), const PrimId& materialId = "",
               const PrimId& instancerId = "");
  /// BasisCurves (primTypes::kBasisCurves) over `points`; widths and normals through SetPrimvar.
  void AddBasisCurves(const PrimId& id, const BasisCurvesTopology& topology, const std::vector<Vec3f>& points,
                      const Matrix4d& transform = Matrix4d(1.0), const PrimId& materialId = "");
  /// Points (primTypes::kPoints), spheres of SetPrimvar's "widths" (default 1).
  void AddPoints(const PrimId& id, const std::vector<Vec3f>& points, const Matrix4d& transform = Matrix4d(1.0),
                 const PrimId& materialId = "");
  /// An instancer: per-instance transforms (instance to world, column vectors) and optional per-instance
  /// displayColors (empty, or one per instance).
  void AddInstancer(const PrimId& id, const std::vector<Matrix4d>& transforms, const std::vector<Vec3f>& colors = {});
  /// New instances (count may change): marks the instancer dirty and its meshes DirtyInstancer only.
  void SetInstanceTransforms(const PrimId& id, const std::vector<Matrix4d>& transforms,
                             const std::vector<Vec3f>& colors = {});
  void AddCamera(const PrimId& id, const CameraParams& params, const Matrix4d& transform);
  /// type: one of the light prim types (sphereLight, distantLight, rectLight, diskLight, domeLight).
  void AddLight(const PrimId& id, const std::string& type, const LightParams& params,
                const Matrix4d& transform = Matrix4d(1.0));
  void AddMaterial(const PrimId& id, const MaterialParams& params);
  /// An eye on a mesh (primTypes::kEyeMesh): the mesh is what rays hit; its cornea continues against
  /// the analytic model of `eyeParams` (whose modelTransform places the canonical frame in the mesh's
  /// local space).
  void AddEyeMesh(const PrimId& id, const MeshTopology& topology, const std::vector<Vec3f>& points,
                  const EyeParams& eyeParams, const Matrix4d& transform = Matrix4d(1.0), const PrimId& materialId = "");
  /// An analytic eye (the anterior segment alone, no mesh).
  void AddAnalyticEye(const PrimId& id, const EyeParams& params, const Matrix4d& transform = Matrix4d(1.0));
  void AddRenderBuffer(const PrimId& id, int width, int height, int components);

  void SetPoints(const PrimId& id, const std::vector<Vec3f>& points);
  void SetTopology(const PrimId& id, const MeshTopology& topology, const std::vector<Vec3f>& points);
  /// A mesh's subdivision scheme and tags and its holes (the rest of its topology kept). Marks DirtyTopology.
  void SetSubdivision(const PrimId& id, SubdivScheme scheme, const SubdivTags& tags,
                      const std::vector<int>& holeIndices);
  /// A mesh's per-face materials (the rest of its topology kept). Marks DirtyTopology.
  void SetGeomSubsets(const PrimId& id, const std::vector<GeomSubset>& subsets);
  void SetTransform(const PrimId& id, const Matrix4d& transform);
  /// Motion samples of a prim's transform (times in frames relative to the frame, ascending; one matrix per time).
  /// GetTransform then returns the transform at time 0. Marks DirtyTransform, as SetTransform, which sets one
  /// (static) sample. std::invalid_argument for mismatched lengths, no samples, or a matrix CheckTransform rejects.
  void SetTransformSamples(const PrimId& id, const std::vector<float>& times, const std::vector<Matrix4d>& matrices);
  /// Motion samples of a point-based prim's points (each the same count); GetPoints then returns the points at
  /// time 0. Marks DirtyPoints, as SetPoints.
  void SetPointsSamples(const PrimId& id, const std::vector<float>& times,
                        const std::vector<std::vector<Vec3f>>& pointsPerTime);
  /// Motion samples of an instancer's transforms (each the same instance count; colours kept). Marks the instancer
  /// dirty, as SetInstanceTransforms.
  void SetInstanceTransformSamples(const PrimId& id, const std::vector<float>& times,
                                   const std::vector<std::vector<Matrix4d>>& transformsPerTime);
  void SetVisible(const PrimId& id, bool visible);
  /// A mesh primvar by name ("st", "normals", "displayColor", "rest"); an empty one removes it.
  /// Marks DirtyPrimvar.
  void SetPrimvar(const PrimId& id, const std::string& name, const Primvar& primvar);
  /// Shorthand for SetPrimvar(id, "displayColor", a vertex primvar of `colors`).
  void SetDisplayColor(const PrimId& id, const std::vector<Vec3f>& colors);
  void SetLightParams(const PrimId& id, const LightParams& params);
  void SetCameraParams(const PrimId& id, const CameraParams& params);
  void SetMaterialParams(const PrimId& id, const MaterialParams& params);
  void SetEyeParams(const PrimId& id, const EyeParams& params);
  void SetMaterialId(const PrimId& id, const PrimId& materialId);
  /// Removes a prim from the render index and forgets its data; unknown ids are ignored.
  void RemovePrim(const PrimId& id);

  RenderIndex* GetRenderIndex() override { return index_; }
  PrimId GetInstancerId(const PrimId& id) override;
  std::vector<Matrix4d> GetInstanceTransforms(const PrimId& id) override { return instancers_.at(id).transforms; }
  std::vector<Vec3f> GetInstanceColors(const PrimId& id) override { return instancers_.at(id).colors; }
  MeshTopology GetMeshTopology(const PrimId& id) override { return meshes_.at(id).topology; }
  std::vector<Vec3f> GetPoints(const PrimId& id) override { return meshes_.at(id).points; }
  BasisCurvesTopology GetBasisCurvesTopology(const PrimId& id) override { return curves_.at(id); }
  Matrix4d GetTransform(const PrimId& id) override { return transforms_.at(id); }
  bool GetVisible(const PrimId& id) override { return !hidden_.count(id); }
  Primvar GetPrimvar(const PrimId& id, const std::string& name) override;
  PrimId GetMaterialId(const PrimId& id) override { return meshes_.at(id).materialId; }
  CameraParams GetCameraParams(const PrimId& id) override { return cameras_.at(id); }
  LightParams GetLightParams(const PrimId& id) override { return lights_.at(id); }
  MaterialParams GetMaterialParams(const PrimId& id) override { return materials_.at(id); }
  EyeParams GetEyeParams(const PrimId& id) override { return eyes_.at(id); }
  TimeSampled<Matrix4d> SampleTransform(const PrimId& id) override;
  TimeSampled<std::vector<Vec3f>> SamplePoints(const PrimId& id) override;
  TimeSampled<std::vector<Matrix4d>> SampleInstanceTransforms(const PrimId& id) override;

 private:
  struct MeshData {
    MeshTopology topology;
    std::vector<Vec3f> points;
    std::map<std::string, Primvar> primvars;
    PrimId materialId;
    PrimId instancerId;
    TimeSampled<std::vector<Vec3f>> pointsSamples;  ///< empty: static (`points`)
  };
  struct InstancerData {
    std::vector<Matrix4d> transforms;
    std::vector<Vec3f> colors;
    TimeSampled<std::vector<Matrix4d>> transformSamples;  ///< empty: static (`transforms`)
  };
  RenderIndex* index_;
  std::map<PrimId, MeshData> meshes_;  ///< meshes, and the points, primvars and material of curves and points
  std::map<PrimId, BasisCurvesTopology> curves_;
  std::map<PrimId, Matrix4d> transforms_;
  std::map<PrimId, TimeSampled<Matrix4d>> transformSamples_;  ///< prims with motion samples only
  std::map<PrimId, CameraParams> cameras_;
  std::map<PrimId, LightParams> lights_;
  std::map<PrimId, MaterialParams> materials_;
  std::map<PrimId, EyeParams> eyes_;
  std::map<PrimId, InstancerData> instancers_;
  std::set<PrimId> hidden_;
};

}  // namespace hdeye
