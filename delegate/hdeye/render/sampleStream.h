#pragma once
// The random numbers of one camera path: dimension d of sample s of pixel (x, y), a pure function of
// (seed, x, y, s, d) for either sampler, so any thread count and any split of the sample range give the same image.
//
// ZSobol (eyelib/zsobol.h): the camera's dimensions come first and stay at fixed indices whether or not the camera
// uses them (a pinhole draws the same path numbers as a lens camera), then the path's in order. Past
// kLowDiscrepancyDimensions the path falls back to the hash (deep paths, long sclera walks: stratification that
// deep buys nothing, and a bound keeps the pair cache honest). Dimensions pair up (2k, 2k + 1) into a 2D point:
// Next2D() starts on a pair, and code that can only call Next() (the eye's, through `random()`) draws whole pairs.
//
// Independent: the counter hash of eyelib/random.h, laid out as before (the pixel jitter from Next(), the lens
// counted from the top of the sample's range), so its images are those of the earlier renderer.
#include "hdeye/render/renderSettings.h"

#include <eyelib/random.h>
#include <eyelib/zsobol.h>

#include <cstdint>

namespace hdeye {

class SampleStream {
 public:
  /// Named dimensions of the ZSobol layout (fixed whether used or not).
  static constexpr std::uint64_t kPixelDimension = 0;  ///< and 1: the jitter inside the pixel
  static constexpr std::uint64_t kLensDimension = 2;   ///< and 3: the point on the lens
  static constexpr std::uint64_t kTimeDimension = 4;   ///< the shutter time (FromTop(2))
  static constexpr std::uint64_t kFirstPathDimension = 6;
  /// Path dimensions drawn from Sobol points; later ones come from the hash.
  static constexpr std::uint64_t kLowDiscrepancyDimensions = 256;

  /// The ZSobol pairs a render's key table covers (KeyTable): every low-discrepancy one.
  static constexpr std::uint64_t kTablePairs = (kFirstPathDimension + kLowDiscrepancyDimensions + 1) / 2;
  /// The pair keys of a render's seed, computed once per render instead of once per pair drawn.
  static eyelib::ZSobolKeyTable KeyTable(std::uint64_t seed) { return eyelib::ZSobolKeyTable(seed, kTablePairs); }

  /// keys: KeyTable(seed), or null (each pair's keys are then computed where drawn; the numbers are the same).
  SampleStream(SamplerKind kind, std::uint64_t seed, std::uint32_t x, std::uint32_t y, std::uint32_t width,
               std::uint64_t sample, const eyelib::ZSobolKeyTable* keys = nullptr)
      : kind_(kind), seed_(seed), x_(x), y_(y), pixel_(std::uint64_t(y) * width + x), sample_(sample) {
    if (kind_ != SamplerKind::ZSobol) return;
    dim_ = kFirstPathDimension;
    keys_ = keys && keys->Seed() == seed ? keys : nullptr;
    beyond_ = eyelib::ZSobolBeyond(x, y, sample);
    reversedIndex_ = eyelib::ZSobolReversedIndex(x, y, sample);
  }

  /// The next path dimension.
  double Next() {
    if (kind_ == SamplerKind::Independent)
      return eyelib::UniformAt(seed_, pixel_, sample_ * kDimsPerSample + dim_++ % kDimsPerSample);
    return Dimension(dim_++);
  }

  /// Two path dimensions for one 2D sample; ZSobol starts them on a pair (skipping one dimension if needed).
  void Next2D(double* u, double* v) {
    if (kind_ == SamplerKind::ZSobol) dim_ += dim_ & 1;
    *u = Next();
    *v = Next();
  }

  /// Moves to the start of the next pair (ZSobol; nothing for the independent sampler): the eye's draws, which come
  /// in whole pairs, then land their 2D samples on pairs.
  void AlignToPair() {
    if (kind_ == SamplerKind::ZSobol) dim_ += dim_ & 1;
  }

  /// The jitter inside the pixel, [0, 1)^2.
  void PixelJitter(double* jx, double* jy) {
    if (kind_ == SamplerKind::Independent) {
      *jx = Next(), *jy = Next();
      return;
    }
    *jx = Dimension(kPixelDimension), *jy = Dimension(kPixelDimension + 1);
  }

  /// Camera dimension k: 0 and 1 the lens, 2 the shutter time; never shifts the path's dimensions.
  double FromTop(std::uint64_t k) {
    if (kind_ == SamplerKind::Independent)
      return eyelib::UniformAt(seed_, pixel_, sample_ * kDimsPerSample + kDimsPerSample - 1 - k);
    if (kLensDimension + k < kFirstPathDimension) return Dimension(kLensDimension + k);
    return eyelib::UniformAt(seed_ ^ kCameraSalt, pixel_, sample_ * kDimsPerSample + k);
  }

 private:
  // The independent sampler's room per sample: far above the deepest path, so no two samples share numbers.
  static constexpr std::uint64_t kDimsPerSample = std::uint64_t(1) << 16;
  static constexpr std::uint64_t kCameraSalt = 0x6a09e667f3bcc909ull;  // camera dimensions past the named ones
  static constexpr std::uint64_t kHashSalt = 0xbb67ae8584caa73bull;    // path dimensions past the budget

  /// ZSobol dimension d. A pair's shared part (its permuted index) and first coordinate are kept from its first
  /// draw; the second coordinate is computed only if drawn (a lone Next() uses half a pair).
  /// The rare cases (past the low-discrepancy budget, or a pair the key table lacks) are out of line, so the common
  /// one keeps a small stack frame and the table's keys are read in place rather than copied.
  double Dimension(std::uint64_t d) {
    if (d >= kFirstPathDimension + kLowDiscrepancyDimensions) return HashedDimension(d);
    const std::uint64_t pair = d >> 1;
    if (pair != cachedPair_) {
      const eyelib::ZSobolPairKeys* found = keys_ ? keys_->Find(pair, beyond_) : nullptr;
      if (found)
        StartPair(pair, *found);
      else
        StartPairComputingKeys(pair);
    }
    if (!(d & 1)) return u_;
    if (!vReady_) v_ = eyelib::ZSobolV(permuted_, vKey_), vReady_ = true;
    return v_;
  }
  void StartPair(std::uint64_t pair, const eyelib::ZSobolPairKeys& keys) {
    permuted_ = eyelib::ZSobolPermuted(reversedIndex_, keys);
    u_ = eyelib::ZSobolU(permuted_, keys.u);
    vKey_ = keys.v;
    vReady_ = false;
    cachedPair_ = pair;
  }
  [[gnu::noinline]] void StartPairComputingKeys(std::uint64_t pair) {
    StartPair(pair, eyelib::ZSobolKeysOf(seed_, pair, beyond_));
  }
  [[gnu::noinline]] double HashedDimension(std::uint64_t d) const {
    return eyelib::UniformAt(seed_ ^ kHashSalt, pixel_, sample_ * kDimsPerSample + d % kDimsPerSample);
  }

  SamplerKind kind_;
  std::uint64_t seed_;
  std::uint32_t x_, y_;
  std::uint64_t pixel_, sample_;
  std::uint64_t dim_ = 0;
  const eyelib::ZSobolKeyTable* keys_ = nullptr;
  std::uint64_t beyond_ = 0, reversedIndex_ = 0;
  std::uint64_t cachedPair_ = ~std::uint64_t(0);
  std::uint64_t permuted_ = 0;  ///< the cached pair's permuted index
  eyelib::NestedHashKey vKey_;  ///< its second coordinate's scramble
  double u_ = 0, v_ = 0;
  bool vReady_ = false;
};

}  // namespace hdeye
