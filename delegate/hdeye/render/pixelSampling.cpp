#include "hdeye/render/pixelSampling.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace hdeye {

namespace {

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

}  // namespace

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

}  // namespace hdeye
