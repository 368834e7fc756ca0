#pragma once
// The scene side (HdSceneDelegate's role): prims pull their data from it during Sync. The Python USD
// scene delegate implements it through the bindings; InMemorySceneDelegate implements it for C++
// programs and tests.
#include "hdeye/hd/types.h"
#include "hdeye/params/primParams.h"
#include "hdeye/params/timeSampled.h"

#include <string>
#include <vector>

namespace hdeye {

/// How a primvar's values map onto a mesh (UsdGeom's interpolation names).
enum class Interpolation { Constant, Uniform, Vertex, Varying, FaceVarying };

/// A primvar's values, flattened: `components` floats per element (one element for Constant, one per
/// face for Uniform, one per point for Vertex and Varying, one per face corner for FaceVarying, after
/// any authored indices have been expanded). Empty values: not authored.
struct Primvar {
  Interpolation interpolation = Interpolation::Vertex;
  int components = 0;
  std::vector<float> values;
  bool Empty() const { return values.empty() || components <= 0; }
};

class RenderIndex;

class SceneDelegate {
 public:
  virtual ~SceneDelegate() = default;
  /// The render index this delegate populates (prims reach their instancer through it, as in Hydra).
  virtual RenderIndex* GetRenderIndex() = 0;
  virtual MeshTopology GetMeshTopology(const PrimId& id) = 0;
  /// BasisCurves prims only; the default suits scene delegates that have none.
  virtual BasisCurvesTopology GetBasisCurvesTopology(const PrimId& /*id*/) { return {}; }
  virtual std::vector<Vec3f> GetPoints(const PrimId& id) = 0;
  virtual Matrix4d GetTransform(const PrimId& id) = 0;
  virtual bool GetVisible(const PrimId& id) = 0;
  /// A primvar by name (meshes: "st", "normals", "displayColor", "rest"; curves: "widths", "normals",
  /// "displayColor"; points: "widths", "displayColor"); empty when not authored.
  virtual Primvar GetPrimvar(const PrimId& /*id*/, const std::string& /*name*/) { return {}; }
  virtual PrimId GetMaterialId(const PrimId& id) = 0;
  virtual CameraParams GetCameraParams(const PrimId& id) = 0;
  virtual LightParams GetLightParams(const PrimId& id) = 0;
  virtual MaterialParams GetMaterialParams(const PrimId& id) = 0;
  virtual EyeParams GetEyeParams(const PrimId& id) = 0;
  /// The instancer whose instances an rprim draws (HdSceneDelegate::GetInstancerId), or empty: drawn once.
  virtual PrimId GetInstancerId(const PrimId& /*rprimId*/) { return {}; }
  /// An instancer's per-instance transforms (instance space to world, column vectors): an rprim drawn by it
  /// renders at instanceTransform * rprimTransform for every instance.
  virtual std::vector<Matrix4d> GetInstanceTransforms(const PrimId& /*instancerId*/) { return {}; }
  /// Per-instance displayColor (linear RGB), one per instance, or empty: the prototypes' own colours.
  virtual std::vector<Vec3f> GetInstanceColors(const PrimId& /*instancerId*/) { return {}; }

  /// Motion samples over the shutter (HdSceneDelegate::SampleTransform and friends), times in frames relative to
  /// the frame. The defaults return the one sample of the Get* call at time 0: a static prim. Cameras, lights,
  /// eyes and rprims all take their transform from SampleTransform.
  virtual TimeSampled<Matrix4d> SampleTransform(const PrimId& id) { return {{0.0f}, {GetTransform(id)}}; }
  /// A point-based prim's points per time (every sample has the same count as GetPoints).
  virtual TimeSampled<std::vector<Vec3f>> SamplePoints(const PrimId& id) { return {{0.0f}, {GetPoints(id)}}; }
  /// An instancer's per-instance transforms per time (every sample has the same instance count).
  virtual TimeSampled<std::vector<Matrix4d>> SampleInstanceTransforms(const PrimId& instancerId) {
    return {{0.0f}, {GetInstanceTransforms(instancerId)}};
  }
};

}  // namespace hdeye
