#include "hdeye/prims/eyeMesh.h"

#include "hdeye/prims/eyeParamsSync.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/render/eyeMeshMapping.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
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

/// The similarity (rotation or reflection, uniform scale, translation) nearest to an affine map: the
/// orthogonal polar factor of its linear part (Higham's averaging iteration, quadratically convergent),
/// scaled by the cube root of |det|. The re-projected eye's rigid frame: a non-uniform scale in the prim
/// transform deforms the mesh, not the optics.
glm::dmat4 NearestSimilarity(const glm::dmat4& m) {
  const glm::dmat3 linear(m);
  const double scale = std::cbrt(std::abs(glm::determinant(linear)));
  glm::dmat3 q = linear / scale;
  for (int k = 0; k < 30; ++k) {
    const glm::dmat3 next = 0.5 * (q + glm::transpose(glm::inverse(q)));
    double change = 0;
    for (int c = 0; c < 3; ++c) change += glm::length(next[c] - q[c]);
    q = next;
    if (change < 1e-14) break;
  }
  glm::dmat4 out(q * scale);
  out[3] = m[3];
  return out;
}

/// The affine map (object space) that best takes the rest points to the current ones, least squares:
/// A = C D^-1 with C = sum (p - p')(q - q')^T and D = sum (q - q')(q - q')^T about the centroids. The
/// identity when there is no rest pose or it is degenerate (flat: D singular).
glm::dmat4 FitAffine(const std::vector<Vec3f>& rest, const std::vector<Vec3f>& current) {
  if (rest.empty() || rest.size() != current.size()) return glm::dmat4(1.0);
  glm::dvec3 qc(0), pc(0);
  for (std::size_t i = 0; i < rest.size(); ++i) qc += glm::dvec3(rest[i]), pc += glm::dvec3(current[i]);
  qc /= double(rest.size()), pc /= double(rest.size());
  glm::dmat3 C(0.0), D(0.0);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    const glm::dvec3 q = glm::dvec3(rest[i]) - qc, p = glm::dvec3(current[i]) - pc;
    C += glm::outerProduct(p, q);
    D += glm::outerProduct(q, q);
  }
  const double det = glm::determinant(D), size = D[0][0] + D[1][1] + D[2][2];
  if (!(std::abs(det) > 1e-12 * size * size * size)) return glm::dmat4(1.0);
  const glm::dmat3 A = C * glm::inverse(D);
  glm::dmat4 out(A);
  out[3] = glm::dvec4(pc - A * qc, 1);
  return out;
}

/// Six times the signed volume the rendered triangles enclose (object units^3): positive for outward
/// counter-clockwise winding.
double SignedVolume(const std::vector<Vec3f>& points, const std::vector<int>& triangles) {
  double sum = 0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const glm::dvec3 a(points[triangles[t]]), b(points[triangles[t + 1]]), c(points[triangles[t + 2]]);
    sum += glm::dot(a, glm::cross(b, c));
  }
  return sum;
}

bool FiniteMatrix(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

}  // namespace

void EyeMesh::ConfigureTriangles(RTCGeometry triangles) {
  rtcSetGeometryUserData(triangles, Context());
  rtcSetGeometryIntersectFilterFunction(triangles, RejectInsideHits);
  rtcSetGeometryOccludedFilterFunction(triangles, RejectInsideHits);
}

int EyeMesh::RefineLevelFor(int sceneLevel) {
  const EyeRenderOptions& o = Context()->eyeOptions;
  return o.planned && o.refineLevel >= 0 ? std::min(sceneLevel, o.refineLevel) : sceneLevel;
}

void EyeMesh::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  Mesh::Sync(sceneDelegate, renderParam, dirtyBits);
  if (bits & (dirty::DirtyParams | dirty::InitRepr)) {
    SyncEyeParams(sceneDelegate, renderParam, "eye mesh", Id(), &params_, &irisTexture_);
  }
  // Cheap, and it depends on the transform, the params and the material binding: rebuilt every sync.
  eye_ = EyeGeometry(params_, Transform());
  if (!(eye_.worldPerMm > 0) || !std::isfinite(eye_.worldPerMm))
    throw std::runtime_error("eye mesh " + Id() + ": its transform or modelTransform is degenerate");
  SyncEyeFrames();
  // A moving eye mesh: its frames follow the mesh's world motion, the rigid correction measured here kept.
  if (WorldMotion())
    eye_.motion = std::make_shared<const EyeMotion>(
        EyeMotion{WorldMotion(), glm::inverse(Transform()) * eye_.canonicalToWorld, renderParam->GetShutter()});
  eye_.irisTexture = irisTexture_;
  eye_.scleraUsesMaterial = !MaterialId().empty();
  Context()->meshEye = &eye_;
  // The eye's world placement moved with the transform; renders must restart.
  if (bits & (dirty::DirtyParams | dirty::InitRepr)) renderParam->AcquireSceneForEdit();
}

void EyeMesh::SyncEyeFrames() {
  const glm::dmat4 prim = Transform(), model = params_.modelTransform;
  eye_.objectToWorld = prim;
  eye_.reprojection = params_.reprojection;
  if (params_.hasIrisProjection) {
    const double det = glm::determinant(glm::dmat3(params_.irisProjection));
    if (!FiniteMatrix(params_.irisProjection) || !(std::abs(det) > 0) || !std::isfinite(det))
      throw std::runtime_error("eye mesh " + Id() + ": irisProjection is singular or not finite");
  }
  // Rest and current points, as rendered (limit positions on subdivided meshes).
  const std::vector<Vec3f>& rest = RestPoints();
  const std::vector<Vec3f>& current = Points();
  if (params_.reprojection) {
    // The optics sit in the eye's rigid frame; hits reach it through the projection (eyeMeshMapping.h).
    eye_.canonicalToWorld = NearestSimilarity(prim * model);
    eye_.objectToCanonical = glm::inverse(model);
    eye_.objectToProjection = params_.hasIrisProjection
                                  ? glm::scale(glm::dmat4(1.0), glm::dvec3(eyelib::paper::kIrisDiameter / 2)) *
                                        glm::inverse(params_.irisProjection)
                                  : eye_.objectToCanonical;
  } else {
    // Baseline: the analytic eye carried by the mesh's best-fit affine deformation.
    const glm::dmat4 deformation = FitAffine(rest, current);
    eye_.canonicalToWorld = prim * deformation * model;
    eye_.objectToCanonical = glm::inverse(deformation * model);
    eye_.objectToProjection = eye_.objectToCanonical;
  }
  eye_.worldToCanonical = glm::inverse(eye_.canonicalToWorld);
  eye_.worldPerMm = std::cbrt(std::abs(glm::determinant(glm::dmat3(eye_.canonicalToWorld))));
  if (!(eye_.worldPerMm > 0) || !std::isfinite(eye_.worldPerMm) || !FiniteMatrix(eye_.worldToCanonical))
    throw std::runtime_error("eye mesh " + Id() + ": its transform or modelTransform is degenerate");
  // Turned inside out relative to the rest pose (a mirror deformation): its normals, computed from the
  // winding, now point in; the outward side flips back (EyeMeshOutwardNormal). A flat (zero-volume)
  // pose keeps its sign.
  eye_.outwardSign = 1;
  if (!rest.empty() && rest.size() == current.size()) {
    const double v0 = SignedVolume(rest, Layout().vertices), v1 = SignedVolume(current, Layout().vertices);
    if (v0 * v1 < 0) eye_.outwardSign = -1;
  }
}

}  // namespace hdeye
