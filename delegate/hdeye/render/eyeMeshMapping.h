#pragma once
// Where a ray's hit on an eye mesh lands on the analytic eye (canonical frame: mm, apex at the origin,
// gaze +z), and how its direction is carried there and back: the paper's re-projection of hits on an
// animated, deformed eye onto the analytic model through an artist-controlled iris projection
// (Chiang and Burley 2018, section 2; Pritchett and Lancaster 2006), from rest-pose positions.
//
// Re-projection (EyeGeometry::reprojection, the default), for a hit at barycentrics (u, v):
//  1. Position. The hit's barycentric REST point (primvar rest, else the current point) goes into the
//     iris projection frame (EyeGeometry::objectToProjection: the frame scaled so its [-1, 1]^2 square is
//     the 15.08 mm iris square) and is projected along the frame's z onto its xy plane: canonical (x, y).
//     The analytic surface gives z = f(r) and the normal. The rest point's depth along the frame's z
//     decides the back of the eyeball (below the iris plane: sclera); r past the outer limbus edge
//     (including a frame that does not cover the hit) is sclera too.
//  2. Direction. A local rotation R (world -> canonical) takes the deformed mesh's local frame at the hit
//     onto the analytic surface's frame at (x, y): the deformed shading normal onto the analytic normal,
//     and the triangle's tangent directions (its edges, rest-projected in the canonical frame and deformed
//     in the world) onto each other in the best least-squares sense (a 2-D Procrustes angle). Preserved:
//     the angle between the ray and the local surface normal (what Fresnel and Snell see, so reflections
//     and refraction follow the deformed surface's shading), and the ray's azimuth about that normal
//     relative to the surface's own texture directions (so a highlight does not spin as the eye
//     squashes). Not preserved: the world direction itself and the exact hit position inside the eye.
//  3. Back to world. Every ray that leaves (reflection at entry, exit refraction after the chamber walk)
//     leaves from the deformed hit point, its canonical direction turned by R^T: the eye behaves as a
//     local scattering function of the surface the camera sees. The iris's direct light (MNEE) stays in
//     the eye's rigid frame (the similarity nearest to prim transform x modelTransform), so the caustic
//     on the iris is the undeformed eye's whatever the mesh does.
//
// Baseline (reprojection off, for comparisons): the analytic eye carried by the mesh's best-fit affine
// deformation (rest -> current, fitted per sync): the current point maps through that affine frame, the
// world direction is pulled back by its linear part (normalised), and the whole chamber walk, MNEE
// included, runs in that frame. This is what putting the deformation into the eye's transform gives.
//
// Fallbacks (never NaN): a zero shading normal falls back to the triangle's outward normal, then to the
// analytic normal placed rigidly; degenerate edges give R with no tangent information (the rigid frame's
// x axis is used as the common tangent reference); a mesh turned inside out (negative signed volume
// relative to its rest pose) has its outward side flipped (EyeGeometry::outwardSign).
#include "hdeye/render/eyeGeometry.h"
#include "hdeye/render/renderContext.h"

namespace hdeye {

/// A hit on an eye mesh, in both frames.
struct EyeMeshHit {
  /// mm: where the hit projects in the canonical frame: (x, y) from the projection, z the rest point's
  /// depth along the projection's z (decides the back of the eyeball). Finite.
  glm::dvec3 canonicalPoint{0};
  glm::dvec3 worldPoint{0};   ///< the hit on the rendered triangle, world
  glm::dvec3 worldNormal{0};  ///< unit, outward: the triangle's geometric normal, world (else a fallback)
  bool fromOutside = true;    ///< the ray met the outside of the mesh
  /// The hit lies on the cornea's side of the outer limbus edge, in front of the iris plane: it continues
  /// against the analytic model from analyticPoint with canonicalDir. Otherwise it is sclera.
  bool onCornea = false;
  glm::dvec3 analyticPoint{0};         ///< mm, on the analytic surface at canonicalPoint's (x, y) (onCornea)
  glm::dvec3 analyticNormal{0, 0, 1};  ///< unit, outward, the analytic normal there (onCornea)
  /// Unit, incoming, canonical: dot(canonicalDir, analyticNormal) < 0 (onCornea).
  glm::dvec3 canonicalDir{0, 0, -1};
  /// Re-projection: the local rotation world -> canonical at this hit; leaving rays map back by its
  /// transpose. Unused for the baseline (its rays map through the eye's affine frame).
  glm::dmat3 worldToLocal{1.0};
  bool reprojected = false;  ///< which of the two mappings produced this hit
};

/// The triangle's geometric normal (object space, not normalised), turned outward: the side its
/// interpolated shading normal points to (which follows the winding and the mesh's handedness), flipped
/// when the eye mesh is turned inside out (EyeGeometry::outwardSign of context.meshEye). Shared by the
/// mapping and the eye mesh's Embree filter, so both decide "from inside" alike.
glm::dvec3 EyeMeshOutwardNormal(const GeometryContext& context, unsigned triangle);

/// Maps the hit at barycentrics (u, v) of rendered triangle `triangle` of an eye mesh, hit by a ray of
/// world direction `worldDir` (unit). `context` must carry points, triangleVertices and vertexNormals
/// (restPoints optional). Cost: about 0.6 us per hit with re-projection, 0.3 us for the baseline
/// (bench/bench_deformed_eye, docs/deformed_eyes.md).
EyeMeshHit EyeMeshHitToCanonical(const GeometryContext& context, const EyeGeometry& eye, unsigned triangle, double u,
                                 double v, const glm::dvec3& worldDir);

/// The world direction of a ray leaving a re-projected hit whose canonical direction is `canonicalDir`
/// (unit): R^T canonicalDir, bent just above the hit's tangent plane if the turn put it below (a
/// grazing exit). Unit and finite.
glm::dvec3 EyeMeshLeavingDirection(const EyeMeshHit& hit, const glm::dvec3& canonicalDir);

}  // namespace hdeye
