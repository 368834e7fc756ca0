#include "hdeye/eyeMesh.h"

#include "hdeye/eyeMeshMapping.h"
#include "hdeye/renderParam.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

namespace {

/// Rejects hits on the inside of an eye mesh, for closest-hit and shadow rays alike. Embree hands an
/// instanced geometry's filter the ray in the instance's object space, the space of the mesh's points.
void RejectInsideHits(const RTCFilterFunctionNArguments* args) {
  const auto* context = static_cast<const GeometryContext*>(args->geometryUserPtr);
  if (!context || !context->points || !context->vertexNormals || !context->triangleVertices) return;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const glm::dvec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                       RTCRayN_dir_z(args->ray, args->N, i));
    const glm::dvec3 outward = EyeMeshOutwardNormal(*context, RTCHitN_primID(args->hit, args->N, i));
    if (glm::dot(d, outward) >= 0) args->valid[i] = 0;
  }
}

}  // namespace

void EyeMesh::ConfigureTriangles(RTCGeometry triangles) {
  rtcSetGeometryUserData(triangles, Context());
  rtcSetGeometryIntersectFilterFunction(triangles, RejectInsideHits);
  rtcSetGeometryOccludedFilterFunction(triangles, RejectInsideHits);
}

void EyeMesh::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  Mesh::Sync(sceneDelegate, renderParam, dirtyBits);
  if (bits & (dirty::DirtyParams | dirty::InitRepr)) {
    params_ = sceneDelegate->GetEyeParams(Id());
    const std::string problem = eyelib::ValidateChamberParams(params_.chamber);
    if (!problem.empty()) throw std::runtime_error("eye mesh " + Id() + ": " + problem);
    try {
      irisTexture_ = params_.irisTexture.empty() ? nullptr : renderParam->Textures().Get(params_.irisTexture);
    } catch (const std::exception& e) {
      throw std::runtime_error("eye mesh " + Id() + ": iris texture: " + e.what());
    }
  }
  // Cheap, and it depends on the transform, the params and the material binding: rebuilt every sync.
  eye_ = EyeGeometry(params_, Transform());
  if (!(eye_.worldPerMm > 0) || !std::isfinite(eye_.worldPerMm))
    throw std::runtime_error("eye mesh " + Id() + ": its transform or modelTransform is degenerate");
  eye_.objectToCanonical = glm::inverse(params_.modelTransform);
  eye_.irisTexture = irisTexture_;
  eye_.scleraUsesMaterial = !MaterialId().empty();
  Context()->meshEye = &eye_;
  // The eye's world placement moved with the transform; renders must restart.
  if (bits & (dirty::DirtyParams | dirty::InitRepr)) renderParam->AcquireSceneForEdit();
}

}  // namespace hdeye
