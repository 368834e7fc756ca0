#pragma once
// Where a light's centre enters an eye, tabulated (eyelib::EntryPointTable) for MNEE's start and its light sampling
// origin. A table is a pure function of the chamber's shape and the light's canonical position, so the renderer keeps
// one per such key for all its threads and renders (EntryTableCache), and each tracer a few of them at hand
// (EntryTables) so that a lookup takes no lock. A moving eye or light would change the key with every sample: the
// renderer asks for none for them (RenderSettings::mneeEntryTables).
#include <eyelib/entry_point_table.h>

#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

namespace hdeye {

/// What a table depends on: the chamber's model, iris depth (mm) and index, and the light point (canonical mm).
struct EntryTableKey {
  eyelib::CorneaModel model;
  double irisDepth, corneaIor;
  eyelib::Vec3d light;

  static EntryTableKey Of(const eyelib::AnteriorChamber<double>& chamber, const eyelib::LightEnd& centre) {
    const eyelib::ChamberParams& p = chamber.Params();
    return {p.model, p.irisDepth, p.corneaIor, centre.position};
  }
  bool operator==(const EntryTableKey& o) const {
    return model == o.model && irisDepth == o.irisDepth && corneaIor == o.corneaIor && light == o.light;
  }
};

/// The renderer's tables, shared by its threads. Thread-safe; a table is built under the lock (a millisecond).
class EntryTableCache {
 public:
  /// Tables kept: past it (a long session of light moves) the cache starts again.
  static constexpr std::size_t kKept = 256;
  std::shared_ptr<const eyelib::EntryPointTable> Get(const eyelib::AnteriorChamber<double>& chamber,
                                                     const eyelib::LightEnd& centre);
  /// Tables held.
  std::size_t Size() {
    std::lock_guard<std::mutex> lock(mutex_);
    return tables_.size();
  }

 private:
  std::mutex mutex_;
  std::vector<std::pair<EntryTableKey, std::shared_ptr<const eyelib::EntryPointTable>>> tables_;
};

/// One tracer's tables at hand, from the shared cache.
class EntryTables {
 public:
  explicit EntryTables(EntryTableCache* shared) : shared_(shared) {}
  /// The entry for iris point x (canonical mm) of the light whose centre is `centre`.
  eyelib::Vec3d At(const eyelib::AnteriorChamber<double>& chamber, const eyelib::LightEnd& centre,
                   const eyelib::Vec3d& x);

 private:
  static constexpr std::size_t kAtHand = 8;
  EntryTableCache* shared_;
  std::vector<std::pair<EntryTableKey, std::shared_ptr<const eyelib::EntryPointTable>>> atHand_;
};

}  // namespace hdeye
