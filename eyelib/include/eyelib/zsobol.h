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

namespace eyelib {

/// Bits of the global Sobol index given to the sample number within a pixel: samples 0 .. 2^kSampleBits - 1 of a
/// pixel are one block of the sequence; past that, each further block is scrambled afresh (still a pure function).
constexpr int kZSobolSampleBits = 24;

inline std::uint64_t ReverseBits64(std::uint64_t v) {
  v = ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
  v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
  v = ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
  v = ((v >> 8) & 0x00ff00ff00ff00ffull) | ((v & 0x00ff00ff00ff00ffull) << 8);
  v = ((v >> 16) & 0x0000ffff0000ffffull) | ((v & 0x0000ffff0000ffffull) << 16);
  return (v >> 32) | (v << 32);
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

/// A bijection of 64-bit words in which output bit k is input bit k flipped by a function of input bits 0..k-1
/// and the seed alone (products by even constants and by odd ones, and an addition, carry only upwards). Read on a
/// bit-reversed fraction it is a hashed Owen scramble; read on a bit-reversed index, a nested index permutation.
inline std::uint64_t NestedHash(std::uint64_t v, std::uint64_t seed) {
  v ^= v * 0x9e2c5a1f3b6d4e8aull;
  v += seed;
  v *= (seed >> 31) | 1;
  v ^= v * 0xd1b54a32d192ed04ull;
  v ^= v * 0x4a7c15f39cc0605eull;
  v += SplitMix64(seed) & ~1ull;  // even: bit 0 stays a function of the seed's first addition
  v ^= v * 0x2545f4914f6cdd1cull;
  return v;
}

/// Owen-scrambles a 64-bit binary fraction (most significant bit first): each digit flipped by a hash of the digits
/// before it and the seed.
inline std::uint64_t OwenScramble(std::uint64_t fraction, std::uint64_t seed) {
  return ReverseBits64(NestedHash(ReverseBits64(fraction), seed));
}

/// Sobol's second dimension (the Pascal matrix mod 2) of a 64-bit index, as a 64-bit fraction: the generator's
/// columns c_0 = 1/2 and c_b = c_{b-1} ^ (c_{b-1} >> 1), XORed for the set bits, eight bits of index per table.
inline std::uint64_t SobolSecondDimension(std::uint64_t index) {
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
          t[byte][v] = x;
        }
    }
  };
  static const Tables tables;
  std::uint64_t x = 0;
  for (int byte = 0; byte < 8; ++byte) x ^= tables.t[byte][(index >> (8 * byte)) & 0xff];
  return x;
}

/// A 64-bit fraction as a double in [0, 1): its top 53 bits.
inline double FractionToUnit(std::uint64_t fraction) { return double(fraction >> 11) * 0x1.0p-53; }

/// Dimension pair `pair` (dimensions 2 pair and 2 pair + 1) of sample `sample` of pixel (x, y), seed `seed`.
struct ZSobolPair {
  double u, v;
};

inline ZSobolPair ZSobolPoint(std::uint64_t seed, std::uint32_t x, std::uint32_t y, std::uint64_t sample,
                              std::uint64_t pair) {
  constexpr std::uint64_t kSampleMask = (std::uint64_t(1) << kZSobolSampleBits) - 1;
  // Pixel coordinates past 16 bits and sample blocks past the first select a fresh scramble.
  const std::uint64_t beyond =
      (std::uint64_t(x >> 16) << 48) ^ (std::uint64_t(y >> 16) << 32) ^ (sample >> kZSobolSampleBits);
  const std::uint64_t pairSeed = SplitMix64(seed ^ SplitMix64(pair ^ SplitMix64(beyond)));
  const std::uint64_t index = (Morton2(x, y) << kZSobolSampleBits) | (sample & kSampleMask);
  // The index permutation: bit b flipped by the bits above it (NestedHash on the reversed index).
  const std::uint64_t permuted = ReverseBits64(NestedHash(ReverseBits64(index), pairSeed));
  const std::uint64_t first = ReverseBits64(permuted);  // Sobol's first dimension: the radical inverse
  const std::uint64_t second = SobolSecondDimension(permuted);
  return {FractionToUnit(OwenScramble(first, SplitMix64(pairSeed ^ 0x5851f42d4c957f2dull))),
          FractionToUnit(OwenScramble(second, SplitMix64(pairSeed ^ 0x14057b7ef767814full)))};
}

/// Dimension `dimension` of sample `sample` of pixel (x, y): one coordinate of its pair's point.
inline double ZSobolSample(std::uint64_t seed, std::uint32_t x, std::uint32_t y, std::uint64_t sample,
                           std::uint64_t dimension) {
  const ZSobolPair p = ZSobolPoint(seed, x, y, sample, dimension >> 1);
  return dimension & 1 ? p.v : p.u;
}

}  // namespace eyelib
