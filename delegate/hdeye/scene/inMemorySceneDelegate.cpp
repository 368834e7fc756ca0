#include "hdeye/scene/inMemorySceneDelegate.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/params/motion.h"
#include "hdeye/prims/renderBuffer.h"
#include "hdeye/prims/renderDelegate.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

namespace {
/// Rejects a transform no prim can use, before a prim syncs it into Embree: NaN/Inf entries, a projective
/// row or a linear part of determinant 0 (no inverse for rays and normals). Called first in every Add, so a
/// rejected Add leaves nothing behind.
void CheckTransform(const PrimId& id, const Matrix4d& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) throw std::invalid_argument("prim " + id + ": transform has NaN or Inf entries");
  // A tolerance, as the Python front end's: a composed look-at matrix carries 1 + 2e-16 where 1 is meant.
  constexpr double kAffineTolerance = 1e-9;
  if (std::abs(m[0][3]) > kAffineTolerance || std::abs(m[1][3]) > kAffineTolerance ||
      std::abs(m[2][3]) > kAffineTolerance || std::abs(m[3][3] - 1) > kAffineTolerance)
    throw std::invalid_argument("prim " + id + ": transform is projective");
  if (glm::determinant(glm::dmat3(m)) == 0) throw std::invalid_argument("prim " + id + ": transform is singular");
}
/// Rejects samples that do not pair one value with each time, or none at all.
template <class T> void CheckSamples(const PrimId& id, const std::vector<float>& times, const std::vector<T>& values) {
  if (times.empty() || times.size() != values.size())
    throw std::invalid_argument("prim " + id + ": " + std::to_string(times.size()) + " sample times for " +
                                std::to_string(values.size()) + " values");
  for (float t : times)
    if (!std::isfinite(t)) throw std::invalid_argument("prim " + id + ": a sample time is NaN or Inf");
}

/// The index of the sample nearest time 0 (what a static Get* call returns when no interpolation applies).
std::size_t NearestToFrame(const std::vector<float>& times) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < times.size(); ++i)
    if (std::abs(times[i]) < std::abs(times[best])) best = i;
  return best;
}
}  // namespace

void InMemorySceneDelegate::AddMesh(const PrimId& id, const MeshTopology& topology, const std::vector<Vec3f>& points,
                                    const Matrix4d& transform, const PrimId& materialId, const PrimId& instancerId) {
  CheckTransform(id, transform);
  meshes_[id] = MeshData{topology, points, {}, materialId, instancerId, {}};
  transforms_[id] = transform;
  index_->InsertRprim(primTypes::kMesh, this, id);
  if (!instancerId.empty()) index_->GetChangeTracker().AddInstancerRprimDependency(instancerId, id);
}

void InMemorySceneDelegate::AddInstancer(const PrimId& id, const std::vector<Matrix4d>& transforms,
                                         const std::vector<Vec3f>& colors) {
  instancers_[id] = InstancerData{transforms, colors, {}};
  index_->InsertInstancer(this, id);
}

void InMemorySceneDelegate::SetInstanceTransforms(const PrimId& id, const std::vector<Matrix4d>& transforms,
                                                  const std::vector<Vec3f>& colors) {
  instancers_.at(id) = InstancerData{transforms, colors, {}};
  index_->GetChangeTracker().MarkInstancerDirty(id);
}

PrimId InMemorySceneDelegate::GetInstancerId(const PrimId& id) {
  const auto mesh = meshes_.find(id);
  return mesh == meshes_.end() ? PrimId{} : mesh->second.instancerId;
}

void InMemorySceneDelegate::AddEyeMesh(const PrimId& id, const MeshTopology& topology, const std::vector<Vec3f>& points,
                                       const EyeParams& eyeParams, const Matrix4d& transform,
                                       const PrimId& materialId) {
  CheckTransform(id, transform);
  meshes_[id] = MeshData{topology, points, {}, materialId, {}, {}};
  eyes_[id] = eyeParams;
  transforms_[id] = transform;
  index_->InsertRprim(primTypes::kEyeMesh, this, id);
}

void InMemorySceneDelegate::AddBasisCurves(const PrimId& id, const BasisCurvesTopology& topology,
                                           const std::vector<Vec3f>& points, const Matrix4d& transform,
                                           const PrimId& materialId) {
  CheckTransform(id, transform);
  meshes_[id] = MeshData{{}, points, {}, materialId, {}, {}};
  curves_[id] = topology;
  transforms_[id] = transform;
  index_->InsertRprim(primTypes::kBasisCurves, this, id);
}

void InMemorySceneDelegate::AddPoints(const PrimId& id, const std::vector<Vec3f>& points, const Matrix4d& transform,
                                      const PrimId& materialId) {
  CheckTransform(id, transform);
  meshes_[id] = MeshData{{}, points, {}, materialId, {}, {}};
  transforms_[id] = transform;
  index_->InsertRprim(primTypes::kPoints, this, id);
}

void InMemorySceneDelegate::AddCamera(const PrimId& id, const CameraParams& params, const Matrix4d& transform) {
  CheckTransform(id, transform);
  cameras_[id] = params;
  transforms_[id] = transform;
  index_->InsertSprim(primTypes::kCamera, this, id);
}

void InMemorySceneDelegate::AddLight(const PrimId& id, const std::string& type, const LightParams& params,
                                     const Matrix4d& transform) {
  CheckTransform(id, transform);
  lights_[id] = params;
  transforms_[id] = transform;
  index_->InsertSprim(type, this, id);
}

void InMemorySceneDelegate::AddMaterial(const PrimId& id, const MaterialParams& params) {
  materials_[id] = params;
  index_->InsertSprim(primTypes::kMaterial, this, id);
}

void InMemorySceneDelegate::AddAnalyticEye(const PrimId& id, const EyeParams& params, const Matrix4d& transform) {
  CheckTransform(id, transform);
  eyes_[id] = params;
  transforms_[id] = transform;
  index_->InsertRprim(primTypes::kAnalyticEye, this, id);
}

void InMemorySceneDelegate::AddRenderBuffer(const PrimId& id, int width, int height, int components) {
  index_->InsertBprim(primTypes::kRenderBuffer, this, id);
  static_cast<RenderBuffer*>(index_->GetBprim(id))->Allocate(width, height, components);
}

void InMemorySceneDelegate::SetPoints(const PrimId& id, const std::vector<Vec3f>& points) {
  meshes_.at(id).points = points;
  meshes_.at(id).pointsSamples = {};
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyPoints);
}

void InMemorySceneDelegate::SetTopology(const PrimId& id, const MeshTopology& topology,
                                        const std::vector<Vec3f>& points) {
  meshes_.at(id).topology = topology;
  meshes_.at(id).points = points;
  meshes_.at(id).pointsSamples = {};
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyTopology | dirty::DirtyPoints);
}

void InMemorySceneDelegate::SetSubdivision(const PrimId& id, SubdivScheme scheme, const SubdivTags& tags,
                                           const std::vector<int>& holeIndices) {
  MeshTopology& topology = meshes_.at(id).topology;
  topology.scheme = scheme;
  topology.subdivTags = tags;
  topology.holeIndices = holeIndices;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyTopology);
}

void InMemorySceneDelegate::SetGeomSubsets(const PrimId& id, const std::vector<GeomSubset>& subsets) {
  meshes_.at(id).topology.geomSubsets = subsets;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyTopology);
}

void InMemorySceneDelegate::SetTransform(const PrimId& id, const Matrix4d& transform) {
  CheckTransform(id, transform);
  transforms_.at(id) = transform;
  transformSamples_.erase(id);
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyTransform);
}

void InMemorySceneDelegate::SetTransformSamples(const PrimId& id, const std::vector<float>& times,
                                                const std::vector<Matrix4d>& matrices) {
  CheckSamples(id, times, matrices);
  for (const Matrix4d& m : matrices) CheckTransform(id, m);
  Matrix4d& atFrame = transforms_.at(id);
  const std::optional<TransformMotion> motion = MakeTransformMotion({times, matrices}, id, nullptr);
  atFrame = motion ? motion->At(0.0) : matrices[NearestToFrame(times)];
  if (matrices.size() == 1)
    transformSamples_.erase(id);
  else
    transformSamples_[id] = {times, matrices};
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyTransform);
}

TimeSampled<Matrix4d> InMemorySceneDelegate::SampleTransform(const PrimId& id) {
  const auto it = transformSamples_.find(id);
  return it != transformSamples_.end() ? it->second : TimeSampled<Matrix4d>{{0.0f}, {transforms_.at(id)}};
}

void InMemorySceneDelegate::SetPointsSamples(const PrimId& id, const std::vector<float>& times,
                                             const std::vector<std::vector<Vec3f>>& pointsPerTime) {
  CheckSamples(id, times, pointsPerTime);
  for (const std::vector<Vec3f>& points : pointsPerTime)
    if (points.size() != pointsPerTime[0].size())
      throw std::invalid_argument("prim " + id + ": point samples differ in count");
  MeshData& mesh = meshes_.at(id);
  mesh.pointsSamples = pointsPerTime.size() == 1 ? TimeSampled<std::vector<Vec3f>>{}
                                                 : TimeSampled<std::vector<Vec3f>>{times, pointsPerTime};
  mesh.points = pointsPerTime.size() == 1 ? pointsPerTime[0] : PointsAt(mesh.pointsSamples, 0.0);
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyPoints);
}

TimeSampled<std::vector<Vec3f>> InMemorySceneDelegate::SamplePoints(const PrimId& id) {
  const MeshData& mesh = meshes_.at(id);
  return mesh.pointsSamples.values.empty() ? TimeSampled<std::vector<Vec3f>>{{0.0f}, {mesh.points}}
                                           : mesh.pointsSamples;
}

void InMemorySceneDelegate::SetInstanceTransformSamples(const PrimId& id, const std::vector<float>& times,
                                                        const std::vector<std::vector<Matrix4d>>& transformsPerTime) {
  CheckSamples(id, times, transformsPerTime);
  for (const std::vector<Matrix4d>& transforms : transformsPerTime)
    if (transforms.size() != transformsPerTime[0].size())
      throw std::invalid_argument("instancer " + id + ": instance transform samples differ in count");
  InstancerData& instancer = instancers_.at(id);
  const std::size_t count = transformsPerTime[0].size();
  instancer.transforms.assign(count, Matrix4d(1.0));
  for (std::size_t k = 0; k < count; ++k) {
    TimeSampled<Matrix4d> one{times, {}};
    for (const std::vector<Matrix4d>& transforms : transformsPerTime) one.values.push_back(transforms[k]);
    const std::optional<TransformMotion> motion = MakeTransformMotion(one, id, nullptr);
    instancer.transforms[k] = motion ? motion->At(0.0) : one.values[NearestToFrame(times)];
  }
  instancer.transformSamples = transformsPerTime.size() == 1
                                   ? TimeSampled<std::vector<Matrix4d>>{}
                                   : TimeSampled<std::vector<Matrix4d>>{times, transformsPerTime};
  index_->GetChangeTracker().MarkInstancerDirty(id);
}

TimeSampled<std::vector<Matrix4d>> InMemorySceneDelegate::SampleInstanceTransforms(const PrimId& id) {
  const InstancerData& instancer = instancers_.at(id);
  return instancer.transformSamples.values.empty() ? TimeSampled<std::vector<Matrix4d>>{{0.0f}, {instancer.transforms}}
                                                   : instancer.transformSamples;
}

void InMemorySceneDelegate::SetVisible(const PrimId& id, bool visible) {
  if (visible)
    hidden_.erase(id);
  else
    hidden_.insert(id);
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyVisibility);
}

void InMemorySceneDelegate::SetPrimvar(const PrimId& id, const std::string& name, const Primvar& primvar) {
  std::map<std::string, Primvar>& primvars = meshes_.at(id).primvars;
  if (primvar.Empty())
    primvars.erase(name);
  else
    primvars[name] = primvar;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyPrimvar);
}

void InMemorySceneDelegate::SetDisplayColor(const PrimId& id, const std::vector<Vec3f>& colors) {
  Primvar primvar{Interpolation::Vertex, 3, {}};
  for (const Vec3f& c : colors) primvar.values.insert(primvar.values.end(), {c.x, c.y, c.z});
  SetPrimvar(id, "displayColor", primvar);
}

Primvar InMemorySceneDelegate::GetPrimvar(const PrimId& id, const std::string& name) {
  const auto mesh = meshes_.find(id);
  if (mesh == meshes_.end()) return {};
  const auto it = mesh->second.primvars.find(name);
  return it == mesh->second.primvars.end() ? Primvar{} : it->second;
}

void InMemorySceneDelegate::SetLightParams(const PrimId& id, const LightParams& params) {
  lights_.at(id) = params;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyParams);
}

void InMemorySceneDelegate::SetCameraParams(const PrimId& id, const CameraParams& params) {
  cameras_.at(id) = params;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyParams);
}

void InMemorySceneDelegate::SetMaterialParams(const PrimId& id, const MaterialParams& params) {
  materials_.at(id) = params;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyParams);
}

void InMemorySceneDelegate::SetEyeParams(const PrimId& id, const EyeParams& params) {
  eyes_.at(id) = params;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyParams);
}

void InMemorySceneDelegate::SetMaterialId(const PrimId& id, const PrimId& materialId) {
  meshes_.at(id).materialId = materialId;
  index_->GetChangeTracker().MarkDirty(id, dirty::DirtyMaterialId);
}

void InMemorySceneDelegate::RemovePrim(const PrimId& id) {
  index_->RemovePrim(id);
  if (const auto mesh = meshes_.find(id); mesh != meshes_.end() && !mesh->second.instancerId.empty())
    index_->GetChangeTracker().RemoveInstancerRprimDependency(mesh->second.instancerId, id);
  instancers_.erase(id), transformSamples_.erase(id);
  meshes_.erase(id), curves_.erase(id), transforms_.erase(id), cameras_.erase(id), lights_.erase(id);
  materials_.erase(id), eyes_.erase(id), hidden_.erase(id);
}

}  // namespace hdeye
