// The ZSobol sampler's specification: per-pixel (0, 2)-net stratification of every dimension pair at every
// power-of-two prefix, uniform values, a pure function of (seed, pixel, sample, dimension), and dimensions that do
// not move together after scrambling.
#include "eyelib/zsobol.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace {

struct Point {
  double u, v;
};

/// Whether `points` (2^m of them) put exactly one point in every cell of every 2^a x 2^(m-a) grid; the first
/// failing grid's a in *failA.
bool IsZeroNet(const std::vector<Point>& points, int m, int* failA) {
  const int n = 1 << m;
  for (int a = 0; a <= m; ++a) {
    std::vector<int> count(n, 0);
    for (const Point& p : points) {
      const int i = std::min((1 << a) - 1, int(p.u * (1 << a)));
      const int j = std::min((1 << (m - a)) - 1, int(p.v * (1 << (m - a))));
      ++count[i * (1 << (m - a)) + j];
    }
    if (!std::all_of(count.begin(), count.end(), [](int c) { return c == 1; })) {
      *failA = a;
      return false;
    }
  }
  return true;
}

}  // namespace

TEST_CASE("every power-of-two prefix of a pixel's samples is a (0,2)-net in every dimension pair", "[zsobol]") {
  int checked = 0;
  for (std::uint64_t seed : {0ull, 7ull, 123456789ull})
    for (auto [x, y] : {std::pair{0u, 0u}, std::pair{17u, 3u}, std::pair{255u, 254u}, std::pair{70000u, 5u}})
      for (std::uint64_t pair : {0ull, 1ull, 3ull, 40ull, 127ull})
        for (int m = 0; m <= 10; ++m) {
          std::vector<Point> points;
          for (std::uint64_t s = 0; s < (1ull << m); ++s) {
            const eyelib::ZSobolPair p = eyelib::ZSobolPoint(seed, x, y, s, pair);
            points.push_back({p.u, p.v});
          }
          int a = -1;
          const bool net = IsZeroNet(points, m, &a);
          INFO("seed " << seed << " pixel (" << x << ", " << y << ") pair " << pair << ": the first " << (1 << m)
                       << " samples are not stratified on the 2^" << a << " x 2^" << (m - a) << " grid");
          CHECK(net);
          ++checked;
        }
  std::printf("zsobol: %d prefixes checked as (0,m,2)-nets\n", checked);
}

TEST_CASE("zsobol values are uniform on the unit interval in every dimension", "[zsobol]") {
  // One sample (of a varying index) from each of 4096 pixels, 32 bins: chi-square with 31 degrees of freedom
  // (99.99 % quantile about 70). Within a pixel the samples are stratified, so they would pass trivially.
  for (std::uint64_t dim : {0ull, 1ull, 6ull, 7ull, 50ull, 201ull}) {
    std::vector<int> bins(32, 0);
    double sum = 0;
    int n = 0;
    for (std::uint32_t px = 0; px < 4096; ++px)
      for (std::uint64_t s = px % 37; s < px % 37 + 1; ++s) {
        const double u = eyelib::ZSobolSample(42, px % 64, px / 64, s, dim);
        REQUIRE(u >= 0.0);
        REQUIRE(u < 1.0);
        ++bins[int(u * 32)];
        sum += u;
        ++n;
      }
    double chi2 = 0;
    const double expected = n / 32.0;
    for (int b : bins) chi2 += (b - expected) * (b - expected) / expected;
    std::printf("zsobol: dimension %llu: mean %.4f, chi-square %.1f (31 dof)\n", (unsigned long long)dim, sum / n,
                chi2);
    CHECK(std::abs(sum / n - 0.5) < 0.02);  // 4.4 standard errors of a mean of 4096 uniforms
    CHECK(chi2 < 70);
  }
}

TEST_CASE("a zsobol value is a pure function of seed, pixel, sample index and dimension", "[zsobol]") {
  // Evaluated in another order, or with other pairs in between, the value is the same; and each argument changes
  // it.
  const double v = eyelib::ZSobolSample(3, 10, 20, 5, 9);
  for (int k = 0; k < 100; ++k) eyelib::ZSobolSample(k, k, k, k, k);
  CHECK(eyelib::ZSobolSample(3, 10, 20, 5, 9) == v);
  CHECK(eyelib::ZSobolPoint(3, 10, 20, 5, 4).v == v);
  CHECK(eyelib::ZSobolSample(4, 10, 20, 5, 9) != v);
  CHECK(eyelib::ZSobolSample(3, 11, 20, 5, 9) != v);
  CHECK(eyelib::ZSobolSample(3, 10, 21, 5, 9) != v);
  CHECK(eyelib::ZSobolSample(3, 10, 20, 6, 9) != v);
  CHECK(eyelib::ZSobolSample(3, 10, 20, 5, 11) != v);
  // Samples past the first block of 2^kZSobolSampleBits are not the first block's again.
  const std::uint64_t block = 1ull << eyelib::kZSobolSampleBits;
  CHECK(eyelib::ZSobolSample(3, 10, 20, block + 5, 9) != v);
}

TEST_CASE("zsobol dimensions are uncorrelated after scrambling, within a pixel and across pixels", "[zsobol]") {
  // Pearson correlation of dimension pairs over each pixel's 256 samples, averaged in absolute value over 64
  // pixels: independent uniforms give about 0.05 (sqrt(2 / pi) / sqrt(256)). The failure this guards against
  // (two pairs walking one sequence in one order) gives 1. The same-half test catches the subtler one: every point
  // of one dimension's lower half in the same half of another dimension.
  const std::pair<std::uint64_t, std::uint64_t> dims[] = {{0, 1}, {0, 2}, {1, 3}, {6, 8}, {7, 9}, {6, 100}, {10, 11}};
  for (auto [d1, d2] : dims) {
    double meanAbsCorrelation = 0, meanCorrelation = 0, worstSameHalf = 0;
    const int pixels = 64, samples = 256;
    for (int px = 0; px < pixels; ++px) {
      double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
      int lowerBoth = 0, lowerA = 0;
      for (int s = 0; s < samples; ++s) {
        const double a = eyelib::ZSobolSample(9, px, 2 * px, s, d1), b = eyelib::ZSobolSample(9, px, 2 * px, s, d2);
        sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
        lowerA += a < 0.5;
        lowerBoth += a < 0.5 && b < 0.5;
      }
      const double cov = sab / samples - (sa / samples) * (sb / samples);
      const double va = saa / samples - (sa / samples) * (sa / samples);
      const double vb = sbb / samples - (sb / samples) * (sb / samples);
      meanAbsCorrelation += std::abs(cov / std::sqrt(va * vb)) / pixels;
      meanCorrelation += cov / std::sqrt(va * vb) / pixels;
      worstSameHalf = std::max(worstSameHalf, std::abs(double(lowerBoth) / lowerA - 0.5));
    }
    std::printf(
        "zsobol: dimensions %llu and %llu: mean correlation %+.4f, mean |correlation| %.4f, worst same-half "
        "share off 0.5 by %.3f\n",
        (unsigned long long)d1, (unsigned long long)d2, meanCorrelation, meanAbsCorrelation, worstSameHalf);
    // Linked strata (each pair of samples shares its coarse strata) make |r| up to 1.4 times the independent one.
    CHECK(std::abs(meanCorrelation) < 0.03);
    CHECK(meanAbsCorrelation < 0.1);
    CHECK(worstSameHalf < 0.2);
  }
  // Across pixels: one dimension of sample 0 in neighbouring pixels.
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  const int n = 4096;
  for (int px = 0; px < n; ++px) {
    const double a = eyelib::ZSobolSample(9, px % 64, px / 64, 0, 6);
    const double b = eyelib::ZSobolSample(9, px % 64 + 1, px / 64, 0, 6);
    sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
  }
  const double corr =
      (sab / n - sa / n * sb / n) / std::sqrt((saa / n - sa * sa / n / n) * (sbb / n - sb * sb / n / n));
  std::printf("zsobol: neighbouring pixels, sample 0: correlation %.4f (independent: |r| about 0.016)\n", corr);
  CHECK(std::abs(corr) < 0.06);
}

TEST_CASE("the stratified pairs integrate a smooth 2D function faster than independent samples", "[zsobol]") {
  // f(u, v) = u v e^(u + v) integrates to 1 over the unit square. Mean squared error over 256 pixels at 256
  // samples: a (0, 2)-net converges near 1 / N^2 (times logs) against 1 / N for independent samples.
  double netError = 0, hashError = 0;
  const int pixels = 256, samples = 256;
  for (int px = 0; px < pixels; ++px) {
    double net = 0, hash = 0;
    for (int s = 0; s < samples; ++s) {
      const eyelib::ZSobolPair p = eyelib::ZSobolPoint(1, px, 0, s, 5);
      net += p.u * p.v * std::exp(p.u + p.v);
      const double u = eyelib::UniformAt(1, px, 2 * s), v = eyelib::UniformAt(1, px, 2 * s + 1);
      hash += u * v * std::exp(u + v);
    }
    netError += std::pow(net / samples - 1, 2) / pixels;
    hashError += std::pow(hash / samples - 1, 2) / pixels;
  }
  std::printf("zsobol: MSE at 256 samples: zsobol %.3g, independent %.3g (ratio %.0f)\n", netError, hashError,
              hashError / netError);
  CHECK(netError * 20 < hashError);
}

TEST_CASE("neighbouring pixels' zsobol estimates have uncorrelated errors", "[zsobol]") {
  // A pixel's samples are its own block of the sequence, decorrelated by the index permutation (which depends on
  // the pixel's bits): were it the same for two pixels, their 16-sample estimates of one integrand would err
  // alike. Correlation of the estimates of horizontal neighbours over 32 x 32 pixels, for 134 pairs and 4 seeds:
  // independent estimates give a standard deviation of about 0.032.
  double worst = 0;
  int worstPair = -1;
  for (std::uint64_t seed = 0; seed < 4; ++seed)
    for (std::uint64_t pair = 0; pair < 134; ++pair) {
      const int w = 32, n = 16;
      std::vector<double> estimate(w * w);
      double mean = 0;
      for (int y = 0; y < w; ++y)
        for (int x = 0; x < w; ++x) {
          double sum = 0;
          for (int s = 0; s < n; ++s) {
            const eyelib::ZSobolPair p = eyelib::ZSobolPoint(seed, x, y, s, pair);
            sum += std::sin(7 * p.u) * std::cos(5 * p.v) + p.u * p.u;
          }
          estimate[y * w + x] = sum / n;
          mean += sum / n / (w * w);
        }
      double saa = 0, sbb = 0, sab = 0;
      for (int y = 0; y < w; ++y)
        for (int x = 0; x + 1 < w; ++x) {
          const double a = estimate[y * w + x] - mean, b = estimate[y * w + x + 1] - mean;
          saa += a * a, sbb += b * b, sab += a * b;
        }
      const double r = sab / std::sqrt(saa * sbb);
      if (std::abs(r) > std::abs(worst)) worst = r, worstPair = int(pair);
    }
  std::printf("zsobol: worst neighbour-pixel error correlation %.3f (pair %d) over 536 pairs and seeds\n", worst,
              worstPair);
  CHECK(std::abs(worst) < 0.15);
}

namespace {

// The sampler as first written (before ZSobolKeyTable and the folded reversals): the values the faster code must
// reproduce bit for bit, so that renders stay what they were.
std::uint64_t ReferenceReverse(std::uint64_t v) {
  v = ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
  v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
  v = ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
  v = ((v >> 8) & 0x00ff00ff00ff00ffull) | ((v & 0x00ff00ff00ff00ffull) << 8);
  v = ((v >> 16) & 0x0000ffff0000ffffull) | ((v & 0x0000ffff0000ffffull) << 16);
  return (v >> 32) | (v << 32);
}

std::uint64_t ReferenceNestedHash(std::uint64_t v, std::uint64_t seed) {
  v ^= v * 0x9e2c5a1f3b6d4e8aull;
  v += seed;
  v *= (seed >> 31) | 1;
  v ^= v * 0xd1b54a32d192ed04ull;
  v ^= v * 0x4a7c15f39cc0605eull;
  v += eyelib::SplitMix64(seed) & ~1ull;
  v ^= v * 0x2545f4914f6cdd1cull;
  return v;
}

std::uint64_t ReferenceSobol2(std::uint64_t index) {
  std::uint64_t column = 1ull << 63, x = 0;
  for (int b = 0; b < 64; ++b, column ^= column >> 1)
    if (index >> b & 1) x ^= column;
  return x;
}

eyelib::ZSobolPair ReferencePoint(std::uint64_t seed, std::uint32_t x, std::uint32_t y, std::uint64_t sample,
                                  std::uint64_t pair) {
  constexpr std::uint64_t kSampleMask = (std::uint64_t(1) << eyelib::kZSobolSampleBits) - 1;
  using eyelib::SplitMix64;
  const std::uint64_t beyond =
      (std::uint64_t(x >> 16) << 48) ^ (std::uint64_t(y >> 16) << 32) ^ (sample >> eyelib::kZSobolSampleBits);
  const std::uint64_t pairSeed = SplitMix64(seed ^ SplitMix64(pair ^ SplitMix64(beyond)));
  const std::uint64_t index = (eyelib::Morton2(x, y) << eyelib::kZSobolSampleBits) | (sample & kSampleMask);
  const std::uint64_t permuted = ReferenceReverse(ReferenceNestedHash(ReferenceReverse(index), pairSeed));
  const std::uint64_t first = ReferenceReverse(permuted), second = ReferenceSobol2(permuted);
  auto owen = [](std::uint64_t f, std::uint64_t s) {
    return ReferenceReverse(ReferenceNestedHash(ReferenceReverse(f), s));
  };
  return {eyelib::FractionToUnit(owen(first, SplitMix64(pairSeed ^ 0x5851f42d4c957f2dull))),
          eyelib::FractionToUnit(owen(second, SplitMix64(pairSeed ^ 0x14057b7ef767814full)))};
}

}  // namespace

TEST_CASE("zsobol points, through the key table or not, are bit for bit the sampler as first written", "[zsobol]") {
  const eyelib::ZSobolKeyTable table(77, 64);
  std::uint64_t rng = 1;
  int compared = 0;
  for (int k = 0; k < 200000; ++k) {
    rng = eyelib::SplitMix64(rng);
    // Mostly small pixels and samples (the table's), sometimes past 16 bits or the first sample block.
    const bool far = (rng & 15) == 0;
    const std::uint32_t x = std::uint32_t(rng >> 8) & (far ? 0x3ffff : 0x3ff);
    const std::uint32_t y = std::uint32_t(rng >> 28) & (far ? 0x3ffff : 0x3ff);
    const std::uint64_t sample = (rng >> 46) & (far ? 0x3ffffff : 0xfff), pair = (rng >> 40) & 63;
    const std::uint64_t seed = (rng & 16) ? 77 : rng;
    const eyelib::ZSobolPair ref = ReferencePoint(seed, x, y, sample, pair),
                             p = eyelib::ZSobolPoint(seed, x, y, sample, pair);
    REQUIRE(p.u == ref.u);
    REQUIRE(p.v == ref.v);
    const std::uint64_t beyond = eyelib::ZSobolBeyond(x, y, sample);
    if (seed == 77 && table.Find(pair, beyond)) {
      const eyelib::ZSobolPairKeys& keys = *table.Find(pair, beyond);
      const std::uint64_t permuted = eyelib::ZSobolPermuted(eyelib::ZSobolReversedIndex(x, y, sample), keys);
      REQUIRE(eyelib::ZSobolU(permuted, keys.u) == ref.u);
      REQUIRE(eyelib::ZSobolV(permuted, keys.v) == ref.v);
      ++compared;
    }
  }
  CHECK(compared > 50000);
}
