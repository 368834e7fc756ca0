#pragma once
// What a camera path carries through the tracer (tracer.h): the surface hit at a vertex, the path's state from one
// vertex to the next, and what it brings back for the AOVs. Internal to the renderer.
#include "hdeye/render/cameraView.h"
#include "hdeye/render/eyeShading.h"
#include "hdeye/render/rayCone.h"
#include "hdeye/render/renderContext.h"
#include "hdeye/render/surfacePoint.h"

#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace hdeye {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Surfaces (cut-outs, thin walls) one path or shadow ray passes through at most; past that the surface counts as
/// there (a bound on the loop, far above any stack of cards a ray meets).
constexpr int kMaxCutoutCrossings = 64;

struct SurfaceHit {
  double t;
  glm::dvec3 p, n;   // n (the shading normal) faces the incoming ray
  glm::dvec3 ng{0};  // the geometric normal, facing the incoming ray
  glm::dvec3 albedo, emission;
  int primIndex;
  const GeometryContext* context;
  unsigned part;                              // the primitive; for eyes, EyeGeometry::Part
  double u = 0, v = 0;                        // barycentrics of the hit in triangle `part` (meshes)
  glm::dvec2 st{0};                           // the mesh's "st" primvar at the hit (0 where not authored)
  const SurfaceMaterial* material = nullptr;  // the material of the hit's face (geomSubsets), else the prim's
  StFrame stFrame;                            // dp/ds, dp/dt of the hit triangle (world), where st and points are known
  bool normalMapped = false;                  // n comes from a normal map (it may lean below the surface itself)
  const Vec3f* instanceColor = nullptr;       // the instancer's displayColor for the hit instance, or null
  int instanceIndex = 0;                      // the hit instance's index in its instancer (0: not instanced)
  float rayTime = 0;                          // the Embree ray time of the ray that hit (deforming meshes' normals)
  /// A still analytic eye's cornea hit as its intersection found it (ExactCorneaHit), else null.
  std::optional<CorneaPoint> cornea;
};

/// The eye a hit belongs to (analytic or mesh), or null.
inline const EyeGeometry* EyeOf(const GeometryContext& context) { return context.eye ? context.eye : context.meshEye; }

/// The absolute part of the spawn offsets off a geometry (SpawnOffset): an eye's own (EyeGeometry::SpawnScale),
/// so that eyes render alike in any scene units; 1 world unit for everything else.
inline double SpawnScaleOf(const GeometryContext& context) {
  const EyeGeometry* eye = EyeOf(context);
  return eye ? eye->SpawnScale() : 1.0;
}

/// An object-space shading normal carried to world space (not normalised), with its length. Degenerate (zero
/// or not finite) ones are not Valid: the caller keeps its geometric normal there.
struct WorldNormal {
  glm::dvec3 v;
  double length;
  WorldNormal(const glm::dmat3& normalToWorld, const glm::dvec3& local)
      : v(normalToWorld * local), length(glm::length(v)) {}
  bool Valid() const { return length > 1e-12 && std::isfinite(length); }
};

/// What the data AOVs show of the first surface a camera path met (a copy of the whole hit would cost more). Left
/// unset until Set: it is read only when the path met a surface, and zeroing it with the rest of PathSample cost
/// a 144-byte clear (rep stos) per camera path.
struct FirstHit {
  double t;              ///< distance along the camera ray
  glm::dvec3 n, albedo;  ///< the shading normal and the albedo shaded there
  int primIndex;
  int instanceIndex;  ///< for the hitId AOV (cryptomatte): which instance of the prim
  int subset;         ///< the hit face's materialBind subset (-1: the prim's own material), for the hitId AOV
  /// Field by field: assigning a temporary FirstHit stalls on its reload (store forwarding) in the path loop.
  void Set(const SurfaceHit& hit) {
    t = hit.t, n = hit.n, albedo = hit.albedo, primIndex = hit.primIndex, instanceIndex = hit.instanceIndex;
    subset = hit.context->triangleSubsets && hit.part < hit.context->triangleSubsets->size()
                 ? (*hit.context->triangleSubsets)[hit.part]
                 : -1;
  }
};

/// The eye AOVs: a path's radiance by the first eye event on its way (the glint a reflection off the cornea at entry,
/// the iris everything after a refraction into the cornea, the sclera everything after a hit on it; nonEye what came
/// before any eye event, or with none), and the limbal arc: everything after the path's first teleported sclera walk.
enum EyePart { kNonEye, kGlint, kIris, kSclera, kLimbalArc, kEyeParts };

/// What one camera path brings back: its radiance, the parts of it the AOVs split out, and the first surface
/// it met (for the data AOVs).
struct PathSample {
  glm::dvec3 L{0};
  glm::dvec3 irisMnee{0};  ///< the part that came to an iris through MNEE
  /// L split by where it came from (EyePart): the parts sum to L.
  std::array<glm::dvec3, kEyeParts> parts{};
  bool hitAny = false;  ///< the camera ray met geometry
  FirstHit first;       ///< that first hit (its albedo the one shaded); set (and read) only when hitAny
};

/// What a camera path does with the reflection off the cornea where it splits (EyeLighting::splitAtEntry) at its first
/// eye event: traces it beside the walk; leaves it out (the main path of a catchlight pixel, whose sub-samples bring
/// it: RenderSettings::catchlightSamples); or traces it alone (such a sub-sample: nothing else it meets counts, and
/// it ends at that eye event, or at the first bounce off a delta chain before it).
enum class CameraReflection { Traced, Left, Only };

/// What a path carries from one vertex to the next.
struct PathState {
  PathState(const WorldRay& ray, const RayCone& cameraCone)
      : o(ray.origin), d(ray.dir), tNear(ray.tNear), tFar(ray.tFar), cone(cameraCone) {}

  glm::dvec3 o, d;  ///< the next ray
  double tNear, tFar;
  RayCone cone;             ///< the next ray's footprint (rayCone.h), for texture filtering
  int cutoutCrossings = 0;  ///< cut-outs the path has passed through (bounded by kMaxCutoutCrossings)
  glm::dvec3 beta{1};
  // How the current ray was chosen, for weighting the lights it meets: after a specular event (the camera,
  // the cornea) a light counts in full; after a diffuse bounce, by MIS against light sampling (or not at all
  // without MIS); straight out of an iris (skipMnee), the lights MNEE counted there not at all, and every
  // other light in full. Why in full and not by MIS: the iris bounce's cosine-hemisphere pdf exists, but for
  // a light MNEE does not handle there is no second strategy at the iris (light sampling cannot see through
  // the refracting cornea; that is what MNEE is for), so the path leaving the iris is that light's only
  // estimator and its weight is 1. Nor is MNEE MIS-weighted against the exiting path for the lights it does
  // handle: its one-solution search has no known pdf over exit directions, so the two are a partition, light
  // by light, never a mixture.
  bool specular = true, skipLights = false, skipMnee = false;
  /// The path has not yet split at a cornea (EyeLighting::splitAtEntry): only the camera's specular chain splits,
  /// at the first cornea it meets, so a sample traces at most two paths. Cleared by the split and by the first
  /// bounce that is not a delta one.
  bool splitsAtCornea = true;
  CameraReflection cameraReflection = CameraReflection::Traced;
  int fromPrim = -1;        ///< primIndex of the vertex the current ray left (-1: the camera), for light linking
  double bsdfPdf = 0;       ///< the pdf the current ray was sampled with (after a diffuse bounce)
  EyeLighting eyeLighting;  ///< the lights and switches of the eye last met
  EyeLighting skipMneeOf;   ///< skipMnee: the lighting of the iris the path left (its MNEE lights)
  /// The analytic eye whose cornea the current ray leaves outwards (EyeRayExchange::leaving), or null.
  const EyeGeometry* leavingEye = nullptr;
  // Whether the path is inside a glass (opacity < 1) object: flipped at every refraction. Hits carry no
  // front/back flag, so this assumes the camera is outside and glass objects are closed and do not nest.
  bool insideGlass = false;
  // The eye AOV (EyePart) the path's radiance goes to from now on, and the sample's L when it last moved the path's
  // light to its part.
  EyePart part = kNonEye;
  glm::dvec3 lMark{0};

  /// The next ray starts at `origin` along unit `dir`, unbounded.
  void SetRay(const glm::dvec3& origin, const glm::dvec3& dir) {
    o = origin, d = dir, tNear = 0, tFar = kInf, leavingEye = nullptr;
  }
  /// What the sample gathered since the last mark goes to the path's part; from now on the path's light goes to `next`.
  void SwitchPart(EyePart next, PathSample* sample) {
    sample->parts[part] += sample->L - lMark;
    lMark = sample->L;
    part = next;
  }
  /// After a delta event: lights the ray meets count in full.
  void SetSpecular() { specular = true, skipLights = false, skipMnee = false; }
  /// The same ray goes on from just past a cut-out it met at distance t, point p: not a bounce.
  void PassCutout(double t, const glm::dvec3& p) {
    const double step = t + SpawnOffset(p);
    o += d * step;
    if (tFar < kInf) tFar -= step;
    cone.width = cone.WidthAt(step);
    tNear = 0;
  }
};

/// What the integrator does with a hit after the eye shaded it.
enum class EyeOutcome { Continue, End, ShadeSurface };

}  // namespace hdeye
