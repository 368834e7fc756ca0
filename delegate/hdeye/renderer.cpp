#include "hdeye/renderer.h"

#include "hdeye/eyeShading.h"
#include "hdeye/previewSurface.h"
#include "hdeye/renderContext.h"
#include "hdeye/scleraScattering.h"
#include "hdeye/texture.h"

#include <eyelib/optics.h>
#include <eyelib/random.h>
#include <eyelib/sampling.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <type_traits>
#include <limits>
#include <stdexcept>

namespace hdeye {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTile = 16;
// Dimensions per pixel sample: room for the deepest path (world bounces times chamber walks) with no reuse.
constexpr std::uint64_t kDimsPerSample = std::uint64_t(1) << 16;

/// The random numbers of one pixel sample: dimension d of sample s of pixel p.
class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
      : seed_(seed), pixel_(pixel), base_(sample * kDimsPerSample) {}
  double Next() { return eyelib::UniformAt(seed_, pixel_, base_ + dim_++ % kDimsPerSample); }

 private:
  std::uint64_t seed_, pixel_, base_, dim_ = 0;
};

/// a^2 / (a^2 + b^2), as a ratio so that pdfs past 1e154 (a tiny light far away) do not overflow.
double PowerHeuristic(double a, double b) {
  if (!(a > 0)) return 0;
  const double q = b / a;
  return std::isfinite(q) ? 1 / (1 + q * q) : 0;
}

/// The UsdPreviewSurface BSDF of a non-eye hit: the bound material's parameters, with its diffuse
/// texture (looked up at the hit's st) replacing `albedo` (diffuseColor, or displayColor) where set.
PreviewSurface MaterialBsdf(const GeometryContext& context, const glm::dvec3& albedo, const glm::dvec2& st) {
  const MaterialParams& m = context.material;
  PreviewSurface s;
  s.albedo = context.diffuseTexture ? glm::dvec3(context.diffuseTexture->Lookup(glm::vec2(st))) : albedo;
  s.roughness = m.roughness;
  s.metallic = m.metallic;
  s.opacity = m.opacity;
  s.ior = m.ior;
  return s;
}


struct SurfaceHit {
  double t;
  glm::dvec3 p, n;  // n (the shading normal) faces the incoming ray
  glm::dvec3 ng{0};  // the geometric normal, facing the incoming ray
  glm::dvec3 albedo, emission;
  int primIndex;
  const GeometryContext* context;
  unsigned part;    // the primitive; for eyes, EyeGeometry::Part
  double u = 0, v = 0;  // barycentrics of the hit in triangle `part` (meshes)
  glm::dvec2 st{0};     // the mesh's "st" primvar at the hit (0 where not authored)
};

class Tracer {
 public:
  Tracer(RTCScene scene, const std::vector<RenderLight>& lights, const RenderSettings& settings)
      : scene_(scene), lights_(lights), settings_(settings) {}

  /// Closest hit of the scene's geometry along the ray, if any.
  bool Intersect(const glm::dvec3& o, const glm::dvec3& d, double tNear, double tFar, SurfaceHit* hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = float(o.x), rh.ray.org_y = float(o.y), rh.ray.org_z = float(o.z);
    rh.ray.dir_x = float(d.x), rh.ray.dir_y = float(d.y), rh.ray.dir_z = float(d.z);
    rh.ray.tnear = float(tNear);
    rh.ray.tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u, rh.ray.flags = 0, rh.ray.time = 0;
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    ++rays_;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    // Meshes sit under instances; eyes are user geometry in the root scene.
    const unsigned id = rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
    const auto* ctx = static_cast<const GeometryContext*>(rtcGetGeometryUserData(rtcGetGeometry(scene_, id)));
    hit->t = rh.ray.tfar;
    hit->p = o + hit->t * d;
    glm::dvec3 n = glm::normalize(ctx->normalToWorld * glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    if (glm::dot(n, d) > 0) n = -n;
    hit->ng = n;
    // Primvars at the hit: per-vertex values (triangleVertices) or per-corner ones (3 per triangle),
    // weighted by the hit's barycentrics.
    const double bu = rh.hit.u, bv = rh.hit.v, bw = 1 - bu - bv;
    const std::size_t firstCorner = 3 * std::size_t(rh.hit.primID);
    auto atCorners = [&](const auto& values) {
      using D = glm::vec<std::decay_t<decltype(values[0])>::length(), double>;
      return bw * D(values[firstCorner]) + bu * D(values[firstCorner + 1]) + bv * D(values[firstCorner + 2]);
    };
    // Smooth shading: authored corner normals, else the per-vertex normals, interpolated. The flat
    // geometric normal still decides the side: the shading normal is flipped onto the side the ray came
    // from, so the renderer's cosines (taken against hit->n and clamped at 0) stay on the lit side.
    // Analytic eyes, meshes without normals and degenerate (zero) normals keep the flat one.
    glm::dvec3 local(0);
    if (ctx->cornerNormals) {
      local = glm::dvec3(atCorners(*ctx->cornerNormals));
    } else if (ctx->vertexNormals && ctx->triangleVertices && !ctx->eye) {
      const int* tri = &(*ctx->triangleVertices)[firstCorner];
      const auto& vn = *ctx->vertexNormals;
      local = bw * glm::dvec3(vn[tri[0]]) + bu * glm::dvec3(vn[tri[1]]) + bv * glm::dvec3(vn[tri[2]]);
    }
    const glm::dvec3 shading = ctx->normalToWorld * local;
    const double length = glm::length(shading);
    if (length > 1e-12 && std::isfinite(length)) n = glm::dot(shading, n) < 0 ? -shading / length : shading / length;
    hit->n = n;
    hit->u = bu, hit->v = bv;
    hit->st = ctx->st ? glm::dvec2(atCorners(*ctx->st)) : glm::dvec2(0);
    hit->albedo = ctx->displayColor ? glm::dvec3(atCorners(*ctx->displayColor)) : glm::dvec3(ctx->material.diffuseColor);
    hit->emission = ctx->eye || ctx->meshEye ? glm::dvec3(0) : glm::dvec3(ctx->material.emissiveColor);
    hit->primIndex = ctx->primIndex;
    hit->context = ctx;
    hit->part = rh.hit.primID;
    return true;
  }

  /// What a sclera hit on an eye mesh did: reflected off the wet surface, or entered, walked and left.
  struct ScleraStep {
    enum Kind { Reflected, Exited, Ended } kind = Ended;
    glm::dvec3 origin{0}, dir{0};  ///< Reflected: the mirror ray
    glm::dvec3 point{0}, normal{0};  ///< Exited: the exit (world) and the outward shading normal there
    glm::dvec3 weight{0};            ///< Exited: the walk's RGB throughput
    bool teleported = false;         ///< Exited: the walk lit the limbal arc
  };

  /// The sclera of an eye mesh as a volume (DESIGN.md step 5): at the hit, a smooth dielectric boundary
  /// of the eye's tissue index (EyeParams' cornea ior: cornea and sclera share it) reflects with the
  /// Fresnel probability or refracts in; inside, eyelib's random walk runs in the canonical frame against
  /// the mesh itself (its own Embree scene), with the teleportation cylinder if the eye asks for it.
  /// Both Fresnel choices are sampled with their own probability, so no weight changes there.
  ScleraStep ScleraWalk(const EyeGeometry& eye, const SurfaceHit& hit, const glm::dvec3& d, const glm::dvec3& albedo,
                        bool limbalArc, const std::function<double()>& random) const {
    ScleraStep step;
    const GeometryContext& ctx = *hit.context;
    const double ior = eye.chamber.CorneaIor();
    // Fresnel against the shading normal (smooth highlights); which side is inside, against the
    // geometric one (the walk's boundary is the triangles themselves).
    const glm::dvec3 wo = -d;
    const double cosO = std::max(0.0, glm::dot(wo, hit.n));
    // Off the float triangles: 1e-5 of the eye's centimetre (so it scales with the scene's units) and of |p|.
    const double offset = 1e-5 * (10 * eye.worldPerMm + glm::length(hit.p));
    if (random() < eyelib::FresnelDielectric(cosO, ior)) {
      step.kind = ScleraStep::Reflected;
      step.dir = eyelib::Reflect(wo, hit.n);
      // A shading normal can tilt the mirror direction under the triangle: lift it just above.
      const double cosG = glm::dot(step.dir, hit.ng);
      if (cosG < 1e-4) step.dir = glm::normalize(step.dir + (1e-4 - cosG) * hit.ng);
      step.origin = hit.p + hit.ng * offset;
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
    const WorldBoundary boundary = EyeMeshBoundary(ctx.prototypeScene, eye.objectToWorld, &queries, &exitCrossing);
    ScleraScatteringSettings ws;
    ws.ior = ior;
    ws.limbalArc = limbalArc;
    const ScleraExit exit = ScatterInSclera(eye, hit.p, inward, albedo, eye.scleraMeanFreePath, boundary, random, ws);
    rays_ += queries;
    ++walks_;
    if (exit.teleported) ++teleportedWalks_;
    if (exit.status == eyelib::WalkStatus::Capped) ++cappedWalks_;
    if (exit.status == eyelib::WalkStatus::Invalid) ++invalidWalks_;
    if (!exit.Exited()) return step;

    step.kind = ScleraStep::Exited;
    step.point = exit.origin;
    step.weight = exit.weight;
    step.teleported = exit.teleported;
    // The outward shading normal at the exit: the mesh's interpolated normals at the last crossing,
    // if they agree with the geometric normal's side; else the geometric normal.
    step.normal = exit.normal;
    if (ctx.vertexNormals && ctx.triangleVertices && exitCrossing.triangle != RTC_INVALID_GEOMETRY_ID &&
        3 * std::size_t(exitCrossing.triangle) + 2 < ctx.triangleVertices->size()) {
      const int* tri = &(*ctx.triangleVertices)[3 * std::size_t(exitCrossing.triangle)];
      const auto& vn = *ctx.vertexNormals;
      const double bu = exitCrossing.u, bv = exitCrossing.v;
      const glm::dvec3 local = (1 - bu - bv) * glm::dvec3(vn[tri[0]]) + bu * glm::dvec3(vn[tri[1]]) + bv * glm::dvec3(vn[tri[2]]);
      const glm::dvec3 shading = ctx.normalToWorld * local;
      const double length = glm::length(shading);
      if (length > 1e-12 && std::isfinite(length) && glm::dot(shading, exit.normal) > 0) step.normal = shading / length;
    }
    return step;
  }

  bool Occluded(const glm::dvec3& o, const glm::dvec3& d, double tFar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = float(o.x), ray.org_y = float(o.y), ray.org_z = float(o.z);
    ray.dir_x = float(d.x), ray.dir_y = float(d.y), ray.dir_z = float(d.z);
    ray.tnear = 0;
    ray.tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
    ray.mask = ~0u, ray.flags = 0, ray.time = 0;
    rtcOccluded1(scene_, &context, &ray);
    ++rays_;
    return ray.tfar < 0;
  }

  /// The nearest light surface a ray meets before maxDistance (for BSDF-sampled rays), with its pdf.
  /// skipMneeOf: the ray left an iris straight through the cornea; the lights MNEE counted there
  /// (MneeCountsLight) are passed over as if absent -- MNEE's own shadow rays treat lights as transparent,
  /// so a light behind one of them (a dome behind a key) is counted here as MNEE would not.
  bool HitLight(const glm::dvec3& o, const glm::dvec3& d, double maxDistance, glm::dvec3* radiance, double* pdf,
                const EyeLighting* skipMneeOf = nullptr) const {
    double best = kInf;
    bool found = false;
    for (std::size_t k = 0; k < lights_.size(); ++k) {
      if (skipMneeOf && MneeCountsLight(*skipMneeOf, k)) continue;
      const RenderLight& l = lights_[k];
      glm::dvec3 le(0);
      double lpdf = 0, dist = kInf;
      if (IntersectLight(l, o, d, std::min(maxDistance, best), &le, &lpdf, &dist) && (!found || dist < best)) {
        best = dist, *radiance = le, *pdf = lpdf, found = true;
      }
    }
    return found;
  }

  /// Radiance along a camera ray; fills the first hit for the data AOVs.
  glm::dvec3 Li(glm::dvec3 o, glm::dvec3 d, double tNear, double tFar, SampleStream& rng, SurfaceHit* first,
                bool* hitAny, glm::dvec3* irisMnee, glm::dvec3* limbalArc) const {
    glm::dvec3 L(0), beta(1);
    // The limbal-arc AOV: everything the path gathers after its first teleported sclera walk (L only
    // grows, so L at the end minus L then).
    bool arc = false;
    glm::dvec3 lAtArc(0);
    // How the current ray was chosen, for weighting the lights it meets: after a specular event
    // (the camera, the cornea) a light counts in full; after a diffuse bounce, by MIS against light
    // sampling (or not at all without MIS); straight out of an iris (skipMnee), the lights MNEE counted
    // there not at all, and every other light in full. Why in full and not by MIS: the iris bounce's
    // cosine-hemisphere pdf exists, but for a light MNEE does not handle there is no second strategy at
    // the iris (light sampling cannot see through the refracting cornea; that is what MNEE is for), so
    // the path leaving the iris is that light's only estimator and its weight is 1. Nor is MNEE MIS-
    // weighted against the exiting path for the lights it does handle: its one-solution search has no
    // known pdf over exit directions, so the two are a partition, light by light, never a mixture.
    bool specular = true, skipLights = false, skipMnee = false;
    EyeLighting skipMneeOf;  // skipMnee: the lighting of the iris the path left (its MNEE lights)
    // Whether the path is inside a glass (opacity < 1) object: flipped at every refraction. Hits carry
    // no front/back flag, so this assumes the camera is outside and glass objects are closed and
    // do not nest.
    bool insideGlass = false;
    double bsdfPdf = 0;
    const double lightSelect = lights_.empty() ? 0 : 1.0 / double(lights_.size());
    const std::function<double()> random = [&rng] { return rng.Next(); };
    EyeLighting eyeLighting{&lights_, [this](const glm::dvec3& po, const glm::dvec3& pd, double t) {
                              return Occluded(po, pd, t);
                            }, settings_.mneeAllSolutions, settings_.mnee};
    static const EyeRenderOptions kUnplanned;  // the walk bound of an eye no plan was applied to
    for (int depth = 0; depth <= settings_.maxDepth; ++depth) {
      SurfaceHit hit;
      const bool hitGeometry = Intersect(o, d, tNear, tFar, &hit);
      if (depth == 0) {
        *hitAny = hitGeometry;
        if (hitGeometry) *first = hit;
      }
      glm::dvec3 le(0);
      double lpdf = 0;
      if (!skipLights && HitLight(o, d, hitGeometry ? hit.t : kInf, &le, &lpdf, skipMnee ? &skipMneeOf : nullptr)) {
        if (specular) L += beta * le;
        else if (settings_.mis) L += beta * le * PowerHeuristic(bsdfPdf, lpdf * lightSelect);
      }
      if (!hitGeometry) break;
      L += beta * hit.emission;

      if (const EyeGeometry* eye = hit.context->eye ? hit.context->eye : hit.context->meshEye) {
        // This eye's switches: the render plan's (EyeRenderOptions, written by ApplyRenderPlan), else the
        // global settings.
        const EyeRenderOptions& options = hit.context->eyeOptions;
        const bool planned = options.planned;
        eyeLighting.mnee = planned ? options.mnee : settings_.mnee;
        eyeLighting.allSolutions = planned ? options.allSolutions : settings_.mneeAllSolutions;
        eyeLighting.mneeLights = planned ? &options.mneeLights : nullptr;
        eyeLighting.maxChamberEvents = planned ? options.maxChamberEvents : kUnplanned.maxChamberEvents;
        const bool scleraScattering = planned ? options.scleraScattering : settings_.scleraScattering;
        const bool limbalArc = planned ? options.limbalArc : eye->limbalArc;
        const EyeEvent ev =
            hit.context->eye
                ? ScatterAtEye(*eye, o, d, EyeGeometry::Part(hit.part), eyeLighting, random)
                : ScatterAtEyeMesh(*eye, EyeMeshHitToCanonical(*hit.context, *eye, hit.part, hit.u, hit.v, d), d,
                                   eyeLighting, random);
        L += beta * ev.radiance;
        *irisMnee += beta * ev.radiance;
        if (ev.kind == EyeEvent::Continue) {
          beta *= ev.weight;
          o = ev.origin, d = ev.dir, tNear = 0, tFar = kInf;
          if (!ev.passThrough) {
            specular = true, skipLights = false, skipMnee = ev.skipLightHits;
            if (skipMnee) skipMneeOf = eyeLighting;
          }
          continue;
        }
        if (ev.kind == EyeEvent::Absorbed) break;
        // Sclera: shaded below as a diffuse surface; an eye mesh's own surface keeps its shading normal
        // and, with a bound material, that material's colour (its diffuse texture at the hit's st, if any).
        if (!ev.scleraOnSurface) hit.n = glm::dot(ev.normal, d) > 0 ? -ev.normal : ev.normal;
        if (!ev.scleraOnSurface || !eye->scleraUsesMaterial) hit.albedo = ev.scleraAlbedo;
        else if (hit.context->diffuseTexture) hit.albedo = glm::dvec3(hit.context->diffuseTexture->Lookup(glm::vec2(hit.st)));
        hit.albedo = glm::clamp(hit.albedo, glm::dvec3(0), glm::dvec3(1));  // an albedo above 1 adds energy
        if (depth == 0) first->albedo = hit.albedo;  // the albedo AOV shows the sclera's
        // An eye mesh's sclera is a volume: the path walks through it instead of bouncing off a Lambert
        // surface (only meshes have a closed eyeball to walk in; the analytic eye's sclera stays diffuse).
        if (ev.scleraOnSurface && scleraScattering && hit.context->prototypeScene) {
          const ScleraStep step = ScleraWalk(*eye, hit, d, hit.albedo, limbalArc, random);
          if (step.kind == ScleraStep::Ended) break;
          if (step.kind == ScleraStep::Reflected) {  // a delta lobe: lights it meets count in full
            o = step.origin, d = step.dir, tNear = 0, tFar = kInf;
            specular = true, skipLights = false, skipMnee = false;
            continue;
          }
          // The exit is a diffuse transmission lobe: the walk decides where light leaves and how much
          // (its Fresnel test at the boundary included); the direction it leaves in is then taken as
          // Lambertian about the exit's outward normal, as Cycles and Hyperion do. The walk's own
          // refracted exit direction is dropped, not followed: its pdf is unknown (it depends on the
          // whole walk), so it could be neither MIS-weighted against light sampling nor combined with
          // next event estimation at the exit without counting the light twice. With a Lambertian lobe,
          // next event estimation and the sampled continuation below are weighted by the power
          // heuristic like any diffuse bounce. What this approximates: light refracted out of a
          // dielectric is Lambertian times (1 - F(theta)), a little darker at grazing exit.
          if (!arc && step.teleported) arc = true, lAtArc = L;
          beta *= step.weight;
          hit.p = step.point;
          hit.n = hit.ng = step.normal;
          hit.albedo = glm::dvec3(1);  // the colour is in the walk's weight
          d = -step.normal;            // wo = the outward normal: the lobe is the outward hemisphere
        }
      }
      // Sclera (and any eye surface handed back to us) is Lambertian; everything else is the bound
      // UsdPreviewSurface.
      const bool eyeSurface = hit.context->eye || hit.context->meshEye;
      const PreviewSurface bsdf =
          eyeSurface ? PreviewSurface::Lambert(hit.albedo) : MaterialBsdf(*hit.context, hit.albedo, hit.st);
      if (depth == 0 && !eyeSurface) first->albedo = bsdf.albedo;  // the albedo AOV shows the texture
      const glm::dvec3 wo = -d;
      // Offset off the surface by more than Embree's float hit error (a few ulps of |p|); on an eye, the
      // absolute part is 1e-5 of the eye's centimetre, so that eyes render alike in any scene units.
      const EyeGeometry* surfaceEye = hit.context->eye ? hit.context->eye : hit.context->meshEye;
      const double offset = 1e-5 * ((surfaceEye ? 10 * surfaceEye->worldPerMm : 1.0) + glm::length(hit.p));
      const glm::dvec3 origin = hit.p + hit.n * offset;

      // Next event estimation: one light chosen uniformly; not for mirrors and glass (delta lobes).
      const double uPick = rng.Next(), u1 = rng.Next(), u2 = rng.Next();
      if (!lights_.empty() && HasSmoothLobe(bsdf, hit.n, wo)) {
        const RenderLight& light = lights_[std::min(lights_.size() - 1, std::size_t(uPick * lights_.size()))];
        const LightSample ls = SampleLight(light, origin, u1, u2);
        const double cosS = glm::dot(ls.dir, hit.n);
        if (ls.pdf > 0 && cosS > 0) {
          const glm::dvec3 f = EvalPreviewSurface(bsdf, hit.n, wo, ls.dir);
          if ((f.x > 0 || f.y > 0 || f.z > 0) && !Occluded(origin, ls.dir, ls.distance * (1 - 1e-6))) {
            const double pl = ls.pdf * lightSelect;
            const double w = settings_.mis ? PowerHeuristic(pl, PdfPreviewSurface(bsdf, hit.n, wo, ls.dir)) : 1.0;
            L += beta * f * ls.radiance * (cosS * w / pl);
          }
        }
      }

      // Continue in a direction sampled from the BSDF; its weight is f |cos| / pdf.
      const double uLobe = rng.Next(), uDir1 = rng.Next(), uDir2 = rng.Next();
      BsdfSample bs;
      if (!SamplePreviewSurface(bsdf, hit.n, wo, insideGlass, uLobe, uDir1, uDir2, &bs)) break;
      if (bs.transmitted) insideGlass = !insideGlass;
      d = bs.wi;
      bsdfPdf = bs.pdf;
      specular = bs.delta, skipLights = !bs.delta && !settings_.mis, skipMnee = false;
      beta *= bs.weight;
      o = glm::dot(d, hit.n) > 0 ? origin : hit.p - hit.n * offset;
      tNear = 0;
      tFar = kInf;
      // Russian roulette after three bounces.
      if (depth >= 3) {
        const double q = std::min(0.95, std::max({beta.x, beta.y, beta.z}));
        if (rng.Next() >= q) break;
        beta /= q;
      }
    }
    if (arc) *limbalArc = L - lAtArc;
    return L;
  }

  std::int64_t Rays() const { return rays_; }
  std::int64_t Walks() const { return walks_; }
  std::int64_t TeleportedWalks() const { return teleportedWalks_; }
  std::int64_t CappedWalks() const { return cappedWalks_; }
  std::int64_t InvalidWalks() const { return invalidWalks_; }

 private:
  RTCScene scene_;
  const std::vector<RenderLight>& lights_;
  const RenderSettings& settings_;
  mutable std::int64_t rays_ = 0;
  mutable std::int64_t walks_ = 0, teleportedWalks_ = 0, cappedWalks_ = 0, invalidWalks_ = 0;
};

}  // namespace

RenderStats Renderer::Render(RTCScene scene, const CameraView& camera, const std::vector<RenderLight>& lights,
                             const RenderSettings& settings, const AovBuffers& aovs) const {
  if (!aovs.color) throw std::invalid_argument("render: a color buffer must be bound");
  const int width = aovs.color->Width(), height = aovs.color->Height();
  for (RenderBuffer* b : {aovs.albedo, aovs.normal, aovs.depth, aovs.primId, aovs.irisMnee, aovs.limbalArc})
    if (b && (b->Width() != width || b->Height() != height))
      throw std::invalid_argument("render: every bound buffer must be " + std::to_string(width) + " x " +
                                  std::to_string(height));
  RenderStats stats;
  if (width == 0 || height == 0) return stats;
  const auto start = std::chrono::steady_clock::now();
  const int tilesX = (width + kTile - 1) / kTile, tilesY = (height + kTile - 1) / kTile;
  const double aspect = double(width) / height;
  std::atomic<std::int64_t> rays{0}, nonFinite{0}, walks{0}, teleported{0}, capped{0}, invalid{0};
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);

  // One pass per sample index, so a time limit stops between whole passes and every pixel has
  // the same samples.
  for (int pass = 0; pass < settings.samplesPerPixel; ++pass) {
    const int s = settings.firstSample + pass;
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& range) {
        Tracer tracer(scene, lights, settings);
        for (int tile = range.begin(); tile != range.end(); ++tile) {
          const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
          for (int y = y0; y < std::min(height, y0 + kTile); ++y)
            for (int x = x0; x < std::min(width, x0 + kTile); ++x) {
              SampleStream rng(settings.seed, std::uint64_t(y) * width + x, std::uint64_t(s));
              const double jx = s == 0 ? 0.5 : rng.Next(), jy = s == 0 ? 0.5 : rng.Next();
              const WorldRay ray = camera.GenerateRay((x + jx) / width, (y + jy) / height, aspect);
              SurfaceHit first{};
              bool hitAny = false;
              glm::dvec3 irisMnee(0), arc(0);
              glm::dvec3 L =
                  tracer.Li(ray.origin, ray.dir, ray.tNear, ray.tFar, rng, &first, &hitAny, &irisMnee, &arc);
              if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z)) {
                L = irisMnee = arc = glm::dvec3(0);  // never let it into the image; count it so tests can fail on it
                ++nonFinite;
              }
              const float color[4] = {float(L.x), float(L.y), float(L.z), hitAny ? 1.0f : 0.0f};
              aovs.color->AddSample(x, y, color);
              if (aovs.irisMnee) {
                const float iris[3] = {float(irisMnee.x), float(irisMnee.y), float(irisMnee.z)};
                aovs.irisMnee->AddSample(x, y, iris);
              }
              if (aovs.limbalArc) {
                const float a[3] = {float(arc.x), float(arc.y), float(arc.z)};
                aovs.limbalArc->AddSample(x, y, a);
              }
              if (s != 0) continue;
              const glm::dvec3 albedo = hitAny ? first.albedo : glm::dvec3(0), n = hitAny ? first.n : glm::dvec3(0);
              const float a[3] = {float(albedo.x), float(albedo.y), float(albedo.z)};
              const float nn[3] = {float(n.x), float(n.y), float(n.z)};
              const float depth = hitAny ? float(first.t) : 0.0f, id = hitAny ? float(first.primIndex) : -1.0f;
              if (aovs.albedo) aovs.albedo->AddSample(x, y, a);
              if (aovs.normal) aovs.normal->AddSample(x, y, nn);
              if (aovs.depth) aovs.depth->AddSample(x, y, &depth);
              if (aovs.primId) aovs.primId->AddSample(x, y, &id);
            }
        }
        rays += tracer.Rays();
        walks += tracer.Walks();
        teleported += tracer.TeleportedWalks();
        capped += tracer.CappedWalks();
        invalid += tracer.InvalidWalks();
      });
    });
    ++stats.passes;
    stats.samples += std::int64_t(width) * height;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (settings.timeLimitSeconds > 0 && elapsed >= settings.timeLimitSeconds && pass + 1 < settings.samplesPerPixel) {
      stats.timeLimitReached = true;
      break;
    }
  }
  stats.rays = rays;
  stats.nonFiniteSamples = nonFinite;
  stats.scleraWalks = walks;
  stats.teleportedWalks = teleported;
  stats.cappedWalks = capped;
  stats.invalidWalks = invalid;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace hdeye
