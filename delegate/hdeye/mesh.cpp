#include "hdeye/mesh.h"

#include "hdeye/renderParam.h"
#include "hdeye/subdivRefiner.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hdeye {

namespace {

[[noreturn]] void Fail(const PrimId& id, const std::string& what) {
  throw std::runtime_error("mesh " + id + ": " + what);
}

/// Fan-triangulates polygons (any count >= 3) into 3 indices per triangle.
std::vector<int> Triangulate(const std::vector<int>& counts, const std::vector<int>& indices) {
  std::vector<int> tris;
  std::size_t base = 0;
  for (int n : counts) {
    for (int k = 1; k + 1 < n; ++k) {
      tris.push_back(indices[base]);
      tris.push_back(indices[base + k]);
      tris.push_back(indices[base + k + 1]);
    }
    base += std::size_t(n);
  }
  return tris;
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

}  // namespace

Mesh::Mesh(PrimId id) : Rprim(std::move(id)) {}
Mesh::~Mesh() = default;

DirtyBits Mesh::GetInitialDirtyBitsMask() const {
  return dirty::InitRepr | dirty::DirtyPoints | dirty::DirtyTopology | dirty::DirtyTransform |
         dirty::DirtyPrimvar | dirty::DirtyVisibility | dirty::DirtyMaterialId;
}

void Mesh::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  const bool topologyDirty = bits & (dirty::DirtyTopology | dirty::InitRepr);
  if (topologyDirty || (bits & dirty::DirtyPoints)) {
    // Fetched once: the topology is checked against their count, then they are evaluated.
    const std::vector<Vec3f> control = sceneDelegate->GetPoints(Id());
    if (topologyDirty) SyncTopology(sceneDelegate, renderParam, int(control.size()));
    SyncPoints(control);
    renderParam->AcquireSceneForEdit();
    UploadPoints();
  }
  if (topologyDirty || (bits & dirty::DirtyPrimvar)) SyncDisplayColor(sceneDelegate);
  if (topologyDirty || (bits & dirty::DirtyTransform)) {
    transform_ = sceneDelegate->GetTransform(Id());
    const glm::mat4 m(transform_);
    renderParam->AcquireSceneForEdit();
    rtcSetGeometryTransform(instance_, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &m[0][0]);
    context_.normalToWorld = glm::transpose(glm::inverse(glm::dmat3(transform_)));
    rtcCommitGeometry(instance_);
    ++stats_.transformUpdates;
  }
  if (topologyDirty || (bits & dirty::DirtyVisibility)) {
    renderParam->AcquireSceneForEdit();
    if (sceneDelegate->GetVisible(Id())) rtcEnableGeometry(instance_);
    else rtcDisableGeometry(instance_);
    rtcCommitGeometry(instance_);
  }
  if (topologyDirty || (bits & dirty::DirtyMaterialId)) materialId_ = sceneDelegate->GetMaterialId(Id());
  *dirtyBits = dirty::Clean;
}

void Mesh::SyncTopology(SceneDelegate* sceneDelegate, RenderParam* renderParam, int controlPointCount) {
  topology_ = sceneDelegate->GetMeshTopology(Id());
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

  if (topology_.refineLevel > 0) {
    refiner_ = std::make_unique<SubdivRefiner>(topology_, controlPointCount_, topology_.refineLevel);
    ++stats_.refinements;
    const std::vector<int>& quads = refiner_->RefinedQuadIndices();
    triangles_ = Triangulate(std::vector<int>(quads.size() / 4, 4), quads);
  } else {
    refiner_.reset();
    triangles_ = Triangulate(topology_.faceVertexCounts, topology_.faceVertexIndices);
  }

  // New connectivity: a new Embree geometry (its buffers have new sizes), a new prototype scene.
  ReleaseGeometry(renderParam);
  const RTCDevice device = renderParam->Device();
  const int pointCount = refiner_ ? refiner_->RefinedPointCount() : controlPointCount_;
  triangleGeometry_ = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Points move every frame while the connectivity stays: refit the BVH instead of rebuilding it.
  rtcSetGeometryBuildQuality(triangleGeometry_, RTC_BUILD_QUALITY_REFIT);
  rtcSetNewGeometryBuffer(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(float) * 3,
                          std::size_t(pointCount));
  auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      triangleGeometry_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(unsigned) * 3, triangles_.size() / 3));
  for (std::size_t i = 0; i < triangles_.size(); ++i) index[i] = unsigned(triangles_[i]);
  prototype_ = rtcNewScene(device);
  rtcSetSceneFlags(prototype_, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(prototype_, RTC_BUILD_QUALITY_LOW);
  rtcAttachGeometry(prototype_, triangleGeometry_);

  instance_ = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(instance_, prototype_);
  rtcSetGeometryUserData(instance_, &context_);
  instanceId_ = rtcAttachGeometry(renderParam->AcquireSceneForEdit(), instance_);
  context_.triangleVertices = &triangles_;
  ++stats_.topologyBuilds;
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
  ++stats_.normalEvaluations;
  context_.vertexNormals = &normals_;
}

void Mesh::UploadPoints() {
  auto* vertex = static_cast<float*>(rtcGetGeometryBufferData(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, 0));
  for (std::size_t i = 0; i < points_.size(); ++i) {
    vertex[3 * i + 0] = points_[i].x;
    vertex[3 * i + 1] = points_[i].y;
    vertex[3 * i + 2] = points_[i].z;
  }
  rtcUpdateGeometryBuffer(triangleGeometry_, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(triangleGeometry_);
  rtcCommitScene(prototype_);
  rtcCommitGeometry(instance_);  // the instance's bounds follow its prototype
  ++stats_.pointUploads;
}

void Mesh::SyncDisplayColor(SceneDelegate* sceneDelegate) {
  const std::vector<Vec3f> control = sceneDelegate->GetDisplayColor(Id());
  displayColor_.clear();
  if (int(control.size()) == controlPointCount_) {
    if (refiner_) {
      displayColor_.resize(std::size_t(refiner_->RefinedPointCount()));
      refiner_->EvaluatePrimvar(&control[0].x, 3, &displayColor_[0].x);
    } else {
      displayColor_ = control;
    }
  }
  context_.displayColor = displayColor_.empty() ? nullptr : &displayColor_;
}

void Mesh::ReleaseGeometry(RenderParam* renderParam) {
  if (instance_) {
    rtcDetachGeometry(renderParam->AcquireSceneForEdit(), instanceId_);
    rtcReleaseGeometry(instance_);
  }
  if (triangleGeometry_) rtcReleaseGeometry(triangleGeometry_);
  if (prototype_) rtcReleaseScene(prototype_);
  instance_ = triangleGeometry_ = nullptr;
  prototype_ = nullptr;
  instanceId_ = RTC_INVALID_GEOMETRY_ID;
}

void Mesh::Finalize(RenderParam* renderParam) { ReleaseGeometry(renderParam); }

}  // namespace hdeye
