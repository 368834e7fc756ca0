#include "hdeye/render/chamberLightCache.h"

#include "hdeye/render/eyeShading.h"

#include <eyelib/random.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstring>

namespace hdeye {

namespace {

/// FNV-1a over the bytes of values whose bytes are their value (doubles, ints, pointers: no padding).
class KeyHash {
 public:
  template <class T> KeyHash& Add(const T& v) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));
    for (unsigned char b : bytes) h_ = (h_ ^ b) * 0x100000001b3ull;
    return *this;
  }
  KeyHash& Add(const glm::dvec3& v) { return Add(v.x).Add(v.y).Add(v.z); }
  KeyHash& Add(bool v) { return Add(int(v)); }
  KeyHash& Add(const std::vector<char>& v) {
    Add(v.size());
    for (char c : v) Add(int(c));
    return *this;
  }
  std::uint64_t Value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

/// The fixed stream the cache's MNEE estimates draw from (no render seed: the cache is the same for every seed).
constexpr std::uint64_t kCacheSeed = 0x63686d6272636163ull;

}  // namespace

eyelib::IrisPolarGrid ChamberCacheGrid(int rings) {
  eyelib::IrisPolarGrid grid;
  grid.rings = std::max(1, rings), grid.sectors = 3 * grid.rings;
  return grid;
}

eyelib::IrisChamberCache BuildChamberLightCache(const EyeGeometry& eye, const eyelib::IrisChamberTransport& transport,
                                                PerThreadLighting lighting, int directSamples) {
  const int nodes = transport.Nodes(), samples = std::max(1, directSamples);
  const eyelib::IrisPolarGrid& grid = transport.Grid();
  std::vector<glm::dvec3> direct(nodes, glm::dvec3(0));
  tbb::parallel_for(0, grid.rings, [&](int ring) {
    lighting([&](const EyeLighting& here) {
      for (int i = ring * grid.sectors; i < (ring + 1) * grid.sectors; ++i) {
        std::uint64_t dim = 0;
        const auto random = [&] { return eyelib::UniformAt(kCacheSeed, std::uint64_t(i), dim++); };
        glm::dvec3 sum(0);
        for (int k = 0; k < samples; ++k) sum += IrisIrradianceMnee(eye, transport.Node(i), here, random);
        direct[i] = sum / double(samples);
      }
    });
  });
  // Each node's albedo: the mean over its cell (4 x 4 points), so a textured iris's fine detail averages out
  // instead of aliasing into the chamber light.
  const double dr = (transport.OuterRadius() - transport.InnerRadius()) / grid.rings, dphi = transport.SectorAngle();
  constexpr int kAlbedoSide = 4;
  std::vector<glm::dvec3> albedo(nodes, glm::dvec3(0));
  for (int i = 0; i < nodes; ++i) {
    const int ring = i / grid.sectors, sector = i % grid.sectors;
    for (int a = 0; a < kAlbedoSide; ++a)
      for (int b = 0; b < kAlbedoSide; ++b) {
        const double r = transport.InnerRadius() + (ring + (a + 0.5) / kAlbedoSide) * dr,
                     phi = (sector + (b + 0.5) / kAlbedoSide) * dphi;
        albedo[i] += eye.IrisAlbedo(glm::dvec3(r * std::cos(phi), r * std::sin(phi), transport.IrisZ()));
      }
    albedo[i] /= double(kAlbedoSide * kAlbedoSide);
  }
  const auto onThreads = [](int count, eyelib::FunctionRef<void(int)> body) {
    tbb::parallel_for(0, count, [&](int i) { body(i); });
  };
  return eyelib::IrisChamberCache(transport, direct, albedo, onThreads);
}

void ChamberLightCaches::BeginRender(const std::vector<RenderLight>& lights, std::uint64_t sceneVersion) {
  KeyHash h;
  h.Add(sceneVersion).Add(lights.size());
  for (const RenderLight& l : lights) {
    h.Add(int(l.type)).Add(l.radiance).Add(l.delta).Add(l.position).Add(l.direction).Add(l.axisU).Add(l.axisV);
    h.Add(l.radius).Add(l.cosHalfAngle).Add(l.dome.get()).Add(l.rectImage.get()).Add(l.unlit).Add(l.unshadowed);
    h.Add(l.shaping.enabled).Add(l.shaping.cutoff).Add(l.shaping.smoothStart).Add(l.shaping.focus);
    h.Add(l.shaping.focusTint).Add(l.shaping.ies.get()).Add(l.shaping.iesProfileScale).Add(l.shaping.iesFactor);
    h.Add(l.frameX).Add(l.frameY).Add(l.halfLength).Add(l.motion.get());
    for (int c = 0; c < 3; ++c) h.Add(l.domeToWorld[c][0]).Add(l.domeToWorld[c][1]).Add(l.domeToWorld[c][2]);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  renderKey_ = h.Value();
}

std::shared_ptr<const eyelib::IrisChamberCache> ChamberLightCaches::Get(const void* owner, const EyeGeometry& eye,
                                                                        const EyeLighting& lighting, int rings,
                                                                        PerThreadLighting perThread) {
  const eyelib::ChamberParams& chamber = eye.chamber.Params();
  const eyelib::IrisPolarGrid grid = rings > 0 ? ChamberCacheGrid(rings) : resolution_.grid;
  KeyHash geometry;
  geometry.Add(int(chamber.model)).Add(chamber.irisDepth).Add(chamber.pupilDiameter).Add(chamber.corneaIor);
  geometry.Add(lighting.maxChamberEvents).Add(grid.rings).Add(grid.sectors).Add(grid.directionsPerSide);
  const std::uint64_t geometryKey = geometry.Value();
  KeyHash key = geometry;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) key.Add(eye.canonicalToWorld[c][r]);
  key.Add(eye.irisColor).Add(eye.irisTexture.get()).Add(lighting.receiver).Add(lighting.switches.mneeAllSolutions);
  key.Add(lighting.switches.mnee).Add(lighting.mneeLights ? lighting.mneeLights->size() : std::size_t(0));
  if (lighting.mneeLights)
    for (bool b : *lighting.mneeLights) key.Add(b);
  std::shared_ptr<Slot<eyelib::IrisChamberTransport>> transport;
  std::shared_ptr<Slot<eyelib::IrisChamberCache>> cache;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    key.Add(renderKey_);
    auto& t = transports_[geometryKey];
    if (!t) t = std::make_shared<Slot<eyelib::IrisChamberTransport>>();
    transport = t;
    Entry& entry = entries_[owner];
    if (!entry.cache || entry.key != key.Value()) {
      entry.cache = std::make_shared<Slot<eyelib::IrisChamberCache>>();
      entry.key = key.Value();
      ++builds_;
    }
    cache = entry.cache;
  }
  tbb::collaborative_call_once(cache->once, [&] {
    tbb::collaborative_call_once(transport->once, [&] {
      // The geometry's chamber paths per ring, in parallel (each ring's its own), then stored in ring order.
      std::vector<std::vector<eyelib::IrisChamberTransport::Landing>> rings(grid.rings);
      tbb::parallel_for(std::size_t(0), rings.size(), [&](std::size_t r) {
        rings[r] = eyelib::IrisChamberTransport::RingLandings(eye.chamber, grid, int(r), lighting.maxChamberEvents);
      });
      transport->value = std::make_shared<const eyelib::IrisChamberTransport>(eye.chamber, grid, rings);
    });
    cache->value = std::make_shared<const eyelib::IrisChamberCache>(
        BuildChamberLightCache(eye, *transport->value, perThread, resolution_.directSamples));
  });
  return cache->value;
}

}  // namespace hdeye
