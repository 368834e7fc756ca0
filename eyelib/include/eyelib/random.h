#pragma once
// A small counter-based random generator: the value is a pure function of (seed, stream, index), so
// results never depend on thread or tile order.
#include <cstdint>

namespace eyelib {

inline std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// A uniform double in [0, 1) from (seed, stream, index).
inline double UniformAt(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  const std::uint64_t h = SplitMix64(seed ^ SplitMix64(stream ^ SplitMix64(index)));
  return double(h >> 11) * 0x1.0p-53;
}

}  // namespace eyelib
