#pragma once
// Where a ray's hit on an eye mesh lands in the eye's canonical frame (mm, apex at the origin, gaze
// +z). This is the one function a deformable-eye change swaps: today the mapping is rigid (the hit's
// rest point, else its current point, through the inverse of EyeParams::modelTransform); the paper's
// artist-controlled iris projection from rest-pose positions (issue 7) replaces it here, and nothing
// downstream changes.
#include "hdeye/eyeGeometry.h"
#include "hdeye/renderContext.h"

namespace hdeye {

/// A hit on an eye mesh, in both frames.
struct EyeMeshHit {
  glm::dvec3 canonicalPoint{0};   ///< mm: where the hit maps in the canonical frame (decides the region)
  glm::dvec3 canonicalNormal{0};  ///< unit, outward: the mesh's shading normal at the hit, canonical frame
  glm::dvec3 worldPoint{0};       ///< the hit on the rendered triangle, world
  glm::dvec3 worldNormal{0};      ///< unit, outward: the triangle's geometric normal, world
  bool fromOutside = true;        ///< the ray met the outside of the mesh
};

/// The triangle's geometric normal (object space, not normalised), turned outward: the side its
/// interpolated shading normal points to (which follows the winding and the mesh's handedness).
/// Shared by the mapping and the eye mesh's Embree filter, so both decide "from inside" alike.
glm::dvec3 EyeMeshOutwardNormal(const GeometryContext& context, unsigned triangle);

/// Maps the hit at barycentrics (u, v) of rendered triangle `triangle` of an eye mesh, hit by a ray of
/// world direction `worldDir`. `context` must carry points, triangleVertices and vertexNormals.
EyeMeshHit EyeMeshHitToCanonical(const GeometryContext& context, const EyeGeometry& eye, unsigned triangle,
                                 double u, double v, const glm::dvec3& worldDir);

}  // namespace hdeye
