// The tracer's closest hits: the Embree query, the hit's primvars (normals, st, colours) and its bound material.
#include "hdeye/render/tracer.h"

#include <algorithm>
#include <type_traits>

namespace hdeye {

namespace {

/// The material of triangle (or primitive) `part` of a geometry: its geomSubset's, else the prim's own.
const SurfaceMaterial& MaterialAt(const GeometryContext& context, unsigned part) {
  if (context.triangleSubsets && part < context.triangleSubsets->size()) {
    const int subset = (*context.triangleSubsets)[part];
    if (subset >= 0 && std::size_t(subset) < context.subsetMaterials.size()) return context.subsetMaterials[subset];
  }
  return context.surface;
}

}  // namespace

bool Tracer::Intersect(const glm::dvec3& o, const glm::dvec3& d, double tNear, double tFar, SurfaceHit* hit,
                       const EyeGeometry* leaving) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = float(o.x), rh.ray.org_y = float(o.y), rh.ray.org_z = float(o.z);
  rh.ray.dir_x = float(d.x), rh.ray.dir_y = float(d.y), rh.ray.dir_z = float(d.z);
  rh.ray.tnear = float(tNear);
  rh.ray.tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
  rh.ray.mask = ~0u, rh.ray.flags = 0, rh.ray.time = rayTime_;
  rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  EyeRayExchange& exchange = *eyeRays_;
  const ExactCorneaHit& cornea = exchange.cornea;
  exchange.cornea.eye = nullptr;
  exchange.leaving = leaving;
  rtcIntersect1(scene_, &context, &rh);
  exchange.leaving = nullptr;  // rays traced elsewhere on this thread leave no eye
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
  // The callback intersected a moving eye at the float ray time, not at the path's: shading intersects it again.
  const bool exact = ctx->eye && cornea.eye == ctx->eye && cornea.t == rh.ray.tfar && !ctx->eye->motion;
  hit->cornea = exact ? std::optional(cornea.at) : std::nullopt;
  FillPrimvars(normalToWorld, hit);
  return true;
}

void Tracer::FillPrimvars(const glm::dmat3& normalToWorld, SurfaceHit* hit) {
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

glm::dvec3 Tracer::VertexNormalAt(const GeometryContext& ctx, const int* tri, double u, double v, float rayTime) {
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

StFrame Tracer::TriangleStFrameAt(const GeometryContext& ctx, const glm::dmat3& normalToWorld,
                                  std::size_t firstCorner) {
  const int* tri = &(*ctx.triangleVertices)[firstCorner];
  const glm::dmat3 toWorld = glm::inverse(glm::transpose(normalToWorld));  // the instance's linear part
  const auto& pts = *ctx.points;
  const auto& st = *ctx.st;
  return TriangleStFrame(toWorld * glm::dvec3(pts[tri[0]]), toWorld * glm::dvec3(pts[tri[1]]),
                         toWorld * glm::dvec3(pts[tri[2]]), glm::dvec2(st[firstCorner]),
                         glm::dvec2(st[firstCorner + 1]), glm::dvec2(st[firstCorner + 2]));
}

TextureSite Tracer::SiteOf(const SurfaceHit& hit, const glm::dvec3& d, const RayCone& cone) const {
  TextureSite site;
  site.st = hit.st;
  site.frame = hit.stFrame;
  if (settings_.textureFiltering && hit.material->textures)  // only textured inputs look at the footprint
    site.footprint = FootprintOnSurface(cone.WidthAt(hit.t), d, hit.ng, hit.stFrame);
  site.thread = textureThread_;
  return site;
}

SurfaceShading Tracer::ShadeMaterialHit(SurfaceHit* hit, const glm::dvec3& d, const RayCone& cone) const {
  SurfaceShading shading = ShadeMaterial(*hit->material, hit->albedo, -d, hit->n, SiteOf(*hit, d, cone));
  shading.bsdf.thinWalled = hit->context->thinWalled;
  hit->emission = shading.emission;
  hit->n = shading.normal;
  hit->normalMapped = shading.normalMapped;
  return shading;
}
}  // namespace hdeye
