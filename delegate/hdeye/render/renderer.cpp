#include "hdeye/render/renderer.h"

#include "hdeye/render/chamberLightCache.h"
#include "hdeye/render/eyeShading.h"
#include "hdeye/render/materialShading.h"
#include "hdeye/render/movingLights.h"
#include "hdeye/render/previewSurface.h"
#include "hdeye/render/rayCone.h"
#include "hdeye/render/renderContext.h"
#include "hdeye/render/sampleStream.h"
#include "hdeye/render/scleraScattering.h"
#include "hdeye/render/surfacePoint.h"
#include "hdeye/render/texture.h"
#include "hdeye/render/thinWalls.h"

#include <eyelib/optics.h>
#include <eyelib/sampling.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <type_traits>

namespace hdeye {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTile = 16;
/// The frame time of pixel sample `sample`'s camera path in the camera's shutter (frames): a closed shutter's time
/// (no random number drawn, so sharp renders are unchanged), stratum `sample mod timeStrata`'s centre, or one more
/// sample dimension counted from the top (after the lens's two). The one place the path time is drawn: a sampler that
/// replaces SampleStream re-maps this dimension here.
double PathTime(const Shutter& shutter, int timeStrata, std::uint64_t sample, SampleStream& rng) {
  if (!shutter.IsOpen()) return shutter.open;
  const double span = shutter.close - shutter.open;
  if (timeStrata > 0) return shutter.open + span * (double(sample % std::uint64_t(timeStrata)) + 0.5) / timeStrata;
  return shutter.open + span * rng.FromTop(2);
}

/// a^2 / (a^2 + b^2), as a ratio so that pdfs past 1e154 (a tiny light far away) do not overflow.
double PowerHeuristic(double a, double b) {
  if (!(a > 0)) return 0;
  const double q = b / a;
  return std::isfinite(q) ? 1 / (1 + q * q) : 0;
}

/// Surfaces (cut-outs, thin walls) one path or shadow ray passes through at most; past that the surface counts as
/// there (a bound on the loop, far above any stack of cards a ray meets).
constexpr int kMaxCutoutCrossings = 64;

/// The material of triangle (or primitive) `part` of a geometry: its geomSubset's, else the prim's own.
const SurfaceMaterial& MaterialAt(const GeometryContext& context, unsigned part) {
  if (context.triangleSubsets && part < context.triangleSubsets->size()) {
    const int subset = (*context.triangleSubsets)[part];
    if (subset >= 0 && std::size_t(subset) < context.subsetMaterials.size()) return context.subsetMaterials[subset];
  }
  return context.surface;
}

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
};

/// The eye a hit belongs to (analytic or mesh), or null.
const EyeGeometry* EyeOf(const GeometryContext& context) { return context.eye ? context.eye : context.meshEye; }

/// The absolute part of the spawn offsets off a geometry (SpawnOffset): an eye's own (EyeGeometry::SpawnScale),
/// so that eyes render alike in any scene units; 1 world unit for everything else.
double SpawnScaleOf(const GeometryContext& context) {
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

/// The switches one eye renders with: the render plan's (EyeRenderOptions, written by ApplyRenderPlan), else
/// the render settings' and the eye's own EyeParams::limbalArc.
struct EyeSwitches {
  bool mnee = true, allSolutions = false;
  const std::vector<bool>* mneeLights = nullptr;  ///< null: MNEE counts every light
  int maxChamberEvents = 64;
  bool scleraScattering = true, limbalArc = true;
};

EyeSwitches ResolveEyeSwitches(const EyeRenderOptions& options, const EyeGeometry& eye,
                               const RenderSettings& settings) {
  if (options.planned)
    return {
        options.mnee,     options.allSolutions, &options.mneeLights, options.maxChamberEvents, options.scleraScattering,
        options.limbalArc};
  static const EyeRenderOptions kUnplanned;  // the walk bound of an eye no plan was applied to
  return {settings.mnee, settings.mneeAllSolutions, nullptr, kUnplanned.maxChamberEvents, settings.scleraScattering,
          eye.limbalArc};
}

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
  /// at the first cornea it meets, so a sample traces at most two paths.
  bool splitsAtCornea = true;
  int fromPrim = -1;        ///< primIndex of the vertex the current ray left (-1: the camera), for light linking
  double bsdfPdf = 0;       ///< the pdf the current ray was sampled with (after a diffuse bounce)
  EyeLighting eyeLighting;  ///< the lights and switches of the eye last met
  EyeLighting skipMneeOf;   ///< skipMnee: the lighting of the iris the path left (its MNEE lights)
  // Whether the path is inside a glass (opacity < 1) object: flipped at every refraction. Hits carry no
  // front/back flag, so this assumes the camera is outside and glass objects are closed and do not nest.
  bool insideGlass = false;
  // The eye AOV (EyePart) the path's radiance goes to from now on, and the sample's L when it last moved the path's
  // light to its part.
  EyePart part = kNonEye;
  glm::dvec3 lMark{0};

  /// The next ray starts at `origin` along unit `dir`, unbounded.
  void SetRay(const glm::dvec3& origin, const glm::dvec3& dir) { o = origin, d = dir, tNear = 0, tFar = kInf; }
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

class Tracer {
 public:
  /// Counters a tracer keeps while it renders (RenderStats' rays and sclera walks).
  struct Counts {
    std::int64_t rays = 0, walks = 0, teleportedWalks = 0, cappedWalks = 0, invalidWalks = 0;
  };

  /// cutouts: some material has an opacityThreshold, so shadow rays must look at what they meet.
  /// shutter: the camera's (the Embree ray time of each path's time).
  /// chamberCaches: the eyes' chamber light (RenderSettings::chamberEstimator), or null.
  Tracer(RTCScene scene, const std::vector<RenderLight>& lights, const RenderSettings& settings, bool cutouts,
         const Shutter& shutter, ChamberLightCaches* chamberCaches = nullptr)
      : scene_(scene),
        sourceLights_(lights),
        lightsNow_(AnyLightMoves(lights) ? lights : std::vector<RenderLight>{}),
        lights_(AnyLightMoves(lights) ? lightsNow_ : lights),
        shutter_(shutter),
        settings_(settings),
        cutouts_(cutouts),
        chamberCaches_(chamberCaches),
        textureThread_(CurrentTextureThread()) {}

  /// Radiance along a camera ray (pbrt's PathIntegrator::Li): per vertex, the lights the ray meets, the
  /// surface's emission, the eye (if it is one), direct light (SampleLd) and the BSDF-sampled continuation.
  /// cone: the camera ray's footprint, carried along the path for texture filtering.
  /// time: the path's, frames (PathTime): rays meet the geometry, lights and eyes as they are then.
  PathSample Li(const WorldRay& ray, const RayCone& cone, SampleStream& rng, double time) {
    SetTime(time);
    PathSample sample;
    // Referred to (not copied) by the path's EyeLighting, so it lives as long as the path.
    const auto transmittance = [this](std::size_t k, const glm::dvec3& po, const glm::dvec3& pd, double t) {
      return Transmittance(lights_[k], po, pd, t);
    };
    PathState path(ray, cone);
    path.eyeLighting = EyeLighting{&lights_, transmittance, -1, settings_.mneeAllSolutions, settings_.mnee};
    TracePath(&path, 0, rng, &sample);
    return sample;
  }

  const Counts& GetCounts() const { return counts_; }

 private:
  /// The path's vertices from `firstDepth` on (0: the camera ray), adding what it gathers to *sample (and, at depth
  /// 0, the first hit's data). A branch split off at a cornea (ShadeEyeHit) goes through here on its own.
  void TracePath(PathState* pathState, int firstDepth, SampleStream& rng, PathSample* samplePtr) {
    PathState& path = *pathState;
    PathSample& sample = *samplePtr;
    for (int depth = firstDepth; depth <= settings_.maxDepth; ++depth) {
      SurfaceHit hit;
      const bool hitGeometry = Intersect(path.o, path.d, path.tNear, path.tFar, &hit);
      if (depth == 0) {
        sample.hitAny = hitGeometry;
        if (hitGeometry) sample.first.Set(hit);
      }
      const bool hideDomes = depth == 0 && !settings_.domeLightCameraVisibility;  // usdrecord's default look
      sample.L += LightsMet(path, hitGeometry ? hit.t : kInf, hideDomes);
      if (!hitGeometry) break;
      // Initialised in place (not assigned): a copy of the whole shading per vertex costs more than it seems.
      const bool eyeHit = EyeOf(*hit.context) != nullptr;
      SurfaceShading shading = eyeHit ? SurfaceShading{} : ShadeMaterialHit(&hit, path.d, path.cone);
      if (!eyeHit) {
        if (!shading.present && path.cutoutCrossings++ < kMaxCutoutCrossings) {
          // A cut-out: lights behind it were not yet tested; the next segment tests them, with this ray's weights.
          path.PassCutout(hit.t, hit.p);
          --depth;
          continue;
        }
        if (depth == 0) sample.first.n = hit.n;  // the normal AOV shows the normal map
      }
      path.fromPrim = hit.primIndex;  // the next ray leaves this vertex (light linking)
      sample.L += path.beta * hit.emission;
      if (const EyeGeometry* eye = EyeOf(*hit.context)) {
        rng.AlignToPair();  // the eye draws whole pairs (EyeLighting)
        // A moving eye is shaded with its frames at the path's time (where the ray met it).
        const std::optional<EyeGeometry> moved = eye->motion ? std::optional(eye->AtTime(time_)) : std::nullopt;
        const EyeOutcome outcome = ShadeEyeHit(moved ? *moved : *eye, depth, rng, &hit, &path, &sample);
        if (outcome == EyeOutcome::Continue) continue;
        if (outcome == EyeOutcome::End) break;
      }
      // Sclera (and any eye surface handed back to us) is Lambertian; everything else is the bound
      // UsdPreviewSurface.
      const bool eyeSurface = EyeOf(*hit.context) != nullptr;
      if (eyeSurface) shading.bsdf = PreviewSurface::Lambert(hit.albedo);  // an eye hit's shading is unused
      const PreviewSurface& bsdf = shading.bsdf;
      if (depth == 0 && !eyeSurface) sample.first.albedo = bsdf.albedo;  // the albedo AOV shows the texture
      const glm::dvec3 origin = SpawnOrigin(hit.p, hit.n, SpawnScaleOf(*hit.context));
      const PreviewSurfaceAt bsdfAt(bsdf, hit.n, -path.d);  // wo's Fresnel and lobes, shared by both
      sample.L += SampleLd(hit, bsdfAt, origin, path.beta, rng);
      if (!SampleContinuation(hit, bsdf, bsdfAt, origin, depth, rng, &path)) break;
    }
    path.SwitchPart(path.part, &sample);
  }

  /// The path's time: Embree's ray time, and the moving lights moved to it.
  void SetTime(double time) {
    time_ = time;
    rayTime_ = shutter_.RayTime(time);
    if (&lights_ == &lightsNow_)
      for (std::size_t k = 0; k < sourceLights_.size(); ++k) MoveLightTo(sourceLights_[k], time, &lightsNow_[k]);
  }

  /// Closest hit of the scene's geometry along the ray, if any.
  bool Intersect(const glm::dvec3& o, const glm::dvec3& d, double tNear, double tFar, SurfaceHit* hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = float(o.x), rh.ray.org_y = float(o.y), rh.ray.org_z = float(o.z);
    rh.ray.dir_x = float(d.x), rh.ray.dir_y = float(d.y), rh.ray.dir_z = float(d.z);
    rh.ray.tnear = float(tNear);
    rh.ray.tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u, rh.ray.flags = 0, rh.ray.time = rayTime_;
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    ++counts_.rays;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    // Meshes sit under instances (user data: an InstanceContext, one per instance); analytic eyes are user
    // geometry in the root scene (user data: their GeometryContext).
    const GeometryContext* ctx;
    const InstanceContext* instance = nullptr;
    if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
      instance = static_cast<const InstanceContext*>(rtcGetGeometryUserData(rtcGetGeometry(scene_, rh.hit.instID[0])));
      ctx = instance->geometry;
    } else {
      ctx = static_cast<const GeometryContext*>(rtcGetGeometryUserData(rtcGetGeometry(scene_, rh.hit.geomID)));
    }
    // The hit instance's object-to-world normal matrix; a moving instance's at the ray's time, as Embree placed it.
    glm::dmat3 moved;
    if (instance && instance->motion) moved = glm::transpose(glm::inverse(glm::dmat3(instance->motion->At(time_))));
    const glm::dmat3& normalToWorld =
        instance ? (instance->motion ? moved : instance->normalToWorld) : ctx->normalToWorld;
    hit->instanceColor = instance && instance->hasColor ? &instance->color : nullptr;
    hit->instanceIndex = instance ? instance->instanceIndex : 0;
    hit->t = rh.ray.tfar;
    hit->p = o + hit->t * d;
    const glm::dvec3 ng = normalToWorld * glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    // Normalised by one reciprocal square root, its sign (towards the ray's origin) folded into the same factor.
    const double scale = 1 / std::sqrt(glm::dot(ng, ng));
    const glm::dvec3 n = ng * (glm::dot(ng, d) > 0 ? -scale : scale);
    hit->ng = n;
    hit->u = rh.hit.u, hit->v = rh.hit.v;
    hit->part = rh.hit.primID;
    hit->context = ctx;
    hit->rayTime = rayTime_;
    FillPrimvars(normalToWorld, hit);
    return true;
  }

  /// The hit's shading normal, st, albedo and emission from its geometry's primvars: per-vertex values
  /// (triangleVertices) or per-corner ones (3 per triangle), weighted by the hit's barycentrics; object-space normals
  /// and st derivatives carried to world space by the hit instance's `normalToWorld`.
  static void FillPrimvars(const glm::dmat3& normalToWorld, SurfaceHit* hit) {
    const GeometryContext& ctx = *hit->context;
    const double bu = hit->u, bv = hit->v, bw = 1 - bu - bv;
    const std::size_t firstCorner = 3 * std::size_t(hit->part);
    auto atCorners = [&](const auto& values) {
      using D = glm::vec<std::decay_t<decltype(values[0])>::length(), double>;
      return bw * D(values[firstCorner]) + bu * D(values[firstCorner + 1]) + bv * D(values[firstCorner + 2]);
    };
    // Smooth shading: authored corner normals, else the per-vertex normals, interpolated. The flat
    // geometric normal still decides the side: the shading normal is flipped onto the side the ray came
    // from, so the renderer's cosines (taken against hit->n and clamped at 0) stay on the lit side.
    // Analytic eyes, meshes without normals and degenerate (zero) normals keep the flat one.
    glm::dvec3 local(0);
    if (ctx.cornerNormals) {
      local = glm::dvec3(atCorners(*ctx.cornerNormals));
    } else if (ctx.vertexNormals && ctx.triangleVertices && !ctx.eye) {
      local = VertexNormalAt(ctx, &(*ctx.triangleVertices)[firstCorner], bu, bv, hit->rayTime);
    }
    const WorldNormal shading(normalToWorld, local);
    hit->n = !shading.Valid() ? hit->ng : shading.v * ((glm::dot(shading.v, hit->ng) < 0 ? -1 : 1) / shading.length);
    hit->st = ctx.st ? glm::dvec2(atCorners(*ctx.st)) : glm::dvec2(0);
    if (ctx.st && ctx.points && ctx.triangleVertices && !ctx.eye)
      hit->stFrame = TriangleStFrameAt(ctx, normalToWorld, firstCorner);
    hit->material = &MaterialAt(ctx, hit->part);
    // displayColor (the prim's, or its instancer's per instance) is the fallback surface's colour (Hydra's), and that
    // of a material whose diffuseColor reads it; any other bound material shows its own.
    const MaterialParams& params = hit->material->params;
    hit->albedo = hit->material->bound && !params.diffuseFromDisplayColor ? glm::dvec3(params.diffuseColor)
                  : hit->instanceColor                                    ? glm::dvec3(*hit->instanceColor)
                  : ctx.displayColor                                      ? glm::dvec3(atCorners(*ctx.displayColor))
                                                                          : glm::dvec3(params.diffuseColor);
    hit->emission = EyeOf(ctx) ? glm::dvec3(0) : glm::dvec3(params.emissiveColor);
    hit->primIndex = ctx.primIndex;
  }

  /// The interpolated vertex normal at barycentrics (u, v) of triangle `tri`, object space; for a deforming mesh
  /// blended between the two time steps around Embree ray time `rayTime`, as Embree blends the positions.
  static glm::dvec3 VertexNormalAt(const GeometryContext& ctx, const int* tri, double u, double v, float rayTime) {
    const glm::dvec3 first = InterpolateAtTriangle(*ctx.vertexNormals, tri, u, v);
    if (!ctx.laterStepNormals || ctx.laterStepNormals->empty()) return first;
    const std::size_t segments = ctx.laterStepNormals->size();
    const double f = std::clamp(double(rayTime), 0.0, 1.0) * double(segments);
    const std::size_t i = std::min(segments - 1, std::size_t(f));
    const double w = f - double(i);
    auto at = [&](std::size_t step) {
      return step == 0 ? first : InterpolateAtTriangle((*ctx.laterStepNormals)[step - 1], tri, u, v);
    };
    return (1 - w) * at(i) + w * at(i + 1);
  }

  /// dp/ds, dp/dt (world) of the mesh triangle whose corners start at `firstCorner`, placed by the hit instance's
  /// `normalToWorld` (an instanced mesh's own context holds its prototype's transform only).
  static StFrame TriangleStFrameAt(const GeometryContext& ctx, const glm::dmat3& normalToWorld,
                                   std::size_t firstCorner) {
    const int* tri = &(*ctx.triangleVertices)[firstCorner];
    const glm::dmat3 toWorld = glm::inverse(glm::transpose(normalToWorld));  // the instance's linear part
    const auto& pts = *ctx.points;
    const auto& st = *ctx.st;
    return TriangleStFrame(toWorld * glm::dvec3(pts[tri[0]]), toWorld * glm::dvec3(pts[tri[1]]),
                           toWorld * glm::dvec3(pts[tri[2]]), glm::dvec2(st[firstCorner]),
                           glm::dvec2(st[firstCorner + 1]), glm::dvec2(st[firstCorner + 2]));
  }

  /// Where a non-eye hit's textures are looked up: its st, filtered over the cone's footprint there (unless
  /// RenderSettings::textureFiltering is off).
  TextureSite SiteOf(const SurfaceHit& hit, const glm::dvec3& d, const RayCone& cone) const {
    TextureSite site;
    site.st = hit.st;
    site.frame = hit.stFrame;
    if (settings_.textureFiltering && hit.material->textures)  // only textured inputs look at the footprint
      site.footprint = FootprintOnSurface(cone.WidthAt(hit.t), d, hit.ng, hit.stFrame);
    site.thread = textureThread_;
    return site;
  }

  /// The bound material at a non-eye hit (materialShading.h); the hit takes its emission and shading normal.
  SurfaceShading ShadeMaterialHit(SurfaceHit* hit, const glm::dvec3& d, const RayCone& cone) const {
    SurfaceShading shading = ShadeMaterial(*hit->material, hit->albedo, -d, hit->n, SiteOf(*hit, d, cone));
    shading.bsdf.thinWalled = hit->context->thinWalled;
    hit->emission = shading.emission;
    hit->n = shading.normal;
    hit->normalMapped = shading.normalMapped;
    return shading;
  }

  /// The fraction of `light` that passes from o along unit d to tFar: 0 behind a surface that casts its shadow,
  /// else the product of the thin walls crossed (thinWalls.h); opacityThreshold cut-outs let it through where
  /// they are cut away. Without shadow linking one any-hit query that skips thin walls decides, and only if it
  /// met one (or, in a scene with cut-outs, anything) are the surfaces crossed in order (CrossSurfaces); with
  /// shadow linking they are crossed at once.
  double Transmittance(const RenderLight& light, const glm::dvec3& o, const glm::dvec3& d, double tFar) const {
    if (!light.unshadowed.empty()) return CrossSurfaces(light, o, d, tFar);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = float(o.x), ray.org_y = float(o.y), ray.org_z = float(o.z);
    ray.dir_x = float(d.x), ray.dir_y = float(d.y), ray.dir_z = float(d.z);
    ray.tnear = 0;
    ray.tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
    ray.mask = ~0u, ray.flags = 0, ray.time = rayTime_;
    ThinWallsMet::Reset();
    rtcOccluded1(scene_, &context, &ray);
    ++counts_.rays;
    const bool blocked = ray.tfar < 0;
    if (blocked && !cutouts_) return 0;
    if (!blocked && !ThinWallsMet::Any()) return 1;
    return CrossSurfaces(light, o, d, tFar);
  }

  /// Transmittance by walking the surfaces from o along d to tFar in order: a surface the light's shadow linking
  /// leaves out passes, as do cut-away parts of cut-outs; thin walls attenuate, anything else blocks. At most
  /// kMaxCutoutCrossings surfaces; more count as opaque (light never leaks through a thick stack).
  double CrossSurfaces(const RenderLight& light, const glm::dvec3& o, const glm::dvec3& d, double tFar) const {
    double transmittance = 1, left = tFar;
    glm::dvec3 origin = o;
    for (int crossed = 0; crossed < kMaxCutoutCrossings; ++crossed) {
      SurfaceHit hit;
      if (!Intersect(origin, d, 0, left, &hit)) return transmittance;
      if (CastsShadow(light, hit.primIndex) && !CutAway(hit, d)) {
        if (!IsThinWall(*hit.context)) return 0;  // an eye or an opaque surface
        transmittance *= ThinWallTransmittance(*hit.context, glm::dot(hit.ng, d));
        if (!(transmittance > 0)) return 0;
      }
      const glm::dvec3 next = SpawnOrigin(hit.p, -hit.ng);  // ng faces the ray: -ng is the far side
      left -= glm::length(next - origin);
      if (!(left > 0)) return transmittance;
      origin = next;
    }
    return 0;
  }

  /// Whether a ray along d passes a hit because its material is cut away there (opacityThreshold).
  bool CutAway(const SurfaceHit& hit, const glm::dvec3& d) const {
    return cutouts_ && !EyeOf(*hit.context) && hit.material->params.opacityThreshold > 0 &&
           !ShadeMaterial(*hit.material, hit.albedo, -d, hit.n, SiteOf(hit, d, RayCone{})).present;
  }

  /// The nearest light surface a ray meets before maxDistance (for BSDF-sampled rays), with its pdf.
  /// skipMneeOf: the ray left an iris straight through the cornea; the lights MNEE counted there
  /// (MneeCountsLight) are passed over as if absent -- MNEE's own shadow rays treat lights as transparent,
  /// so a light behind one of them (a dome behind a key) is counted here as MNEE would not.
  /// minDistance: lights nearer than this were met before (a ray continued past a thin wall starts there).
  /// skipDomes: dome lights are passed over (camera rays, when RenderSettings::domeLightCameraVisibility is off).
  /// fromPrim: the rprim the ray left; lights linked away from it are passed over.
  bool HitLight(const glm::dvec3& o, const glm::dvec3& d, double minDistance, double maxDistance, glm::dvec3* radiance,
                double* pdf, const EyeLighting* skipMneeOf, bool skipDomes, int fromPrim) const {
    double best = kInf;
    bool found = false;
    for (std::size_t k = 0; k < lights_.size(); ++k) {
      if (skipMneeOf && MneeCountsLight(*skipMneeOf, k)) continue;
      if (skipDomes && lights_[k].type == LightType::Dome) continue;
      const RenderLight& l = lights_[k];
      if (skipDomes && l.type == LightType::Dome) continue;
      if (!Illuminates(l, fromPrim)) continue;
      glm::dvec3 le(0);
      double lpdf = 0, dist = kInf;
      if (IntersectLight(l, o, d, std::min(maxDistance, best), &le, &lpdf, &dist) && dist >= minDistance &&
          (!found || dist < best)) {
        best = dist, *radiance = le, *pdf = lpdf, found = true;
      }
    }
    return found;
  }

  /// The light the path's current ray meets before `maxDistance` (the geometry it hits), weighted by how the
  /// ray was chosen (PathState's flags); hideDomes: dome lights are not met.
  glm::dvec3 LightsMet(const PathState& path, double maxDistance, bool hideDomes) const {
    glm::dvec3 le(0);
    double lpdf = 0;
    if (path.skipLights || !HitLight(path.o, path.d, path.tNear, maxDistance, &le, &lpdf,
                                     path.skipMnee ? &path.skipMneeOf : nullptr, hideDomes, path.fromPrim))
      return glm::dvec3(0);
    if (path.specular) return path.beta * le;
    if (settings_.mis) return path.beta * le * PowerHeuristic(path.bsdfPdf, lpdf * LightSelectPdf());
    return glm::dvec3(0);
  }

  /// The probability of picking any one light for next event estimation (uniform).
  double LightSelectPdf() const { return lights_.empty() ? 0 : 1.0 / double(lights_.size()); }

  /// MNEE's light choice at the eye of `ctx` (MneeLightPick), from the eye and the lights as they stand still (so
  /// that it, and a chamber cache built with it, does not depend on which path asked first); the last eye's is kept.
  const std::vector<double>& MneePickOf(const GeometryContext& ctx, const EyeLighting& lighting) {
    LastMneePick& last = lastMneePick_;
    if (last.ctx != &ctx || last.receiver != lighting.receiver || last.mask != lighting.mneeLights) {
      EyeLighting still = lighting;
      still.lights = &sourceLights_;
      last = {&ctx, lighting.receiver, lighting.mneeLights, MneeLightPick(*EyeOf(ctx), still)};
    }
    return last.pick;
  }

  /// The eye's chamber-light cache (RenderSettings::chamberEstimator): one per render whatever the path's time.
  /// Under an open shutter it is built from the eye, the lights and the shadow rays at the shutter's opening, so
  /// which path builds it (thread count, sample split) never changes it; the control variate stays unbiased for
  /// an eye or light that moves, the cache alone then shows them where they were at the opening.
  std::shared_ptr<const eyelib::IrisChamberCache> ChamberCacheOf(const GeometryContext& ctx, const EyeGeometry& eye,
                                                                 const EyeLighting& lighting) {
    // Successive eye hits are mostly the same eye's: the last cache is kept so that they skip the shared map's
    // lock and key (and, under an open shutter, moving the lights to the opening and back).
    const EyeGeometry& still = shutter_.IsOpen() ? *EyeOf(ctx) : eye;
    LastChamberCache& last = lastChamberCache_;
    if (last.cache && last.ctx == &ctx && last.receiver == lighting.receiver && last.frame == still.canonicalToWorld)
      return last.cache;
    const int rings = ctx.eyeOptions.planned ? ctx.eyeOptions.chamberCacheRings : 0;
    // The build's shadow rays, on whichever thread joins it: a tracer of that thread's own, at this path's time.
    std::atomic<std::int64_t> buildRays{0};
    const auto perThread = [&](eyelib::FunctionRef<void(const EyeLighting&)> body) {
      Tracer here(scene_, sourceLights_, settings_, cutouts_, shutter_);
      here.SetTime(time_);
      const auto transmittance = [&here](std::size_t k, const glm::dvec3& o, const glm::dvec3& d, double t) {
        return here.Transmittance(here.lights_[k], o, d, t);
      };
      EyeLighting own = lighting;
      own.lights = &here.lights_;
      own.transmittance = transmittance;
      body(own);
      buildRays += here.counts_.rays;
    };
    std::shared_ptr<const eyelib::IrisChamberCache> cache;
    if (!shutter_.IsOpen()) {
      cache = chamberCaches_->Get(&ctx, eye, lighting, rings, perThread);
    } else {
      const double pathTime = time_;
      SetTime(shutter_.open);
      const std::optional<EyeGeometry> atOpen =
          still.motion ? std::optional(still.AtTime(shutter_.open)) : std::nullopt;
      cache = chamberCaches_->Get(&ctx, atOpen ? *atOpen : still, lighting, rings, perThread);
      SetTime(pathTime);
    }
    counts_.rays += buildRays;
    last = {&ctx, lighting.receiver, still.canonicalToWorld, cache};
    return cache;
  }

  /// An eye hit (pbrt has no such vertex): the eye's switches resolved once, then its shading (eyeShading.h):
  /// the path continues through the cornea, ends, or meets the sclera, which is shaded at the hit or walked.
  EyeOutcome ShadeEyeHit(const EyeGeometry& eye, int depth, SampleStream& rng, SurfaceHit* hit, PathState* path,
                         PathSample* sample) {
    const auto random = [&rng] { return rng.Next(); };
    const GeometryContext& ctx = *hit->context;
    const EyeSwitches switches = ResolveEyeSwitches(ctx.eyeOptions, eye, settings_);
    EyeLighting& lighting = path->eyeLighting;
    lighting.mnee = switches.mnee;
    lighting.allSolutions = switches.allSolutions;
    lighting.mneeLights = switches.mneeLights;
    lighting.maxChamberEvents = switches.maxChamberEvents;
    lighting.irisLightSplits = settings_.irisLightSplits;
    lighting.chamberSplits = settings_.chamberSplits;
    lighting.receiver = hit->primIndex;
    lighting.chamberEstimator = settings_.chamberEstimator;
    lighting.splitAtEntry = path->splitsAtCornea && path->specular;
    lighting.mneePick = lighting.mnee ? &MneePickOf(ctx, lighting) : nullptr;
    const bool cached = lighting.mnee && chamberCaches_ && settings_.chamberEstimator != ChamberEstimator::Path;
    lighting.chamberCache = cached ? ChamberCacheOf(ctx, eye, lighting) : nullptr;
    const EyeEvent ev = ctx.eye
                            ? ScatterAtEye(eye, path->o, path->d, EyeGeometry::Part(hit->part), lighting, random)
                            : ScatterAtEyeMesh(eye, EyeMeshHitToCanonical(ctx, eye, hit->part, hit->u, hit->v, path->d),
                                               path->d, lighting, random);
    const bool firstEyeEvent = path->part == kNonEye && !ev.passThrough;
    if (firstEyeEvent)
      path->SwitchPart(ev.kind == EyeEvent::Sclera ? kSclera : ev.reflectedAtEntry ? kGlint : kIris, sample);
    sample->L += path->beta * ev.radiance;
    sample->irisMnee += path->beta * ev.radiance;
    if (ev.reflection.weight > 0) {
      path->splitsAtCornea = false;
      path->SwitchPart(path->part, sample);
      TraceCorneaReflection(ev.reflection, firstEyeEvent ? kGlint : path->part, depth, *hit, *path, rng, sample);
      path->lMark = sample->L;  // what the branch gathered is in its own part
    }
    if (ev.kind == EyeEvent::Continue) {
      path->beta *= ev.weight;
      path->cone = path->cone.AfterBounce(hit->t, true);
      path->SetRay(ev.origin, ev.dir);
      if (!ev.passThrough) {
        path->specular = true, path->skipLights = false, path->skipMnee = ev.skipLightHits;
        if (path->skipMnee) path->skipMneeOf = lighting;
      }
      return EyeOutcome::Continue;
    }
    if (ev.kind == EyeEvent::Absorbed) return EyeOutcome::End;
    ShadeScleraSurface(eye, ev, path->d, path->cone, hit);
    if (depth == 0) sample->first.albedo = hit->albedo;  // the albedo AOV shows the sclera's
    // An eye mesh's sclera is a volume: the path walks through it instead of bouncing off a Lambert surface
    // (only meshes have a closed eyeball to walk in; the analytic eye's sclera stays diffuse).
    if (ev.scleraOnSurface && switches.scleraScattering && ctx.prototypeScene)
      return EnterSclera(eye, switches.limbalArc, random, hit, path, sample);
    return EyeOutcome::ShadeSurface;
  }

  /// The reflection off the cornea that ShadeEyeHit's eye split from the path at its entry (EyeEvent::reflection),
  /// traced to its end as a path of its own from the next depth, before the path goes on through the cornea.
  /// Its light goes to the eye AOV `part`.
  void TraceCorneaReflection(const EyeEvent::Branch& reflection, EyePart part, int depth, const SurfaceHit& hit,
                             const PathState& path, SampleStream& rng, PathSample* sample) {
    PathState branch = path;
    branch.part = part;
    branch.lMark = sample->L;
    branch.beta *= reflection.weight;
    branch.cone = path.cone.AfterBounce(hit.t, true);
    branch.SetRay(reflection.origin, reflection.dir);
    branch.SetSpecular();
    TracePath(&branch, depth + 1, rng, sample);
  }

  /// The sclera's diffuse surface at an eye hit: the eye's own normal, or an eye mesh's shading normal; the
  /// sclera colour, or with a bound material that material's colour (its diffuse texture at the hit's st,
  /// filtered over the cone's footprint).
  void ShadeScleraSurface(const EyeGeometry& eye, const EyeEvent& ev, const glm::dvec3& d, const RayCone& cone,
                          SurfaceHit* hit) const {
    if (!ev.scleraOnSurface) hit->n = glm::dot(ev.normal, d) > 0 ? -ev.normal : ev.normal;
    if (!ev.scleraOnSurface || !eye.scleraUsesMaterial)
      hit->albedo = ev.scleraAlbedo;
    else
      hit->albedo = TexturedAlbedo(*hit->material, hit->albedo, SiteOf(*hit, d, cone));
    hit->albedo = glm::clamp(hit->albedo, glm::dvec3(0), glm::dvec3(1));  // an albedo above 1 adds energy
  }

  /// The path meets an eye mesh's sclera and walks it (ScleraWalk). A mirror reflection continues the path; an
  /// exit turns the hit into the exit point, shaded as a diffuse transmission lobe by the caller.
  EyeOutcome EnterSclera(const EyeGeometry& eye, bool limbalArc, eyelib::FunctionRef<double()> random, SurfaceHit* hit,
                         PathState* path, PathSample* sample) const {
    const ScleraStep step = ScleraWalk(eye, *hit, path->d, hit->albedo, limbalArc, random);
    if (step.kind == ScleraStep::Ended) return EyeOutcome::End;
    if (step.kind == ScleraStep::Reflected) {  // a delta lobe: lights it meets count in full
      path->cone = path->cone.AfterBounce(hit->t, true);
      path->SetRay(step.origin, step.dir);
      path->SetSpecular();
      return EyeOutcome::Continue;
    }
    // The exit is a diffuse transmission lobe: the walk decides where light leaves and how much (its Fresnel
    // test at the boundary included); the direction it leaves in is then taken as Lambertian about the exit's
    // outward normal, as Cycles and Hyperion do. The walk's own refracted exit direction is dropped, not
    // followed: its pdf is unknown (it depends on the whole walk), so it could be neither MIS-weighted against
    // light sampling nor combined with next event estimation at the exit without counting the light twice.
    // With a Lambertian lobe, next event estimation and the sampled continuation are weighted by the power
    // heuristic like any diffuse bounce. What this approximates: light refracted out of a dielectric is
    // Lambertian times (1 - F(theta)), a little darker at grazing exit.
    if (path->part != kLimbalArc && step.teleported) path->SwitchPart(kLimbalArc, sample);
    path->beta *= step.weight;
    hit->p = step.point;
    hit->n = hit->ng = step.normal;
    hit->albedo = glm::dvec3(1);  // the colour is in the walk's weight
    path->d = -step.normal;       // wo = the outward normal: the lobe is the outward hemisphere
    return EyeOutcome::ShadeSurface;
  }

  /// What a sclera hit on an eye mesh did: reflected off the wet surface, or entered, walked and left.
  struct ScleraStep {
    enum Kind { Reflected, Exited, Ended } kind = Ended;
    glm::dvec3 origin{0}, dir{0};    ///< Reflected: the mirror ray
    glm::dvec3 point{0}, normal{0};  ///< Exited: the exit (world) and the outward shading normal there
    glm::dvec3 weight{0};            ///< Exited: the walk's RGB throughput
    bool teleported = false;         ///< Exited: the walk lit the limbal arc
  };

  /// The sclera of an eye mesh as a volume: at the hit, a smooth dielectric boundary of the eye's tissue index
  /// (EyeParams' cornea ior: cornea and sclera share it) reflects with the Fresnel probability or refracts in;
  /// inside, eyelib's random walk runs in the canonical frame against the mesh itself (its own Embree scene),
  /// with the teleportation cylinder if the eye asks for it. Both Fresnel choices are sampled with their own
  /// probability, so no weight changes there.
  ScleraStep ScleraWalk(const EyeGeometry& eye, const SurfaceHit& hit, const glm::dvec3& d, const glm::dvec3& albedo,
                        bool limbalArc, eyelib::FunctionRef<double()> random) const {
    ScleraStep step;
    const double ior = eye.chamber.CorneaIor();
    // Fresnel against the shading normal (smooth highlights); which side is inside, against the
    // geometric one (the walk's boundary is the triangles themselves).
    const glm::dvec3 wo = -d;
    const double cosO = std::max(0.0, glm::dot(wo, hit.n));
    if (random() < eyelib::FresnelDielectric(cosO, ior)) {
      step.kind = ScleraStep::Reflected;
      step.dir = eyelib::Reflect(wo, hit.n);
      // A shading normal can tilt the mirror direction under the triangle: lift it just above.
      const double cosG = glm::dot(step.dir, hit.ng);
      if (cosG < 1e-4) step.dir = glm::normalize(step.dir + (1e-4 - cosG) * hit.ng);
      step.origin = SpawnOrigin(hit.p, hit.ng, eye.SpawnScale());
      return step;
    }
    glm::dvec3 inward;
    if (!eyelib::Refract(wo, hit.n, ior, &inward)) return step;  // cannot happen from outside (ior >= 1)
    // The refracted direction must enter the triangle the ray met (hit.ng faces the ray: inside is -ng).
    const double cosIn = glm::dot(inward, hit.ng);
    if (cosIn > -1e-4) inward = glm::normalize(inward - (cosIn + 1e-4) * hit.ng);

    // The walk meets the mesh as it is now (deformed or not): its own triangles, placed by the prim
    // transform; the cylinder lives in the eye's canonical frame (ScatterInSclera), so it follows the eye.
    std::int64_t queries = 0;
    MeshCrossing exitCrossing;
    const WorldBoundary boundary =
        EyeMeshBoundary(hit.context->prototypeScene, eye.objectToWorld, &queries, &exitCrossing, rayTime_);
    ScleraScatteringSettings ws;
    ws.ior = ior;
    ws.limbalArc = limbalArc;
    const ScleraExit exit = ScatterInSclera(eye, hit.p, inward, albedo, eye.scleraMeanFreePath, boundary, random, ws);
    CountWalk(exit, queries);
    if (!exit.Exited()) return step;

    step.kind = ScleraStep::Exited;
    step.point = exit.origin;
    step.weight = exit.weight;
    step.teleported = exit.teleported;
    step.normal = ExitShadingNormal(*hit.context, exitCrossing, exit.normal);
    return step;
  }

  void CountWalk(const ScleraExit& exit, std::int64_t queries) const {
    counts_.rays += queries;
    ++counts_.walks;
    if (exit.teleported) ++counts_.teleportedWalks;
    if (exit.status == eyelib::WalkStatus::Capped) ++counts_.cappedWalks;
    if (exit.status == eyelib::WalkStatus::Invalid) ++counts_.invalidWalks;
  }

  /// The outward shading normal where a sclera walk left the mesh: the mesh's interpolated normals at the last
  /// crossing, if they agree with the geometric normal's side; else the geometric normal `outward`.
  static glm::dvec3 ExitShadingNormal(const GeometryContext& ctx, const MeshCrossing& crossing,
                                      const glm::dvec3& outward) {
    if (!ctx.vertexNormals || !ctx.triangleVertices || crossing.triangle == RTC_INVALID_GEOMETRY_ID ||
        3 * std::size_t(crossing.triangle) + 2 >= ctx.triangleVertices->size())
      return outward;
    const int* tri = &(*ctx.triangleVertices)[3 * std::size_t(crossing.triangle)];
    const WorldNormal shading(ctx.normalToWorld,
                              InterpolateAtTriangle(*ctx.vertexNormals, tri, crossing.u, crossing.v));
    return shading.Valid() && glm::dot(shading.v, outward) > 0 ? shading.v / shading.length : outward;
  }

  /// Next event estimation (pbrt's SampleLd): one light chosen uniformly, sampled from `origin`, weighted by the
  /// power heuristic against BSDF sampling; nothing for mirrors and glass (delta lobes). Returns beta times the
  /// light's contribution. Always draws its light choice and one 2D sample.
  glm::dvec3 SampleLd(const SurfaceHit& hit, const PreviewSurfaceAt& bsdf, const glm::dvec3& origin,
                      const glm::dvec3& beta, SampleStream& rng) const {
    const double uPick = rng.Next();
    double u1, u2;
    rng.Next2D(&u1, &u2);
    if (lights_.empty() || !bsdf.HasSmoothLobe()) return glm::dvec3(0);
    const RenderLight& light = lights_[std::min(lights_.size() - 1, std::size_t(uPick * lights_.size()))];
    if (!Illuminates(light, hit.primIndex)) return glm::dvec3(0);
    const LightSample ls = SampleLight(light, origin, u1, u2);
    const double cosS = glm::dot(ls.dir, hit.n);
    if (!(ls.pdf > 0 && cosS > 0)) return glm::dvec3(0);
    // A normal map may tilt the shading normal towards a light below the surface itself: no light there.
    if (hit.normalMapped && glm::dot(ls.dir, hit.ng) <= 0) return glm::dvec3(0);
    double bsdfPdf;
    const glm::dvec3 f = bsdf.EvalAndPdf(ls.dir, &bsdfPdf);
    if (!(f.x > 0 || f.y > 0 || f.z > 0)) return glm::dvec3(0);
    const double transmittance = Transmittance(light, origin, ls.dir, ls.distance * (1 - 1e-6));
    if (!(transmittance > 0)) return glm::dvec3(0);
    const double pl = ls.pdf * LightSelectPdf();
    // A delta light (a point, a parallel beam) is found by light sampling alone: weight 1.
    const double w = settings_.mis && !ls.delta ? PowerHeuristic(pl, bsdfPdf) : 1.0;
    return beta * f * ls.radiance * (cosS * w * transmittance / pl);
  }

  /// The path's next ray, sampled from the BSDF (its weight f |cos| / pdf), then Russian roulette after three
  /// bounces. False: the path ends here.
  bool SampleContinuation(const SurfaceHit& hit, const PreviewSurface& bsdf, const PreviewSurfaceAt& bsdfAt,
                          const glm::dvec3& origin, int depth, SampleStream& rng, PathState* path) const {
    const double uLobe = rng.Next();
    double uDir1, uDir2;
    rng.Next2D(&uDir1, &uDir2);
    BsdfSample bs;
    if (!bsdfAt.Sample(path->insideGlass, uLobe, uDir1, uDir2, &bs)) return false;
    if (bs.transmitted && bsdf.thinWalled) {
      // Straight through a thin wall: the same ray, continued past the wall. Origin and weighting state stay
      // the previous vertex's, so a light met beyond is weighted (and its pdf taken) as from there, as next
      // event estimation saw it through the wall's transmittance.
      path->beta *= bs.weight;
      path->tNear = hit.t + SpawnOffset(hit.p, SpawnScaleOf(*hit.context));
      return RussianRoulette(depth, rng, path);
    }
    // Under a normal map, a direction on the wrong side of the surface itself ends the path (the energy a
    // shading normal cannot conserve); it would otherwise start inside the surface and hit it again.
    if (hit.normalMapped && (glm::dot(bs.wi, hit.ng) > 0) == bs.transmitted) return false;
    if (bs.transmitted) path->insideGlass = !path->insideGlass;
    path->bsdfPdf = bs.pdf;
    path->specular = bs.delta, path->skipLights = !bs.delta && !settings_.mis, path->skipMnee = false;
    path->beta *= bs.weight;
    path->cone = path->cone.AfterBounce(hit.t, bs.delta);
    path->SetRay(glm::dot(bs.wi, hit.n) > 0 ? origin : SpawnOrigin(hit.p, -hit.n, SpawnScaleOf(*hit.context)), bs.wi);
    return RussianRoulette(depth, rng, path);
  }

  /// Russian roulette after three bounces: false ends the path, else the survivor's weight grows to match.
  static bool RussianRoulette(int depth, SampleStream& rng, PathState* path) {
    if (depth < 3) return true;
    const double q = std::min(0.95, std::max({path->beta.x, path->beta.y, path->beta.z}));
    if (rng.Next() >= q) return false;
    path->beta /= q;
    return true;
  }

  RTCScene scene_;
  const std::vector<RenderLight>& sourceLights_;
  /// Moving lights at the path's time (a copy of the lights, rebuilt per path); empty when none moves.
  std::vector<RenderLight> lightsNow_;
  const std::vector<RenderLight>& lights_;  ///< what paths see: lightsNow_ when a light moves, else sourceLights_
  Shutter shutter_;
  double time_ = 0;    ///< the path's time, frames
  float rayTime_ = 0;  ///< its Embree ray time
  const RenderSettings& settings_;
  bool cutouts_ = false;
  ChamberLightCaches* chamberCaches_ = nullptr;
  /// The chamber-light cache of the last eye hit (ChamberCacheOf), by its context, receiver and unmoved frame.
  struct LastChamberCache {
    const GeometryContext* ctx = nullptr;
    int receiver = -1;
    glm::dmat4 frame{0.0};
    std::shared_ptr<const eyelib::IrisChamberCache> cache;
  } lastChamberCache_;
  struct LastMneePick {
    const GeometryContext* ctx = nullptr;
    int receiver = -1;
    const std::vector<bool>* mask = nullptr;
    std::vector<double> pick;
  } lastMneePick_;
  TextureThread* textureThread_ = nullptr;  ///< OIIO's per-thread state of the thread running this tracer
  mutable Counts counts_;
};

/// Throws std::invalid_argument unless a colour buffer is bound and every bound buffer has its size.
void CheckBuffers(const AovBuffers& aovs) {
  if (!aovs.color) throw std::invalid_argument("render: a color buffer must be bound");
  const int width = aovs.color->Width(), height = aovs.color->Height();
  for (AccumulationBuffer* b : {aovs.albedo, aovs.normal, aovs.depth, aovs.primId, aovs.irisMnee, aovs.glint, aovs.iris,
                                aovs.sclera, aovs.nonEye, aovs.limbalArc, aovs.hitId})
    if (b && (b->Width() != width || b->Height() != height))
      throw std::invalid_argument("render: every bound buffer must be " + std::to_string(width) + " x " +
                                  std::to_string(height));
}

void AddRgb(AccumulationBuffer* buffer, int x, int y, const glm::dvec3& v) {
  if (!buffer) return;
  const float rgb[3] = {float(v.x), float(v.y), float(v.z)};
  buffer->AddSample(x, y, rgb);
}

/// Adds one path sample of pixel (x, y), sample index s, to the bound AOVs: colour and the light AOVs always,
/// the data AOVs (albedo, normal, depth, primId) from sample 0 only. A non-finite radiance is dropped (black)
/// and reported through the return value.
bool AddPathSample(const AovBuffers& aovs, int x, int y, int s, PathSample sample) {
  const glm::dvec3& L = sample.L;
  const bool finite = std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z);
  if (!finite) sample = PathSample{};  // never let it into the image
  const float color[4] = {float(L.x), float(L.y), float(L.z), sample.hitAny ? 1.0f : 0.0f};
  aovs.color->AddSample(x, y, color);
  AddRgb(aovs.irisMnee, x, y, sample.irisMnee);
  // The eye AOVs' buffers in EyePart's order.
  constexpr AccumulationBuffer* AovBuffers::*kPartBuffers[kEyeParts] = {
      &AovBuffers::nonEye, &AovBuffers::glint, &AovBuffers::iris, &AovBuffers::sclera, &AovBuffers::limbalArc};
  for (int part = 0; part < kEyeParts; ++part) AddRgb(aovs.*kPartBuffers[part], x, y, sample.parts[part]);
  if (aovs.hitId) {  // every sample: cryptomatte ranks the first hits of all of them
    const FirstHit& first = sample.first;
    const float hit[3] = {sample.hitAny ? float(first.primIndex) : -1.0f,
                          sample.hitAny ? float(first.instanceIndex) : 0, sample.hitAny ? float(first.subset) : -1.0f};
    aovs.hitId->AddSample(x, y, hit);
  }
  if (s != 0) return finite;
  const FirstHit& first = sample.first;
  AddRgb(aovs.albedo, x, y, sample.hitAny ? first.albedo : glm::dvec3(0));
  AddRgb(aovs.normal, x, y, sample.hitAny ? first.n : glm::dvec3(0));
  const float depth = sample.hitAny ? float(first.t) : 0.0f, id = sample.hitAny ? float(first.primIndex) : -1.0f;
  if (aovs.depth) aovs.depth->AddSample(x, y, &depth);
  if (aovs.primId) aovs.primId->AddSample(x, y, &id);
  return finite;
}

/// The counters every tile's tracer adds to, shared across threads.
struct SharedCounts {
  std::atomic<std::int64_t> rays{0}, nonFinite{0}, walks{0}, teleported{0}, capped{0}, invalid{0};
  void Add(const Tracer::Counts& c) {
    rays += c.rays, walks += c.walks, teleported += c.teleportedWalks, capped += c.cappedWalks;
    invalid += c.invalidWalks;
  }
};

/// The cone of the camera ray through image point (x, y) (pixels) from lens point (lensU, lensV): the ray one pixel
/// over from the same lens point gives its width (orthographic) and spread (perspective), both scaled by
/// RenderSettings::textureFootprintScale. Through one lens point the cone narrows to the pixel at the focus distance;
/// the lens's blur comes from the lens samples, not from the footprint.
RayCone PixelCone(const CameraView& camera, const WorldRay& ray, double x, double y, int width, int height,
                  double aspect, double lensU, double lensV, double footprintScale) {
  const WorldRay next = camera.GenerateRay((x + 1) / width, y / height, aspect, lensU, lensV);
  return {footprintScale * glm::length(next.origin - ray.origin),
          footprintScale * std::acos(std::clamp(glm::dot(ray.dir, next.dir), -1.0, 1.0))};
}

/// The pixels a pass stage renders: those on the stride grid (x and y multiples of `stride`) that are not on the
/// coarser grid of the stage before (0: none before). A first pass in stages 4, 2, 1 renders each pixel once.
struct PixelGrid {
  int stride = 1, coarser = 0;
  bool Has(int x, int y) const {
    return x % stride == 0 && y % stride == 0 && !(coarser && x % coarser == 0 && y % coarser == 0);
  }
};

/// Samples [firstSample, firstSample + samples) of the grid's pixels in a range of tiles, each (pixel, sample) from its
/// own random stream. A pixel's samples are taken one after another (in sample order, so its sums are those of one pass
/// per sample): its buffer entries stay in cache, where a pass over the whole image would fetch them again each time.
void RenderTiles(const tbb::blocked_range<int>& range, int firstSample, int samples, const PixelGrid& grid,
                 RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                 const RenderSettings& settings, bool cutouts, bool textured, const AovBuffers& aovs,
                 SharedCounts* counts, ChamberLightCaches* chamberCaches, const eyelib::ZSobolKeyTable* sampleKeys) {
  const int width = aovs.color->Width(), height = aovs.color->Height();
  const int tilesX = (width + kTile - 1) / kTile;
  // The film's aspect: non-square pixels (RenderSettings::pixelAspectRatio) stretch it.
  const double par =
      std::isfinite(settings.pixelAspectRatio) && settings.pixelAspectRatio > 0 ? settings.pixelAspectRatio : 1;
  const double aspect = double(width) * par / height, invWidth = 1.0 / width, invHeight = 1.0 / height;
  const Shutter shutter = camera.GetShutter();
  Tracer tracer(scene, lights, settings, cutouts, shutter, chamberCaches);
  for (int tile = range.begin(); tile != range.end(); ++tile) {
    const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
    for (int y = y0; y < std::min(height, y0 + kTile); ++y)
      for (int x = x0; x < std::min(width, x0 + kTile); ++x)
        for (int s = firstSample; s < firstSample + samples && grid.Has(x, y); ++s) {
          SampleStream rng(settings.sampler, settings.seed, x, y, width, std::uint64_t(s), sampleKeys);
          double jx = 0.5, jy = 0.5;  // sample 0 at the pixel's centre (the data AOVs')
          if (s != 0) rng.PixelJitter(&jx, &jy);
          const double time = PathTime(shutter, settings.timeStrata, std::uint64_t(s), rng);
          const std::optional<CameraView> moved = camera.motion ? std::optional(camera.AtTime(time)) : std::nullopt;
          const CameraView& view = moved ? *moved : camera;
          const bool lens = view.HasLens();
          const double lensU = lens ? rng.FromTop(0) : 0.5, lensV = lens ? rng.FromTop(1) : 0.5;
          const WorldRay ray = view.GenerateRay((x + jx) * invWidth, (y + jy) * invHeight, aspect, lensU, lensV);
          // Only texture lookups read the cone (and only when filtering): without them it is never computed.
          const RayCone cone = textured && settings.textureFiltering
                                   ? PixelCone(view, ray, x + jx, y + jy, width, height, aspect, lensU, lensV,
                                               settings.textureFootprintScale)
                                   : RayCone{};
          if (!AddPathSample(aovs, x, y, s, tracer.Li(ray, cone, rng, time))) ++counts->nonFinite;
        }
  }
  counts->Add(tracer.GetCounts());
}

/// Seconds since `start`.
double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// What every pass of one Render call shares: the scene, the tile count, the thread arena, the counters.
struct PassContext {
  RTCScene scene;
  const CameraView& camera;
  const std::vector<RenderLight>& lights;
  const RenderSettings& settings;
  const AovBuffers& aovs;
  bool cutouts, textured;
  ChamberLightCaches* chamberCaches;
  const eyelib::ZSobolKeyTable* sampleKeys;
  int tiles;
  tbb::task_arena* arena;
  SharedCounts* counts;
};

/// Samples [firstSample, firstSample + samples) of the grid's pixels, on the arena's threads.
void RenderPassSamples(const PassContext& c, int firstSample, int samples, const PixelGrid& grid = {}) {
  c.arena->execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, c.tiles), [&](const tbb::blocked_range<int>& range) {
      RenderTiles(range, firstSample, samples, grid, c.scene, c.camera, c.lights, c.settings, c.cutouts, c.textured,
                  c.aovs, c.counts, c.chamberCaches, c.sampleKeys);
    });
  });
}

/// The first pass (one sample) in coarse-to-fine stages, strides control.firstPassStride, its half, ..., 1, with the
/// callback after each stage but the last (PassProgress::stride; its return value waits for the pass's end: a
/// render stops only between whole passes). Every pixel takes its sample once, so the image is as one stage's.
/// Returns the seconds to the end of the first stage. Each stride is a multiple of the next (powers of two: a stride
/// that is not one is rounded down to one), so no pixel is in two stages.
double RenderFirstPassInStages(const PassContext& c, const ProgressiveControl& control, PassProgress progress,
                               std::chrono::steady_clock::time_point start) {
  int coarser = 0, first = 1;
  while (first * 2 <= control.firstPassStride) first *= 2;
  for (int stride = first; stride > 1; coarser = stride, stride /= 2) {
    RenderPassSamples(c, c.settings.firstSample, 1, PixelGrid{stride, coarser});
    progress.stride = stride;
    progress.seconds = SecondsSince(start);
    if (progress.previewSeconds == 0) progress.previewSeconds = progress.seconds;
    if (control.onPass) control.onPass(progress);
  }
  RenderPassSamples(c, c.settings.firstSample, 1, PixelGrid{1, coarser});
  return progress.previewSeconds;
}

void CopyCounts(const SharedCounts& counts, RenderStats* stats) {
  stats->rays = counts.rays;
  stats->nonFiniteSamples = counts.nonFinite;
  stats->scleraWalks = counts.walks;
  stats->teleportedWalks = counts.teleported;
  stats->cappedWalks = counts.capped;
  stats->invalidWalks = counts.invalid;
}

}  // namespace

int NextPassSamples(int remaining, int lastPass, double secondsPerSample, double passSeconds, double timeLeft) {
  if (remaining <= 0) return 0;
  if (lastPass <= 0 || !(secondsPerSample > 0)) return 1;
  const double target = timeLeft >= 0 ? std::min(passSeconds, timeLeft) : passSeconds;
  const double fit = std::clamp(std::floor(target / secondsPerSample), 1.0, 2.0 * lastPass);
  return std::min(int(fit), remaining);
}

RenderStats Renderer::Render(RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                             const RenderSettings& settings, const AovBuffers& aovs,
                             const ProgressiveControl& control) const {
  CheckBuffers(aovs);
  const int width = aovs.color->Width(), height = aovs.color->Height();
  RenderStats stats;
  if (width == 0 || height == 0) return stats;
  const auto start = std::chrono::steady_clock::now();
  SharedCounts counts;
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  if (!chamberCaches_) chamberCaches_ = std::make_shared<ChamberLightCaches>();
  chamberCaches_->BeginRender(lights, sceneVersion_);
  const eyelib::ZSobolKeyTable sampleKeys = SampleStream::KeyTable(settings.seed);
  const int tiles = ((width + kTile - 1) / kTile) * ((height + kTile - 1) / kTile);
  const PassContext context{scene,       camera, lights, settings, aovs, cutouts_, textured_, chamberCaches_.get(),
                            &sampleKeys, tiles,  &arena, &counts};

  // Without a callback, a stop flag or a time limit every pixel takes all its samples at once (in cache); else pass
  // after pass as NextPassSamples sizes them, stopping only between whole passes so every pixel has the same samples.
  const bool progressive = control.Progressive(settings), limited = settings.timeLimitSeconds > 0;
  PassProgress progress;
  progress.samplesTotal = settings.samplesPerPixel;
  double secondsPerSample = 0;
  while (progress.samplesDone < settings.samplesPerPixel) {
    const int remaining = settings.samplesPerPixel - progress.samplesDone;
    const double timeLeft = limited ? std::max(0.0, settings.timeLimitSeconds - SecondsSince(start)) : -1.0;
    const int samples =
        progressive ? NextPassSamples(remaining, progress.passSamples, secondsPerSample, control.passSeconds, timeLeft)
                    : remaining;
    const auto passStart = std::chrono::steady_clock::now();
    if (progress.samplesDone == 0 && progressive && control.firstPassStride > 1)
      stats.previewSeconds = progress.previewSeconds = RenderFirstPassInStages(context, control, progress, start);
    else
      RenderPassSamples(context, settings.firstSample + progress.samplesDone, samples);
    secondsPerSample = SecondsSince(passStart) / samples;
    progress.samplesDone += samples;
    progress.passSamples = samples;
    progress.seconds = SecondsSince(start);
    if (progress.firstPassSeconds == 0) progress.firstPassSeconds = progress.seconds;
    stats.passes += samples;
    stats.samples += std::int64_t(width) * height * samples;
    const bool more = progress.samplesDone < settings.samplesPerPixel;
    if (control.onPass && !control.onPass(progress) && more) {
      stats.stopped = true;
      break;
    }
    if (more && control.stop && control.stop->load()) {
      stats.stopped = true;
      break;
    }
    if (more && limited && SecondsSince(start) >= settings.timeLimitSeconds) {
      stats.timeLimitReached = true;
      break;
    }
  }
  CopyCounts(counts, &stats);
  stats.firstPassSeconds = progress.firstPassSeconds;
  stats.seconds = SecondsSince(start);
  return stats;
}

}  // namespace hdeye
