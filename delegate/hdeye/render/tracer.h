#pragma once
// The path tracer of one render thread (pbrt's PathIntegrator with the eye as a vertex of its own). Its member
// functions live by subject: the path loop (tracer.cpp), closest hits and their primvars (tracerSurfaceHits.cpp),
// shadow rays (tracerShadowRays.cpp), light sampling and the lights a ray meets (tracerLightSampling.cpp), eye hits
// and the cornea's branch (tracerEyeHits.cpp) and the sclera's random walk (tracerScleraWalk.cpp). Internal to the
// renderer (renderer.cpp and pixelSampling.cpp drive it).
#include "hdeye/params/motion.h"
#include "hdeye/render/chamberLightCache.h"
#include "hdeye/render/entryTables.h"
#include "hdeye/render/materialShading.h"
#include "hdeye/render/movingLights.h"
#include "hdeye/render/pathState.h"
#include "hdeye/render/previewSurface.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/renderSettings.h"
#include "hdeye/render/sampleStream.h"
#include "hdeye/render/scleraScattering.h"
#include "hdeye/render/texture.h"

#include <embree3/rtcore.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace hdeye {

class Tracer {
 public:
  /// Counters a tracer keeps while it renders (RenderStats' rays and sclera walks).
  struct Counts {
    std::int64_t rays = 0, walks = 0, teleportedWalks = 0, cappedWalks = 0, invalidWalks = 0;
  };

  /// cutouts: some material has an opacityThreshold, so shadow rays must look at what they meet.
  /// shutter: the camera's (the Embree ray time of each path's time).
  /// chamberCaches: the eyes' chamber light (RenderSettings::chamberEstimator) and entry tables, or null.
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
        entryTables_(chamberCaches ? &chamberCaches->EntryTables() : nullptr),
        textureThread_(CurrentTextureThread()),
        eyeRays_(&ThisThreadsEyeRays()) {}

  /// Radiance along a camera ray (pbrt's PathIntegrator::Li): per vertex, the lights the ray meets, the
  /// surface's emission, the eye (if it is one), direct light (SampleLd) and the BSDF-sampled continuation.
  /// cone: the camera ray's footprint, carried along the path for texture filtering.
  /// time: the path's, frames (PathTime): rays meet the geometry, lights and eyes as they are then.
  /// reflection: what the path does with the cornea's reflection at its first eye event (CameraReflection).
  PathSample Li(const WorldRay& ray, const RayCone& cone, SampleStream& rng, double time,
                CameraReflection reflection = CameraReflection::Traced);

  /// Whether the camera ray's first hit is an eye whose cornea there mirrors a light other than a dome (a
  /// catchlight): the entry's reflection meets the light before any geometry. A function of the scene only (the
  /// entry's random numbers are fixed); catchlightPixels.h asks it at pixel corners.
  bool SeesCatchlight(const WorldRay& ray, double time);

  const Counts& GetCounts() const { return counts_; }

 private:
  /// The path's vertices from `firstDepth` on (0: the camera ray), adding what it gathers to *sample (and, at depth
  /// 0, the first hit's data). A branch split off at a cornea (ShadeEyeHit) goes through here on its own.
  void TracePath(PathState* pathState, int firstDepth, SampleStream& rng, PathSample* samplePtr);

  /// The shadow test an eye's lighting calls (EyeLighting::transmittance) over this tracer's lights, by index. The
  /// caller keeps the returned callable alive while the lighting refers to it.
  auto LightTransmittance() {
    return [this](std::size_t k, const glm::dvec3& o, const glm::dvec3& d, double t, const EyeGeometry* leaving) {
      return Transmittance(lights_[k], o, d, t, leaving);
    };
  }

  /// The path's time: Embree's ray time, and the moving lights moved to it.
  void SetTime(double time);

  /// Closest hit of the scene's geometry along the ray, if any. `leaving`: the analytic eye whose cornea the ray leaves
  /// outwards (EyeRayExchange::leaving: its callbacks skip the ray), or null.
  bool Intersect(const glm::dvec3& o, const glm::dvec3& d, double tNear, double tFar, SurfaceHit* hit,
                 const EyeGeometry* leaving = nullptr) const;

  /// The hit's shading normal, st, albedo and emission from its geometry's primvars: per-vertex values
  /// (triangleVertices) or per-corner ones (3 per triangle), weighted by the hit's barycentrics; object-space normals
  /// and st derivatives carried to world space by the hit instance's `normalToWorld`.
  static void FillPrimvars(const glm::dmat3& normalToWorld, SurfaceHit* hit);

  /// The interpolated vertex normal at barycentrics (u, v) of triangle `tri`, object space; for a deforming mesh
  /// blended between the two time steps around Embree ray time `rayTime`, as Embree blends the positions.
  static glm::dvec3 VertexNormalAt(const GeometryContext& ctx, const int* tri, double u, double v, float rayTime);

  /// dp/ds, dp/dt (world) of the mesh triangle whose corners start at `firstCorner`, placed by the hit instance's
  /// `normalToWorld` (an instanced mesh's own context holds its prototype's transform only).
  static StFrame TriangleStFrameAt(const GeometryContext& ctx, const glm::dmat3& normalToWorld,
                                   std::size_t firstCorner);

  /// Where a non-eye hit's textures are looked up: its st, filtered over the cone's footprint there (unless
  /// RenderSettings::textureFiltering is off).
  TextureSite SiteOf(const SurfaceHit& hit, const glm::dvec3& d, const RayCone& cone) const;

  /// The bound material at a non-eye hit (materialShading.h); the hit takes its emission and shading normal.
  SurfaceShading ShadeMaterialHit(SurfaceHit* hit, const glm::dvec3& d, const RayCone& cone) const;

  /// The fraction of `light` that passes from o along unit d to tFar: 0 behind a surface that casts its shadow,
  /// else the product of the thin walls crossed (thinWalls.h); opacityThreshold cut-outs let it through where
  /// they are cut away. Without shadow linking one any-hit query that skips thin walls decides, and only if it
  /// met one (or, in a scene with cut-outs, anything) are the surfaces crossed in order (CrossSurfaces); with
  /// shadow linking they are crossed at once.
  double Transmittance(const RenderLight& light, const glm::dvec3& o, const glm::dvec3& d, double tFar,
                       const EyeGeometry* leaving = nullptr) const;

  /// Transmittance by walking the surfaces from o along d to tFar in order: a surface the light's shadow linking
  /// leaves out passes, as do cut-away parts of cut-outs; thin walls attenuate, anything else blocks. At most
  /// kMaxCutoutCrossings surfaces; more count as opaque (light never leaks through a thick stack).
  double CrossSurfaces(const RenderLight& light, const glm::dvec3& o, const glm::dvec3& d, double tFar,
                       const EyeGeometry* leaving) const;

  /// Whether a ray along d passes a hit because its material is cut away there (opacityThreshold).
  bool CutAway(const SurfaceHit& hit, const glm::dvec3& d) const;

  /// The light of every light surface the path's current ray meets past path.tNear (a ray continued past a thin wall
  /// starts there) and before `maxDistance` (the geometry it hits), weighted by how the ray was chosen (PathState's
  /// flags). Lights are transparent to one another, as to shadow rays: a dome behind a rect counts in full. Passed
  /// over: the lights MNEE counted when the ray left an iris straight through the cornea (path.skipMneeOf), domes
  /// with hideDomes (camera rays, when RenderSettings::domeLightCameraVisibility is off), and lights linked away from
  /// the rprim the ray left.
  glm::dvec3 LightsMet(const PathState& path, double maxDistance, bool hideDomes) const;

  /// Next event estimation samples every light at each vertex when there are at most this many, else one picked
  /// uniformly. Picking one of a dome, a rect key and a small fill left the production eye sample's frame at 4.7
  /// times the variance of sampling all three (its eyes at 1.7 times), which costs 1.2 times the time
  /// (docs/production_eye.md).
  static constexpr std::size_t kEveryLightMax = 8;
  bool SamplesEveryLight() const { return lights_.size() <= kEveryLightMax; }
  /// The probability that next event estimation samples any one light: 1 when it samples every light, else uniform.
  double LightSelectPdf() const {
    return lights_.empty() ? 0 : SamplesEveryLight() ? 1.0 : 1.0 / double(lights_.size());
  }

  /// MNEE's light choice at the eye of `ctx` (MneeLightPick), from the eye and the lights as they stand still (so
  /// that it, and a chamber cache built with it, does not depend on which path asked first); the last eye's is kept.
  const std::vector<double>& MneePickOf(const GeometryContext& ctx, const EyeLighting& lighting);

  /// The eye's chamber-light cache (RenderSettings::chamberEstimator): one per render whatever the path's time.
  /// Under an open shutter it is built from the eye, the lights and the shadow rays at the shutter's opening, so
  /// which path builds it (thread count, sample split) never changes it; the control variate stays unbiased for
  /// an eye or light that moves, the cache alone then shows them where they were at the opening.
  /// Held by the tracer while it lives.
  const eyelib::IrisChamberCache* ChamberCacheOf(const GeometryContext& ctx, const EyeGeometry& eye,
                                                 const EyeLighting& lighting);

  /// An eye hit (pbrt has no such vertex): the eye's switches resolved once, then its shading (eyeShading.h):
  /// the path continues through the cornea, ends, or meets the sclera, which is shaded at the hit or walked.
  EyeOutcome ShadeEyeHit(const EyeGeometry& eye, int depth, SampleStream& rng, SurfaceHit* hit, PathState* path,
                         PathSample* sample);

  /// The reflection off the cornea that ShadeEyeHit's eye split from the path at its entry (EyeEvent::reflection),
  /// traced to its end as a path of its own from the next depth, before the path goes on through the cornea.
  /// Its light goes to the eye AOV `part`.
  void TraceCorneaReflection(const EyeEvent::Branch& reflection, EyePart part, int depth, const SurfaceHit& hit,
                             const PathState& path, SampleStream& rng, PathSample* sample);

  /// A reflection-only path (CameraReflection::Only) at its first eye event: what it gathered so far is dropped, the
  /// reflection split at the entry (if any) is traced into the glint part, and the path ends.
  EyeOutcome TraceOnlyCameraReflection(const EyeEvent& ev, int depth, const SurfaceHit& hit, PathState* path,
                                       SampleStream& rng, PathSample* sample);

  /// The sclera's diffuse surface at an eye hit: the eye's own normal, or an eye mesh's shading normal; the
  /// sclera colour, or with a bound material that material's colour (its diffuse texture at the hit's st,
  /// filtered over the cone's footprint).
  void ShadeScleraSurface(const EyeGeometry& eye, const EyeEvent& ev, const glm::dvec3& d, const RayCone& cone,
                          SurfaceHit* hit) const;

  /// The path meets an eye mesh's sclera and walks it (ScleraWalk). A mirror reflection continues the path; an
  /// exit turns the hit into the exit point, shaded as a diffuse transmission lobe by the caller.
  EyeOutcome EnterSclera(const EyeGeometry& eye, bool limbalArc, eyelib::FunctionRef<double()> random, SurfaceHit* hit,
                         PathState* path, PathSample* sample) const;

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
                        bool limbalArc, eyelib::FunctionRef<double()> random) const;

  void CountWalk(const ScleraExit& exit, std::int64_t queries) const;

  /// The outward shading normal where a sclera walk left the mesh: the mesh's interpolated normals at the last
  /// crossing, if they agree with the geometric normal's side; else the geometric normal `outward`.
  static glm::dvec3 ExitShadingNormal(const GeometryContext& ctx, const MeshCrossing& crossing,
                                      const glm::dvec3& outward);

  /// Next event estimation (pbrt's SampleLd): every light (SamplesEveryLight), or one chosen uniformly, sampled
  /// from `origin` with one 2D sample, each weighted by the power heuristic against BSDF sampling; nothing for
  /// mirrors and glass (delta lobes). Returns beta times the lights' contribution. Always draws its light choice and
  /// the 2D sample.
  glm::dvec3 SampleLd(const SurfaceHit& hit, const PreviewSurfaceAt& bsdf, const glm::dvec3& origin,
                      const glm::dvec3& beta, SampleStream& rng) const;
  /// One light's term of SampleLd, from the 2D sample (u1, u2).
  glm::dvec3 SampleLdFrom(const RenderLight& light, const SurfaceHit& hit, const PreviewSurfaceAt& bsdf,
                          const glm::dvec3& origin, double u1, double u2) const;

  /// The path's next ray, sampled from the BSDF (its weight f |cos| / pdf), then Russian roulette after three
  /// bounces. False: the path ends here.
  bool SampleContinuation(const SurfaceHit& hit, const PreviewSurface& bsdf, const PreviewSurfaceAt& bsdfAt,
                          const glm::dvec3& origin, int depth, SampleStream& rng, PathState* path) const;

  /// Russian roulette after three bounces: false ends the path, else the survivor's weight grows to match.
  static bool RussianRoulette(int depth, SampleStream& rng, PathState* path);

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
    const eyelib::IrisChamberCache* cache = nullptr;
  } lastChamberCache_;
  /// Every cache ChamberCacheOf handed out, held while the tracer lives: paths point to them (EyeLighting).
  std::vector<std::shared_ptr<const eyelib::IrisChamberCache>> heldChamberCaches_;
  EntryTables entryTables_;  ///< from chamberCaches_, for EyeLighting::entryTables
  struct LastMneePick {
    const GeometryContext* ctx = nullptr;
    int receiver = -1;
    const std::vector<bool>* mask = nullptr;
    std::vector<double> pick;
  } lastMneePick_;
  TextureThread* textureThread_ = nullptr;  ///< OIIO's per-thread state of the thread running this tracer
  EyeRayExchange* eyeRays_ = nullptr;       ///< what that thread's rays share with the analytic eyes' callbacks
  mutable Counts counts_;
};

}  // namespace hdeye
