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

/// Where a pixel sample's camera path starts: its ray (jittered in the pixel, through its lens point, at its time), the
/// ray's footprint and its time.
struct CameraSample {
  WorldRay ray;
  RayCone cone;
  double time;
};

/// The camera rays of one render's pixels.
class FilmSampler {
 public:
  FilmSampler(const CameraView& camera, const RenderSettings& settings, int width, int height, bool textured)
      : camera_(camera),
        settings_(settings),
        shutter_(camera.GetShutter()),
        width_(width),
        height_(height),
        invWidth_(1.0 / width),
        invHeight_(1.0 / height),
        aspect_(FilmAspect(settings, width, height)),
        cones_(textured && settings.textureFiltering) {}

  const Shutter& GetShutter() const { return shutter_; }

  /// Sample `s` of pixel (x, y) from its stream: at the pixel's centre if `centred`, else jittered.
  CameraSample At(int x, int y, std::uint64_t s, bool centred, SampleStream& rng) const {
    double jx = 0.5, jy = 0.5;
    if (!centred) rng.PixelJitter(&jx, &jy);
    const double time = PathTime(shutter_, settings_.timeStrata, s, rng);
    const std::optional<CameraView> moved = camera_.motion ? std::optional(camera_.AtTime(time)) : std::nullopt;
    const CameraView& view = moved ? *moved : camera_;
    const bool lens = view.HasLens();
    const double lensU = lens ? rng.FromTop(0) : 0.5, lensV = lens ? rng.FromTop(1) : 0.5;
    const WorldRay ray = view.GenerateRay((x + jx) * invWidth_, (y + jy) * invHeight_, aspect_, lensU, lensV);
    // Only texture lookups read the cone (and only when filtering): without them it is never computed.
    const RayCone cone = cones_ ? PixelCone(view, ray, x + jx, y + jy, width_, height_, aspect_, lensU, lensV,
                                            settings_.textureFootprintScale)
                                : RayCone{};
    return {ray, cone, time};
  }

 private:
  const CameraView& camera_;
  const RenderSettings& settings_;
  Shutter shutter_;
  int width_, height_;
  double invWidth_, invHeight_, aspect_;
  bool cones_;
};

/// The cornea's reflection at the first eye event of sample `s` of a catchlight pixel (catchlightPixels.h), from
/// RenderSettings::catchlightSamples reflection-only paths, each 1 / N of it, added to the sample: sub-sample k is
/// sample s N + k of the catchlight's own stream (its own seed), so over the pixel's samples its jitter, lens and time
/// points are one stratified sequence.
void AddCatchlightSubSamples(const FilmSampler& film, Tracer& tracer, const RenderSettings& settings, int x, int y,
                             int width, std::uint64_t s, const eyelib::ZSobolKeyTable* keys, PathSample* sample) {
  const int n = settings.catchlightSamples;
  const double w = 1.0 / n;
  for (int k = 0; k < n; ++k) {
    const std::uint64_t sub = s * std::uint64_t(n) + std::uint64_t(k);
    SampleStream rng(settings.sampler, CatchlightSeed(settings.seed), x, y, width, sub, keys);
    const CameraSample camera = film.At(x, y, sub, false, rng);
    const PathSample r = tracer.Li(camera.ray, camera.cone, rng, camera.time, CameraReflection::Only);
    sample->L += w * r.L;
    sample->irisMnee += w * r.irisMnee;
    for (int part = 0; part < kEyeParts; ++part) sample->parts[part] += w * r.parts[part];
  }
}

}  // namespace

double FilmAspect(const RenderSettings& settings, int width, int height) {
  // Non-square pixels (RenderSettings::pixelAspectRatio) stretch the film.
  const double par =
      std::isfinite(settings.pixelAspectRatio) && settings.pixelAspectRatio > 0 ? settings.pixelAspectRatio : 1;
  return double(width) * par / height;
}

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
                 SharedCounts* counts, ChamberLightCaches* chamberCaches, const SampleKeys& keys,
                 const CatchlightPixels& catchlights) {
  const int width = aovs.color->Width(), height = aovs.color->Height();
  const int tilesX = (width + kTile - 1) / kTile;
  const FilmSampler film(camera, settings, width, height, textured);
  Tracer tracer(scene, lights, settings, cutouts, film.GetShutter(), chamberCaches);
  for (int tile = range.begin(); tile != range.end(); ++tile) {
    const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
    for (int y = y0; y < std::min(height, y0 + kTile); ++y)
      for (int x = x0; x < std::min(width, x0 + kTile); ++x) {
        const bool catchlight = catchlights.Has(x, y);  // none are found without sub-samples to give them
        for (int s = firstSample; s < firstSample + samples && grid.Has(x, y); ++s) {
          SampleStream rng(settings.sampler, settings.seed, x, y, width, std::uint64_t(s), keys.path);
          const CameraSample c = film.At(x, y, std::uint64_t(s), s == 0, rng);  // sample 0: the data AOVs' centre
          PathSample sample =
              tracer.Li(c.ray, c.cone, rng, c.time, catchlight ? CameraReflection::Left : CameraReflection::Traced);
          if (catchlight) AddCatchlightSubSamples(film, tracer, settings, x, y, width, s, keys.catchlight, &sample);
          if (!AddPathSample(aovs, x, y, s, sample)) ++counts->nonFinite;
        }
      }
  }
  counts->Add(tracer.GetCounts());
}

}  // namespace hdeye
