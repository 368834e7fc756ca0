#pragma once
// Owen-scrambled Sobol samples in Z (Morton) order, after pbrt-v4's ZSobolSampler: the value of dimension d of
// sample s of pixel (x, y) is a pure function of (seed, x, y, s, d), so results never depend on thread, tile or
// sample-range order.
//
// Every dimension belongs to a pair (2k, 2k + 1), and a pair is a 2D point of Sobol's first two dimensions, a
// (0, 2)-sequence: within a pixel, the first 2^m samples of every pair form a (0, m, 2)-net (every 2^a x 2^(m-a)
// grid of the unit square holds exactly one point), for every m. Two draws that make one 2D sample (a direction, a
// point on a light) should therefore start on an even dimension.
//
// How a point is made: the pixel's Morton code over the sample index is one global Sobol index (kSampleBits bits of
// sample); each pair permutes that index by a nested hash (the flip of a bit depends only on the bits above it, so
// an aligned block of 2^m indices stays one, and the pixel's prefixes stay nets) and scrambles each coordinate by a
// hashed Owen scramble (the flip of a digit depends only on the digits before it, which keeps nets nets). The
// index permutation is what decorrelates the pairs from each other: without it every pair would walk one sequence
// in the same order. Unlike pbrt, the sample part has a fixed width (the renderer does not know the sample count
// of a progressive render in advance), so neighbouring pixels do not share one larger net; the per-pixel
// stratification, which is what a pixel's error sees, is the same.
#include "eyelib/random.h"

#include <array>
#include <cstdint>
#include <vector>

namespace eyelib {

/// Bits of the global Sobol index given to the sample number within a pixel: samples 0 .. 2^kSampleBits - 1 of a
/// pixel are one block of the sequence; past that, each further block is scrambled afresh (still a pure function).
constexpr int kZSobolSampleBits = 24;

inline std::uint64_t ReverseBits64(std::uint64_t v) {
  // The bits of each byte reversed, then the bytes (one instruction): the same as six swap stages.
  v = ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
  v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
  v = ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
  return __builtin_bswap64(v);
}

/// The bits of x (low 16) and y (low 16) interleaved, x in the even bits: the Z-order index of a pixel.
inline std::uint64_t Morton2(std::uint32_t x, std::uint32_t y) {
  auto spread = [](std::uint64_t v) {
    v &= 0xffff;
    v = (v | (v << 8)) & 0x00ff00ffull;
    v = (v | (v << 4)) & 0x0f0f0f0full;
    v = (v | (v << 2)) & 0x33333333ull;
    return (v | (v << 1)) & 0x55555555ull;
  };
  return spread(x) | (spread(y) << 1);
}

/// What NestedHash derives from its seed, computed once for a seed that hashes many words (a dimension pair's).
struct NestedHashKey {
  std::uint64_t add = 0, mul = 1, add2 = 0;
  NestedHashKey() = default;
  explicit NestedHashKey(std::uint64_t seed) : add(seed), mul((seed >> 31) | 1), add2(SplitMix64(seed) & ~1ull) {}
};

/// A bijection of 64-bit words in which output bit k is input bit k flipped by a function of input bits 0..k-1
/// and the seed alone (products by even constants and by odd ones, and an addition, carry only upwards). Read on a
/// bit-reversed fraction it is a hashed Owen scramble; read on a bit-reversed index, a nested index permutation.
inline std::uint64_t NestedHash(std::uint64_t v, const NestedHashKey& key) {
  v ^= v * 0x9e2c5a1f3b6d4e8aull;
  v += key.add;
  v *= key.mul;
  v ^= v * 0xd1b54a32d192ed04ull;
  v ^= v * 0x4a7c15f39cc0605eull;
  v += key.add2;  // even: bit 0 stays a function of the seed's first addition
  v ^= v * 0x2545f4914f6cdd1cull;
  return v;
}

inline std::uint64_t NestedHash(std::uint64_t v, std::uint64_t seed) { return NestedHash(v, NestedHashKey(seed)); }

/// Owen-scrambles a 64-bit binary fraction (most significant bit first): each digit flipped by a hash of the digits
/// before it and the seed.
inline std::uint64_t OwenScramble(std::uint64_t fraction, std::uint64_t seed) {
  return ReverseBits64(NestedHash(ReverseBits64(fraction), seed));
}

/// Sobol's second dimension (the Pascal matrix mod 2) of a 64-bit index, bit-reversed (least significant digit
/// first, as NestedHash reads a fraction): the generator's columns c_0 = 1/2 and c_b = c_{b-1} ^ (c_{b-1} >> 1),
/// reversed and XORed for the set bits, eight bits of index per table.
inline std::uint64_t SobolSecondDimensionReversed(std::uint64_t index) {
  struct Tables {
    std::array<std::array<std::uint64_t, 256>, 8> t{};
    Tables() {
      std::uint64_t column[64];
      column[0] = 1ull << 63;
      for (int b = 1; b < 64; ++b) column[b] = column[b - 1] ^ (column[b - 1] >> 1);
      for (int byte = 0; byte < 8; ++byte)
        for (int v = 0; v < 256; ++v) {
          std::uint64_t x = 0;
          for (int bit = 0; bit < 8; ++bit)
            if (v >> bit & 1) x ^= column[8 * byte + bit];
          t[byte][v] = ReverseBits64(x);
        }
    }
  };
  static const Tables tables;
  std::uint64_t x = 0;
  for (int byte = 0; byte < 8; ++byte) x ^= tables.t[byte][(index >> (8 * byte)) & 0xff];
  return x;
}

/// Sobol's second dimension of a 64-bit index, as a 64-bit fraction (most significant digit first).
inline std::uint64_t SobolSecondDimension(std::uint64_t index) {
  return ReverseBits64(SobolSecondDimensionReversed(index));
}

/// A 64-bit fraction as a double in [0, 1): its top 53 bits.
inline double FractionToUnit(std::uint64_t fraction) { return double(fraction >> 11) * 0x1.0p-53; }

/// Dimension pair `pair` (dimensions 2 pair and 2 pair + 1) of sample `sample` of pixel (x, y), seed `seed`.
struct ZSobolPair {
  double u, v;
};

/// What selects a fresh scramble: pixel coordinates past 16 bits and sample blocks past the first (0 for every
/// pixel below 65536 x 65536 and every sample below 2^kZSobolSampleBits).
inline std::uint64_t ZSobolBeyond(std::uint32_t x, std::uint32_t y, std::uint64_t sample) {
  return (std::uint64_t(x >> 16) << 48) ^ (std::uint64_t(y >> 16) << 32) ^ (sample >> kZSobolSampleBits);
}

/// The global Sobol index of sample `sample` of pixel (x, y) (the pixel's Morton code over the sample), reversed.
inline std::uint64_t ZSobolReversedIndex(std::uint32_t x, std::uint32_t y, std::uint64_t sample) {
  constexpr std::uint64_t kSampleMask = (std::uint64_t(1) << kZSobolSampleBits) - 1;
  return ReverseBits64((Morton2(x, y) << kZSobolSampleBits) | (sample & kSampleMask));
}

/// A pair's three hashes: the index permutation and the two coordinates' Owen scrambles. They depend on the seed,
/// the pair and ZSobolBeyond only, so a sampler can compute them once per render (ZSobolKeyTable).
struct ZSobolPairKeys {
  NestedHashKey permute, u, v;
};

inline ZSobolPairKeys ZSobolKeysOf(std::uint64_t seed, std::uint64_t pair, std::uint64_t beyond) {
  const std::uint64_t pairSeed = SplitMix64(seed ^ SplitMix64(pair ^ SplitMix64(beyond)));
  return {NestedHashKey(pairSeed), NestedHashKey(SplitMix64(pairSeed ^ 0x5851f42d4c957f2dull)),
          NestedHashKey(SplitMix64(pairSeed ^ 0x14057b7ef767814full))};
}

// A point in three steps, so that a sampler can keep the shared part and draw a coordinate only when it is used.
// The index permutation: bit b of the index flipped by the bits above it (NestedHash on the reversed index). Sobol's
// first dimension is the radical inverse of the permuted index, and its Owen scramble reverses it back for
// NestedHash: so u is NestedHash of the permuted index itself, reversed into a fraction.

/// The permuted global Sobol index of a pair, from ZSobolReversedIndex.
inline std::uint64_t ZSobolPermuted(std::uint64_t reversedIndex, const ZSobolPairKeys& keys) {
  return ReverseBits64(NestedHash(reversedIndex, keys.permute));
}
/// The pair's first coordinate: Sobol's first dimension of the permuted index, Owen-scrambled.
inline double ZSobolU(std::uint64_t permuted, const NestedHashKey& uKey) {
  return FractionToUnit(ReverseBits64(NestedHash(permuted, uKey)));
}
/// The pair's second coordinate: Sobol's second dimension of the permuted index, Owen-scrambled.
inline double ZSobolV(std::uint64_t permuted, const NestedHashKey& vKey) {
  return FractionToUnit(ReverseBits64(NestedHash(SobolSecondDimensionReversed(permuted), vKey)));
}

inline ZSobolPair ZSobolPoint(std::uint64_t seed, std::uint32_t x, std::uint32_t y, std::uint64_t sample,
                              std::uint64_t pair) {
  const ZSobolPairKeys keys = ZSobolKeysOf(seed, pair, ZSobolBeyond(x, y, sample));
  const std::uint64_t permuted = ZSobolPermuted(ZSobolReversedIndex(x, y, sample), keys);
  return {ZSobolU(permuted, keys.u), ZSobolV(permuted, keys.v)};
}

/// The pair keys of one seed for pairs 0 .. pairs - 1 at ZSobolBeyond 0: what ZSobolKeysOf would compute, once.
class ZSobolKeyTable {
 public:
  ZSobolKeyTable(std::uint64_t seed, std::uint64_t pairs) : seed_(seed) {
    keys_.reserve(pairs);
    for (std::uint64_t pair = 0; pair < pairs; ++pair) keys_.push_back(ZSobolKeysOf(seed, pair, 0));
  }
  std::uint64_t Seed() const { return seed_; }
  /// The keys of `pair`, or null where the table has none (the caller computes them).
  const ZSobolPairKeys* Find(std::uint64_t pair, std::uint64_t beyond) const {
    return beyond == 0 && pair < keys_.size() ? &keys_[pair] : nullptr;
  }

 private:
  std::uint64_t seed_;
  std::vector<ZSobolPairKeys> keys_;
};

/// Dimension `dimension` of sample `sample` of pixel (x, y): one coordinate of its pair's point.
inline double ZSobolSample(std::uint64_t seed, std::uint32_t x, std::uint32_t y, std::uint64_t sample,
                           std::uint64_t dimension) {
  const ZSobolPair p = ZSobolPoint(seed, x, y, sample, dimension >> 1);
  return dimension & 1 ? p.v : p.u;
}

}  // namespace eyelib
