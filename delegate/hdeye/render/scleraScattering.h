#pragma once
// Sclera subsurface scattering for the eye shading code (docs/limbal_arc.md): a thin adapter that runs eyelib's random
// walk in the eye's canonical frame, so the limbal-arc teleportation cylinder follows the eye wherever it is and
// however it is turned, and hands back a world-space exit. The renderer supplies the eyeball's boundary as a
// world-space closest-hit callback; EyeMeshBoundary builds that callback from an eye mesh's own Embree scene.
//
// Called by the renderer (tracerScleraWalk.cpp, Tracer::ScleraWalk) for eye-mesh hits the eye shading classifies
// as sclera (and the sclera share of the limbus blend); docs/limbal_arc.md describes the integration.
#include "hdeye/render/eyeGeometry.h"

#include <embree3/rtcore.h>
#include <eyelib/function_ref.h>
#include <eyelib/random_walk_sss.h>

#include <cstdint>
#include <functional>

namespace hdeye {

/// The eyeball's boundary in world space: the closest crossing of origin + t * dir (dir unit),
/// 0 < t <= tMax (world units), writing *t and the geometric normal (unit, either orientation). It must
/// not report the surface the origin lies on at t ~ 0 (Embree: tnear from an error bound). A query it
/// cannot answer within its own bounds is reported by writing a non-finite *t (the walk then ends as
/// WalkStatus::Invalid, which the renderer counts).
using WorldBoundary =
    std::function<bool(const glm::dvec3& origin, const glm::dvec3& dir, double tMax, double* t, glm::dvec3* normal)>;

struct ScleraScatteringSettings {
  double ior = 1.376;     ///< sclera over outside
  double g = 0;           ///< Henyey-Greenstein asymmetry (the albedo inversion assumes 0)
  int maxSteps = 1024;    ///< every scattering, internal reflection and teleport counts
  bool limbalArc = true;  ///< the teleportation cylinder (diameter = the eye's outer limbus edge)
};

struct ScleraExit {
  eyelib::WalkStatus status = eyelib::WalkStatus::Invalid;
  glm::dvec3 origin{0.0};  ///< world, on the eyeball surface (Exited only)
  glm::dvec3 dir{0.0};     ///< world, unit, leaving the eyeball (Exited only)
  /// World, unit, the boundary's geometric normal at the exit, turned outward (dot(normal, dir) > 0).
  glm::dvec3 normal{0.0};
  glm::dvec3 weight{0.0};  ///< RGB throughput (Exited; the dropped weight when Capped)
  int steps = 0;
  int teleports = 0;
  bool teleported = false;  ///< the path lit the limbal arc (the `limbalArc` AOV)
  bool Exited() const { return status == eyelib::WalkStatus::Exited; }
};

/// One sclera walk. `entry` (world) is the hit on the eyeball, `inwardDir` (world, any length) the
/// direction already refracted into the sclera (entry Fresnel is the surface's job); `scleraColor` the
/// artist's albedo (RGB, [0, 1]) and `meanFreePathMm` the scattering distance in millimetres (RGB, the
/// eye's own unit whatever the scene's: worldPerMm converts). `random` gives uniforms in [0, 1).
/// Artist values eyelib::ValidateSssArtistParams rejects give an Invalid walk (no guessing).
ScleraExit ScatterInSclera(const EyeGeometry& eye, const glm::dvec3& entry, const glm::dvec3& inwardDir,
                           const glm::dvec3& scleraColor, const glm::dvec3& meanFreePathMm,
                           const WorldBoundary& boundary, eyelib::FunctionRef<double()> random,
                           const ScleraScatteringSettings& settings = {});

/// Where the last crossing an EyeMeshBoundary reported lies on the mesh: its rendered triangle and
/// barycentrics (for shading normals at a walk's exit, which is always the last crossing reported).
struct MeshCrossing {
  unsigned triangle = RTC_INVALID_GEOMETRY_ID;
  double u = 0, v = 0;
};

/// The boundary of one closed mesh, from its prototype scene (object space; Mesh::PrototypeScene, or
/// GeometryContext::prototypeScene) and its object-to-world transform, for walks inside it. `rays`
/// (optional) counts the Embree queries, `last` (optional) receives the last crossing reported.
///
/// Eye meshes carry an Embree filter that rejects hits from inside (the analytic model owns the inside
/// for every other ray), and a walk only ever meets its boundary from inside. So each query is cast
/// backwards: from the far end of the segment (clipped to the mesh's bounds) towards the origin, where
/// the filter sees a ray arriving from outside. The first such hit is the crossing farthest from the
/// origin; the query repeats past it (at most 8 times, for non-convex meshes) until none is left, and
/// the last is the closest. A mesh that needs more is reported (non-finite t), not guessed.
/// The surface the origin lies on is excluded by the filter itself (a walker leaving it moves inward,
/// so the backward ray meets it from inside) and, for neighbouring triangles at grazing angles, by a
/// tnear from the float rounding bound of the query's coordinates, not a fixed epsilon.
/// XXX: a flag in the eye mesh's filter (eyeMesh.cpp: accept inside hits for walk queries) would make
/// this one forward query; the backward cast costs one extra query only on non-convex meshes.
/// rayTime: the Embree ray time the walk happens at (a deforming mesh's points at that time; objectToWorld must be
/// the transform then).
WorldBoundary EyeMeshBoundary(RTCScene prototype, const glm::dmat4& objectToWorld, std::int64_t* rays = nullptr,
                              MeshCrossing* last = nullptr, float rayTime = 0);

}  // namespace hdeye
