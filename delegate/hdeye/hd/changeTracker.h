#pragma once
// Dirty bits per prim (HdChangeTracker's role): the scene side marks what changed, Sync pulls only
// that and clears the bits. Prims declare what they care about in GetInitialDirtyBitsMask.
#include "hdeye/hd/types.h"

#include <cstdint>
#include <unordered_map>
#include <unordered_set>

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
inline constexpr DirtyBits DirtyParams = 1u << 6;  ///< sprim/bprim parameters (camera, light, buffer size)
inline constexpr DirtyBits DirtyMaterialId = 1u << 7;
/// On an rprim: its instancer's instances changed (rebuild its instances, nothing else). On an instancer: its
/// instance transforms or colours changed.
inline constexpr DirtyBits DirtyInstancer = 1u << 8;
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
  /// Marks bits dirty on every tracked prim (a change every prim's data depends on, such as the render's shutter).
  void MarkAllDirty(DirtyBits bits) {
    for (auto& [id, b] : bits_) b |= bits;
  }
  DirtyBits GetDirtyBits(const PrimId& id) const {
    auto it = bits_.find(id);
    return it == bits_.end() ? dirty::Clean : it->second;
  }
  void MarkClean(const PrimId& id, DirtyBits remaining = dirty::Clean) {
    if (auto it = bits_.find(id); it != bits_.end()) it->second = remaining;
  }

  /// Records that rprim `rprimId` draws the instances of `instancerId` (HdChangeTracker's
  /// AddInstancerRprimDependency), so that MarkInstancerDirty reaches it.
  void AddInstancerRprimDependency(const PrimId& instancerId, const PrimId& rprimId) {
    instancerRprims_[instancerId].insert(rprimId);
  }
  void RemoveInstancerRprimDependency(const PrimId& instancerId, const PrimId& rprimId) {
    if (auto it = instancerRprims_.find(instancerId); it != instancerRprims_.end()) it->second.erase(rprimId);
  }
  /// Marks the instancer dirty and every rprim that depends on it DirtyInstancer: those rebuild their
  /// instances only, never their topology or points.
  void MarkInstancerDirty(const PrimId& instancerId, DirtyBits bits = dirty::DirtyInstancer) {
    MarkDirty(instancerId, bits);
    if (auto it = instancerRprims_.find(instancerId); it != instancerRprims_.end())
      for (const PrimId& rprim : it->second) MarkDirty(rprim, dirty::DirtyInstancer);
  }

 private:
  std::unordered_map<PrimId, DirtyBits> bits_;
  std::unordered_map<PrimId, std::unordered_set<PrimId>> instancerRprims_;
};

}  // namespace hdeye
