#pragma once
// Dirty bits per prim (HdChangeTracker's role): the scene side marks what changed, Sync pulls only
// that and clears the bits. Prims declare what they care about in GetInitialDirtyBitsMask.
#include "hdeye/hd/types.h"

#include <cstdint>
#include <unordered_map>

namespace hdeye {

using DirtyBits = std::uint32_t;

/// The bits, named as in HdChangeTracker.
namespace dirty {
inline constexpr DirtyBits Clean = 0;
inline constexpr DirtyBits InitRepr = 1u << 0;
inline constexpr DirtyBits DirtyPoints = 1u << 1;
inline constexpr DirtyBits DirtyTopology = 1u << 2;
inline constexpr DirtyBits DirtyTransform = 1u << 3;
inline constexpr DirtyBits DirtyPrimvar = 1u << 4;
inline constexpr DirtyBits DirtyVisibility = 1u << 5;
inline constexpr DirtyBits DirtyParams = 1u << 6;     ///< sprim/bprim parameters (camera, light, buffer size)
inline constexpr DirtyBits DirtyMaterialId = 1u << 7;
inline constexpr DirtyBits AllDirty = ~0u;
}  // namespace dirty

class ChangeTracker {
 public:
  void Track(const PrimId& id, DirtyBits initial) { bits_[id] = initial; }
  void Untrack(const PrimId& id) { bits_.erase(id); }

  /// Marks bits dirty on a tracked prim; unknown ids are ignored (the prim may have been removed).
  void MarkDirty(const PrimId& id, DirtyBits bits) {
    auto it = bits_.find(id);
    if (it == bits_.end() || bits == dirty::Clean) return;
    it->second |= bits;
  }
  DirtyBits GetDirtyBits(const PrimId& id) const {
    auto it = bits_.find(id);
    return it == bits_.end() ? dirty::Clean : it->second;
  }
  void MarkClean(const PrimId& id, DirtyBits remaining = dirty::Clean) {
    if (auto it = bits_.find(id); it != bits_.end()) it->second = remaining;
  }

 private:
  std::unordered_map<PrimId, DirtyBits> bits_;
};

}  // namespace hdeye
