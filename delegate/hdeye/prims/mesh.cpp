#include "hdeye/prims/mesh.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/prims/meshBoundary.h"
#include "hdeye/prims/motionSync.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/prims/subdivRefiner.h"
#include "hdeye/render/thinWalls.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

namespace hdeye {

namespace {

[[noreturn]] void Fail(const PrimId& id, const std::string& what) {
  throw std::runtime_error("mesh " + id + ": " + what);
}

/// Copies `width`-float elements into a vector of glm vectors of that width.
template <class V> std::vector<V> ToVectors(const std::vector<float>& values) {
  static_assert(sizeof(V) == sizeof(float) * V::length(), "packed glm vector");
  std::vector<V> out(values.size() / V::length());
  std::copy(values.begin(), values.end(), &out.data()->x);
  return out;
}

/// Unit vectors (zero stays zero: the renderer then falls back to the flat normal).
void Normalize(std::vector<Vec3f>* normals) {
  for (Vec3f& n : *normals) {
    const float length = glm::length(n);
    n = length > 0 && std::isfinite(length) ? n / length : Vec3f(0);
  }
}

/// Smooth vertex normals of a polygon mesh (Hd_SmoothNormals' formula): each face corner adds the cross
/// product of its two edges (next - corner) x (previous - corner), a normal weighted by the corner's
/// parallelogram area, to its point; the sums are normalised. Over the authored polygons, not the fan
/// triangles, so the triangulation cannot tilt them (fan-triangle areas tilt a UV sphere's normals by 1.3
/// degrees; corner weights are radial there). Counter-clockwise faces get outward normals; a point no face
/// spans (or whose corners cancel) gets a zero normal, which the renderer treats as "use the flat normal".
std::vector<Vec3f> SmoothNormals(const MeshTopology& topology, const std::vector<Vec3f>& points) {
  std::vector<glm::dvec3> sum(points.size(), glm::dvec3(0));
  std::size_t base = 0;
  for (int n : topology.faceVertexCounts) {
    const int* face = &topology.faceVertexIndices[base];
    for (int k = 0; k < n; ++k) {
      const glm::dvec3 p(points[face[k]]), next(points[face[(k + 1) % n]]), prev(points[face[(k + n - 1) % n]]);
      sum[face[k]] += glm::cross(next - p, prev - p);
    }
    base += std::size_t(n);
  }
  std::vector<Vec3f> normals(points.size(), Vec3f(0));
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double length = glm::length(sum[i]);
    if (length > 0) normals[i] = Vec3f(sum[i] / length);
  }
  return normals;
}

/// The layout without the triangles of hole faces (polygon meshes; the refiner drops refined holes itself).
TriangleLayout RemoveHoles(TriangleLayout layout, const std::vector<int>& holes) {
  if (holes.empty()) return layout;
  const std::set<int> hole(holes.begin(), holes.end());
  TriangleLayout kept;
  for (std::size_t t = 0; t < layout.faces.size(); ++t) {
    if (hole.count(layout.faces[t])) continue;
    kept.faces.push_back(layout.faces[t]);
    kept.vertices.insert(kept.vertices.end(), &layout.vertices[3 * t], &layout.vertices[3 * t] + 3);
    kept.corners.insert(kept.corners.end(), &layout.corners[3 * t], &layout.corners[3 * t] + 3);
  }
  return kept;
}

}  // namespace

Mesh::Mesh(PrimId id) : Rprim(std::move(id)) {}

int Mesh::RefineLevelFor(int sceneLevel) {
  if (plannedRefineLevel_ >= 0) return std::min(sceneLevel, plannedRefineLevel_);
  return awaitingPlan_ ? 0 : sceneLevel;
}
Mesh::~Mesh() = default;

DirtyBits Mesh::GetInitialDirtyBitsMask() const {
  return dirty::InitRepr | dirty::DirtyPoints | dirty::DirtyTopology | dirty::DirtyTransform | dirty::DirtyPrimvar |
         dirty::DirtyVisibility | dirty::DirtyMaterialId | dirty::DirtyInstancer;
}

void Mesh::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  const bool topologyDirty = bits & (dirty::DirtyTopology | dirty::InitRepr);
  if (topologyDirty || (bits & dirty::DirtyPoints)) {
    // Fetched once: the topology is checked against their count, then they are evaluated. Over an open shutter, the
    // points of every Embree time step (deformation blur); the first step's are the ones shading reads.
    const PointSteps steps = SyncPointSteps(sceneDelegate, renderParam, Id(), "mesh " + Id());
    if (steps.points.empty()) Fail(Id(), "no points");
    const std::vector<Vec3f>& control = steps.points[0];
    if (topologyDirty) SyncTopology(sceneDelegate, renderParam, control);
    SyncPoints(control);
    SyncLaterSteps(steps);
    renderParam->AcquireSceneForEdit();
    UploadPoints();
  }
  // Primvars after points: "rest" is refined through the same refiner the topology just built.
  if (topologyDirty || (bits & dirty::DirtyPrimvar)) SyncPrimvars(sceneDelegate, renderParam);
  if (topologyDirty || (bits & (dirty::DirtyTransform | dirty::DirtyVisibility | dirty::DirtyInstancer)))
    SyncInstances(sceneDelegate, renderParam, bits, topologyDirty);
  if (topologyDirty || (bits & dirty::DirtyMaterialId)) materialId_ = sceneDelegate->GetMaterialId(Id());
  *dirtyBits = dirty::Clean;
}

void Mesh::SyncTopology(SceneDelegate* sceneDelegate, RenderParam* renderParam, const std::vector<Vec3f>& control) {
  const int controlPointCount = int(control.size());
  const int previousLevel = sceneRefineLevel_ < 0 ? -1 : topology_.refineLevel;
  topology_ = sceneDelegate->GetMeshTopology(Id());
  sceneRefineLevel_ = topology_.refineLevel;
  if (plannedRefineLevel_ < 0 && renderParam->MeshLevelsAwaitPlan()) awaitingPlan_ = true;
  topology_.refineLevel = RefineLevelFor(sceneRefineLevel_);
  if (previousLevel >= 0 && previousLevel != topology_.refineLevel) ++stats_.refineLevelChanges;
  controlPointCount_ = controlPointCount;
  std::size_t expected = 0;
  for (std::size_t f = 0; f < topology_.faceVertexCounts.size(); ++f) {
    const int n = topology_.faceVertexCounts[f];
    if (n < 3) Fail(Id(), "face " + std::to_string(f) + " has " + std::to_string(n) + " vertices (need 3 or more)");
    expected += std::size_t(n);
  }
  if (topology_.faceVertexCounts.empty()) Fail(Id(), "no faces");
  if (expected != topology_.faceVertexIndices.size())
    Fail(Id(), "faceVertexCounts add up to " + std::to_string(expected) + " but there are " +
                   std::to_string(topology_.faceVertexIndices.size()) + " faceVertexIndices");
  for (std::size_t i = 0; i < topology_.faceVertexIndices.size(); ++i) {
    const int v = topology_.faceVertexIndices[i];
    if (v < 0 || v >= controlPointCount_)
      Fail(Id(), "faceVertexIndices[" + std::to_string(i) + "] = " + std::to_string(v) + " is outside the " +
                     std::to_string(controlPointCount_) + " points");
  }

  const int faceCount = int(topology_.faceVertexCounts.size());
  auto checkFace = [&](const std::string& what, int f) {
    if (f < 0 || f >= faceCount)
      Fail(Id(), what + " names face " + std::to_string(f) + ", outside the " + std::to_string(faceCount) + " faces");
  };
  for (int h : topology_.holeIndices) checkFace("holeIndices", h);
  for (const GeomSubset& subset : topology_.geomSubsets)
    for (int f : subset.faceIndices) checkFace("geomSubset " + subset.materialId, f);

  if (topology_.refineLevel > 0) {
    try {
      refiner_ = std::make_unique<SubdivRefiner>(topology_, controlPointCount_, topology_.refineLevel);
    } catch (const std::invalid_argument& e) {
      Fail(Id(), e.what());
    }
    ++stats_.refinements;
    const std::vector<int>& faces = refiner_->RefinedFaceIndices();
    const int size = refiner_->RefinedFaceSize();
    layout_ = TriangulateFaces(std::vector<int>(faces.size() / std::size_t(size), size), faces,
                               refiner_->RefinedFaceParents());
  } else {
    refiner_.reset();
    layout_ = RemoveHoles(TriangulateFaces(topology_.faceVertexCounts, topology_.faceVertexIndices, {}),
                          topology_.holeIndices);
  }
  triangles_ = layout_.vertices;
  context_.thinWalled = HasBoundaryEdges(topology_.faceVertexCounts, topology_.faceVertexIndices, control);
  SyncSubsets();

  // New connectivity: a new Embree geometry (its buffers have new sizes), a new prototype scene.
  ReleaseGeometry(renderParam);
  const RTCDevice device = renderParam->Device();
  const int pointCount = refiner_ ? refiner_->RefinedPointCount() : controlPointCount_;
  triangleGeometry_ = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Points move every frame while the connectivity stays: refit the BVH instead of rebuilding it.
  rtcSetGeometryBuildQuality(triangleGeometry_, RTC_BUILD_QUALITY_REFIT);
  // Open meshes may be thin walls that shadow rays cross (thinWalls.h); EyeMesh replaces this filter with its own.
  if (context_.thinWalled) {
    rtcSetGeometryUserData(triangleGeometry_, &context_);
    rtcSetGeometryOccludedFilterFunction(triangleGeometry_, PassThinWallsFilter);
  }
  ConfigureTriangles(triangleGeometry_);
  rtcSetNewGeometryBuffer(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(float) * 3,
                          std::size_t(pointCount));
  uploadedSteps_ = 1;
  auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      triangleGeometry_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(unsigned) * 3, triangles_.size() / 3));
  for (std::size_t i = 0; i < triangles_.size(); ++i) index[i] = unsigned(triangles_[i]);
  prototype_ = rtcNewScene(device);
  rtcSetSceneFlags(prototype_, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(prototype_, RTC_BUILD_QUALITY_LOW);
  rtcAttachGeometry(prototype_, triangleGeometry_);
  context_.prototypeScene = prototype_;
  context_.triangleVertices = &triangles_;
  ++stats_.topologyBuilds;
}

void Mesh::SyncSubsets() {
  subsetMaterialIds_.clear();
  triangleSubsets_.clear();
  if (topology_.geomSubsets.empty()) {
    context_.triangleSubsets = nullptr;
    return;
  }
  std::vector<int> faceSubset(topology_.faceVertexCounts.size(), -1);
  for (std::size_t k = topology_.geomSubsets.size(); k-- > 0;)  // reversed: the first subset naming a face wins
    for (int f : topology_.geomSubsets[k].faceIndices) faceSubset[std::size_t(f)] = int(k);
  for (const GeomSubset& subset : topology_.geomSubsets) subsetMaterialIds_.push_back(subset.materialId);
  triangleSubsets_.resize(layout_.faces.size());
  for (std::size_t t = 0; t < layout_.faces.size(); ++t)
    triangleSubsets_[t] = faceSubset[std::size_t(layout_.faces[t])];
  context_.triangleSubsets = &triangleSubsets_;
}

void Mesh::SyncPoints(const std::vector<Vec3f>& control) {
  if (int(control.size()) != controlPointCount_)
    Fail(Id(), std::to_string(control.size()) + " points but the topology was built for " +
                   std::to_string(controlPointCount_) + " (mark the topology dirty too)");
  for (std::size_t i = 0; i < control.size(); ++i)
    if (!std::isfinite(control[i].x) || !std::isfinite(control[i].y) || !std::isfinite(control[i].z))
      Fail(Id(), "point " + std::to_string(i) + " is not finite");
  // Points and normals change together (this runs only when points or topology are dirty): the renderer
  // interpolates normals_ over the triangles whose vertices are points_.
  if (refiner_) {
    // Limit positions, not the refined points: see the header (the geometry must match the normals).
    refiner_->EvaluateLimit(control, &points_, &normals_);
    ++stats_.stencilEvaluations;
  } else {
    points_ = control;
    normals_ = SmoothNormals(topology_, points_);
  }
  // Both normal formulas follow the winding, which a left-handed mesh reverses.
  if (topology_.leftHanded)
    for (Vec3f& n : normals_) n = -n;
  ++stats_.normalEvaluations;
  context_.vertexNormals = &normals_;
  context_.points = &points_;
}

void Mesh::SyncLaterSteps(const PointSteps& steps) {
  laterSteps_.clear();
  laterNormals_.clear();
  for (std::size_t k = 1; k < steps.points.size(); ++k) {
    const std::vector<Vec3f>& control = steps.points[k];
    for (std::size_t i = 0; i < control.size(); ++i)
      if (!std::isfinite(control[i].x) || !std::isfinite(control[i].y) || !std::isfinite(control[i].z))
        Fail(Id(), "point " + std::to_string(i) + " of a motion sample is not finite");
    // As SyncPoints does for the first step: limit positions and normals, or the polygons' smooth normals.
    std::vector<Vec3f> points, normals;
    if (refiner_) {
      refiner_->EvaluateLimit(control, &points, &normals);
      ++stats_.stencilEvaluations;
    } else {
      points = control;
      normals = SmoothNormals(topology_, points);
    }
    if (topology_.leftHanded)
      for (Vec3f& n : normals) n = -n;
    laterSteps_.push_back(std::move(points));
    laterNormals_.push_back(std::move(normals));
  }
  context_.laterStepNormals = laterNormals_.empty() ? nullptr : &laterNormals_;
}

void Mesh::UploadPoints() {
  // One vertex buffer per Embree time step: points_ at the first, laterSteps_ after it (a new step count re-creates
  // the slots; a static mesh keeps its one buffer, updated in place).
  const unsigned stepCount = unsigned(1 + laterSteps_.size());
  if (stepCount != uploadedSteps_) {
    rtcSetGeometryTimeStepCount(triangleGeometry_, stepCount);
    for (unsigned k = 0; k < stepCount; ++k)
      rtcSetNewGeometryBuffer(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, k, RTC_FORMAT_FLOAT3, sizeof(float) * 3,
                              points_.size());
    uploadedSteps_ = stepCount;
  }
  for (unsigned k = 0; k < stepCount; ++k) {
    const std::vector<Vec3f>& points = k == 0 ? points_ : laterSteps_[k - 1];
    auto* vertex = static_cast<float*>(rtcGetGeometryBufferData(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, k));
    for (std::size_t i = 0; i < points.size(); ++i) {
      vertex[3 * i + 0] = points[i].x;
      vertex[3 * i + 1] = points[i].y;
      vertex[3 * i + 2] = points[i].z;
    }
    rtcUpdateGeometryBuffer(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, k);
  }
  rtcCommitGeometry(triangleGeometry_);
  rtcCommitScene(prototype_);
  for (RTCGeometry instance : instances_) rtcCommitGeometry(instance);  // instance bounds follow the prototype
  ++stats_.pointUploads;
}

void Mesh::SyncPrimvars(SceneDelegate* sceneDelegate, RenderParam* renderParam) {
  ++stats_.primvarSyncs;
  // Each primvar: read, checked against the topology, expanded to triangle corners. A bad one is dropped with one
  // warning naming the mesh and the primvar, as Storm drops it: the mesh renders without it.
  auto read = [&](const std::string& name, int components) {
    Primvar primvar = sceneDelegate->GetPrimvar(Id(), name);
    if (primvar.Empty()) return Primvar{};
    try {
      ValidatePrimvar(primvar, name, components, topology_, controlPointCount_);
      if (name == "rest" && primvar.interpolation != Interpolation::Vertex &&
          primvar.interpolation != Interpolation::Varying)
        throw std::runtime_error("primvar rest: must be vertex-interpolated (a position per point)");
    } catch (const std::runtime_error& e) {
      renderParam->Warn("mesh " + Id() + ": " + e.what() + " (ignored)");
      return Primvar{};
    }
    if (refiner_ && primvar.interpolation == Interpolation::FaceVarying) ++stats_.faceVaryingRefinements;
    return primvar;
  };
  const Primvar st = read("st", 2), color = read("displayColor", 3), normals = read("normals", 3),
                rest = read("rest", 3);

  st_ = st.Empty() ? std::vector<Vec2f>{} : ToVectors<Vec2f>(PrimvarAtCorners(st, layout_, refiner_.get()));
  displayColor_ =
      color.Empty() ? std::vector<Vec3f>{} : ToVectors<Vec3f>(PrimvarAtCorners(color, layout_, refiner_.get()));
  // Authored normals shade polygon meshes only: a subdivided mesh's limit normals describe the surface
  // it renders, which the authored (control-cage) normals do not (Hydra ignores them there too).
  cornerNormals_.clear();
  if (!normals.Empty() && !refiner_) {
    cornerNormals_ = ToVectors<Vec3f>(PrimvarAtCorners(normals, layout_, nullptr));
    Normalize(&cornerNormals_);
  }
  rest_.clear();
  if (!rest.Empty()) {
    rest_ = ToVectors<Vec3f>(rest.values);
    // Pushed to the limit like the points, so an undeformed mesh's rest positions equal its points.
    if (refiner_) {
      std::vector<Vec3f> unusedNormals;
      refiner_->EvaluateLimit(std::vector<Vec3f>(rest_), &rest_, &unusedNormals);
    }
  }
  context_.st = st_.empty() ? nullptr : &st_;
  context_.displayColor = displayColor_.empty() ? nullptr : &displayColor_;
  context_.cornerNormals = cornerNormals_.empty() ? nullptr : &cornerNormals_;
  context_.restPoints = rest_.empty() ? nullptr : &rest_;
}

namespace {

/// Whether Embree can instance with this transform: finite, with an invertible linear part (a zero-scale
/// instance, which PointInstancers use to hide one, draws nothing and is left out).
bool Instanceable(const Matrix4d& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  const double det = glm::determinant(glm::dmat3(m));
  return std::isfinite(det) && std::abs(det) > 1e-300;
}

}  // namespace

void Mesh::SyncInstances(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits bits, bool topologyDirty) {
  if (topologyDirty || (bits & dirty::DirtyTransform)) {
    const PrimMotion synced = SyncTransformMotion(sceneDelegate, renderParam, Id(), "mesh " + Id());
    transform_ = synced.transform;
    transformMotion_ = synced.motion;
    context_.normalToWorld = glm::transpose(glm::inverse(glm::dmat3(transform_)));
    ++stats_.transformUpdates;
  }
  if (topologyDirty || (bits & dirty::DirtyVisibility)) visible_ = sceneDelegate->GetVisible(Id());
  if (topologyDirty || (bits & dirty::DirtyInstancer)) instancerId_ = sceneDelegate->GetInstancerId(Id());

  // Each drawn instance: instance transform * the mesh's own (column vectors), as HdInstancer composes them.
  // Over an open shutter, an instance moves when the mesh or its instance does: its world motion resampled on
  // Embree's uniform steps (SteppedMotion); a closed shutter takes each instance at the shutter's time.
  std::vector<Matrix4d> worlds;
  std::vector<int> indices;
  std::vector<std::shared_ptr<const TransformMotion>> motions;
  const Instancer* instancer = nullptr;
  const Shutter shutter = renderParam->GetShutter();
  const std::vector<double> meshTimes = transformMotion_ ? transformMotion_->times : std::vector<double>{};
  auto meshAt = [&](double t) { return transformMotion_ ? transformMotion_->At(t) : transform_; };
  if (instancerId_.empty()) {
    if (Instanceable(transform_)) {
      worlds.push_back(transform_), indices.push_back(0);
      motions.push_back(transformMotion_ ? SteppedMotion(meshTimes, shutter, meshAt) : nullptr);
    }
  } else {
    RenderIndex* index = sceneDelegate->GetRenderIndex();
    instancer = index ? index->GetInstancer(instancerId_) : nullptr;
    if (!instancer) Fail(Id(), "instancer " + instancerId_ + " does not exist");
    for (const std::string& warning : instancer->MotionWarnings()) renderParam->Warn(warning);
    const std::vector<Matrix4d>& transforms = instancer->InstanceTransforms();
    const auto& instanceMotions = instancer->InstanceMotions();
    for (std::size_t i = 0; i < transforms.size(); ++i) {
      const TransformMotion* im = i < instanceMotions.size() ? instanceMotions[i].get() : nullptr;
      const Matrix4d world = (im ? im->At(shutter.open) : transforms[i]) * transform_;
      if (!Instanceable(world)) continue;
      worlds.push_back(world), indices.push_back(int(i));
      if (!im && !transformMotion_) {
        motions.push_back(nullptr);
        continue;
      }
      std::vector<double> times = meshTimes;
      if (im) times.insert(times.end(), im->times.begin(), im->times.end());
      std::sort(times.begin(), times.end());
      times.erase(std::unique(times.begin(), times.end()), times.end());
      motions.push_back(
          SteppedMotion(times, shutter, [&](double t) { return (im ? im->At(t) : transforms[i]) * meshAt(t); }));
    }
  }

  renderParam->AcquireSceneForEdit();
  if (worlds.size() != instances_.size()) {
    // A new count: new Embree instances (their user data lives in instanceContexts_, sized here once).
    ReleaseInstances(renderParam);
    instanceContexts_.resize(worlds.size());
    for (std::size_t k = 0; k < worlds.size(); ++k) {
      RTCGeometry instance = rtcNewGeometry(renderParam->Device(), RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(instance, prototype_);
      rtcSetGeometryUserData(instance, &instanceContexts_[k]);
      instanceIds_.push_back(rtcAttachGeometry(renderParam->AcquireSceneForEdit(), instance));
      instances_.push_back(instance);
    }
  }
  const std::vector<Vec3f>* colors =
      instancer && !instancer->InstanceColors().empty() ? &instancer->InstanceColors() : nullptr;
  for (std::size_t k = 0; k < worlds.size(); ++k) {
    InstanceContext& c = instanceContexts_[k];
    c.geometry = &context_;
    c.normalToWorld = glm::transpose(glm::inverse(glm::dmat3(worlds[k])));
    c.instanceIndex = indices[k];
    c.hasColor = colors != nullptr;
    c.color = colors ? (*colors)[std::size_t(indices[k])] : Vec3f(0);
    c.motion = motions[k];
    SetInstanceMotion(instances_[k], worlds[k], motions[k].get());
    if (visible_)
      rtcEnableGeometry(instances_[k]);
    else
      rtcDisableGeometry(instances_[k]);
    rtcCommitGeometry(instances_[k]);
  }
  instanceWorlds_ = std::move(worlds);
  worldMotion_ = instancerId_.empty() && !motions.empty() ? motions[0] : nullptr;
  stats_.instancesDrawn = int(instances_.size());
  ++stats_.instanceSyncs;
}

void Mesh::ReleaseInstances(RenderParam* renderParam) {
  for (std::size_t k = 0; k < instances_.size(); ++k) {
    rtcDetachGeometry(renderParam->AcquireSceneForEdit(), instanceIds_[k]);
    rtcReleaseGeometry(instances_[k]);
  }
  instances_.clear(), instanceIds_.clear(), instanceContexts_.clear();
}

void Mesh::ReleaseGeometry(RenderParam* renderParam) {
  ReleaseInstances(renderParam);
  if (triangleGeometry_) rtcReleaseGeometry(triangleGeometry_);
  if (prototype_) rtcReleaseScene(prototype_);
  triangleGeometry_ = nullptr;
  prototype_ = nullptr;
  context_.prototypeScene = nullptr;
}

void Mesh::Finalize(RenderParam* renderParam) { ReleaseGeometry(renderParam); }

}  // namespace hdeye
