#include "hdeye/render/entryTables.h"

namespace hdeye {

std::shared_ptr<const eyelib::EntryPointTable> EntryTableCache::Get(const eyelib::AnteriorChamber<double>& chamber,
                                                                    const eyelib::LightEnd& centre) {
  const EntryTableKey key = EntryTableKey::Of(chamber, centre);
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [k, table] : tables_)
    if (k == key) return table;
  if (tables_.size() == kKept) tables_.clear();
  tables_.emplace_back(key, std::make_shared<const eyelib::EntryPointTable>(chamber, centre));
  return tables_.back().second;
}

eyelib::Vec3d EntryTables::At(const eyelib::AnteriorChamber<double>& chamber, const eyelib::LightEnd& centre,
                              const eyelib::Vec3d& x) {
  // A light point that is not finite never equals its own key: computed, not tabulated (one table per call).
  if (!eyelib::IsFinite(centre.position)) return eyelib::ApproximateEntryPoint(chamber, x, centre);
  const EntryTableKey key = EntryTableKey::Of(chamber, centre);
  for (const auto& [k, table] : atHand_)
    if (k == key) return table->At(chamber, x);
  if (atHand_.size() == kAtHand) atHand_.erase(atHand_.begin());
  atHand_.emplace_back(key, shared_->Get(chamber, centre));
  return atHand_.back().second->At(chamber, x);
}

}  // namespace hdeye
