#pragma once
// Chamber light (light that reaches the iris after leaving the iris and reflecting off the cornea's inside) from a
// cache instead of from the chamber walk alone finding the lit part of the iris by chance. Per eye, a polar grid over
// the iris (eyelib's IrisChamberCache) is built from MNEE at its nodes, with the render's own lights and shadow
// rays, the first time a render needs it, and kept while the eye, its lights and the scene stay the same: a
// progressive render (one Render call per sample) builds it once. Its build uses no random number of the render, so
// every sample stays a pure function of (seed, pixel, sample index) and split sample ranges still merge exactly.
#include "hdeye/render/entryTables.h"
#include "hdeye/render/eyeGeometry.h"
#include "hdeye/render/renderLight.h"
#include "hdeye/render/renderSettings.h"

#include <eyelib/function_ref.h>
#include <eyelib/iris_chamber_cache.h>
#include <tbb/collaborative_call_once.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace hdeye {

struct EyeLighting;

/// The resolution of the cache and of the first-order irradiance it is built from.
struct ChamberCacheResolution {
  /// The grid of an eye without a planned ring count (EyeRenderOptions::chamberCacheRings 0); a planned eye gets
  /// ChamberCacheGrid(rings).
  eyelib::IrisPolarGrid grid;
  int directSamples = 8;  ///< MNEE estimates averaged per node (a light point each)
};

/// The cache grid of `rings` rings: three sectors per ring (the default grid's aspect) and the default directions.
eyelib::IrisPolarGrid ChamberCacheGrid(int rings);

/// Calls `body` with the eye's lighting whose shadow test the calling thread may use. The cache's MNEE runs on
/// every thread that joins its build, and a shadow ray needs its thread's own renderer state (counters, texture
/// handles): so the lighting is asked for per thread, and the callable must be safe to call from several at once.
using PerThreadLighting = eyelib::FunctionRef<void(eyelib::FunctionRef<void(const EyeLighting&)> body)>;

/// Builds an eye's cache: MNEE's first-order irradiance at the transport's nodes (directSamples estimates each, from
/// a fixed random stream per node, in parallel over rings: the result does not depend on the thread count), the
/// iris albedo where each chamber path lands, then the fixed point. World-unit irradiance, as IrisIrradianceMnee's.
/// Zero where no light reaches the iris.
eyelib::IrisChamberCache BuildChamberLightCache(const EyeGeometry& eye, const eyelib::IrisChamberTransport& transport,
                                                PerThreadLighting lighting, int directSamples);

/// The caches of a renderer's eyes, across its Render calls.
class ChamberLightCaches {
 public:
  explicit ChamberLightCaches(ChamberCacheResolution resolution = {}) : resolution_(resolution) {}
  /// A render starts: its lights and scene version (RenderPass's committed Embree scene) are part of every key.
  void BeginRender(const std::vector<RenderLight>& lights, std::uint64_t sceneVersion);
  /// The cache of the eye that `owner` (its GeometryContext) holds, under `lighting` (its lights, receiver,
  /// switches), on a grid of `rings` rings (ChamberCacheGrid; 0: the resolution's grid); built here if missing or
  /// stale, its MNEE shadow rays traced through `perThread`. Thread-safe: the render's threads that need a cache
  /// being built join its build (tbb::collaborative_call_once) instead of waiting idle; the result does not depend
  /// on how many do.
  std::shared_ptr<const eyelib::IrisChamberCache> Get(const void* owner, const EyeGeometry& eye,
                                                      const EyeLighting& lighting, int rings,
                                                      PerThreadLighting perThread);
  int Builds() const { return builds_; }
  /// The eyes' entry-point tables (entryTables.h), kept alongside: they outlive renders as the caches do.
  EntryTableCache& EntryTables() { return entryTables_; }

 private:
  /// One build, done once by whichever threads arrive.
  template <class T> struct Slot {
    tbb::collaborative_once_flag once;
    std::shared_ptr<const T> value;
  };
  struct Entry {
    std::uint64_t key = 0;
    std::shared_ptr<Slot<eyelib::IrisChamberCache>> cache;
  };
  ChamberCacheResolution resolution_;
  std::mutex mutex_;  ///< guards the maps and keys, never held during a build
  std::uint64_t renderKey_ = 0;
  std::map<const void*, Entry> entries_;
  /// Transports by chamber geometry (model, depth, pupil, index, walk bound) and grid: they depend on nothing else.
  std::map<std::uint64_t, std::shared_ptr<Slot<eyelib::IrisChamberTransport>>> transports_;
  int builds_ = 0;
  EntryTableCache entryTables_;
};

}  // namespace hdeye
