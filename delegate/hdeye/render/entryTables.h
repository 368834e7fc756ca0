#pragma once
// One thread's tables of where a light's centre enters an eye (eyelib::EntryPointTable), for MNEE's start and its
// light sampling origin: built the first time an eye asks for a light and kept while the eye and the light's
// canonical position stay the same, so a still scene builds each once per tracer. A moving eye or light would change
// the key with every sample: the renderer asks for none for them (RenderSettings::mneeEntryTables).
#include <eyelib/entry_point_table.h>

#include <cstddef>
#include <vector>

namespace hdeye {

class EntryTables {
 public:
  /// The tables kept: every eye's lights in most scenes; past it, the oldest is rebuilt for the new key.
  static constexpr std::size_t kKept = 16;

  /// The entry for iris point x (canonical mm) of the light whose centre is `centre`, into the eye that `eye` (its
  /// GeometryContext, which owns the chamber) stands for.
  eyelib::Vec3d At(const void* eye, const eyelib::AnteriorChamber<double>& chamber, const eyelib::LightEnd& centre,
                   const eyelib::Vec3d& x) {
    for (const Entry& e : entries_)
      if (e.eye == eye && e.table.Light().position == centre.position) return e.table.At(chamber, x);
    if (entries_.size() == kKept) entries_.erase(entries_.begin());
    entries_.push_back({eye, eyelib::EntryPointTable(chamber, centre)});
    return entries_.back().table.At(chamber, x);
  }

 private:
  struct Entry {
    const void* eye;
    eyelib::EntryPointTable table;
  };
  std::vector<Entry> entries_;
};

}  // namespace hdeye
