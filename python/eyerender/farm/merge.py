"""Merging a frame's sample-range renders, and proving the merge gives the single-machine image bit for bit.

A render buffer adds each float32 sample s_i into a double sum in sample order; a split frame adds the ranges'
double partial sums instead, and double addition is not associative. Two certificates decide, per value, that the
merge is nonetheless exact:

1. Exact sums. Every float32 sample is an integer multiple of its own ulp, so of the smallest ulp g among a value's
   nonzero samples. If sum|s_i| < 2^53 g, every partial sum in any order is a multiple of g below 2^53 g, which a
   double holds exactly: every addition is exact, the sequential and the merged sums are the same number.
2. Same rounding. Otherwise both sums are summation trees of the same n addends, each within gamma(n-1) sum|s_i| of
   the exact sum (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., eq. 4.4; gamma(k) = k u/(1 - k u),
   u = 2^-53). The image holds float32(S / count), monotone in S: where it takes one value over the whole interval
   [S_merged - r, S_merged + r], r = 2 gamma(n-1) sum|s_i|, the output value is the sequential render's.

A value neither certifies lies within r of a float32 rounding boundary, so merged and sequential outputs differ by
at most one float32 ulp there; the caller re-renders such a frame unsplit when it wants bit-exact outputs.
"""
import numpy as np

UNIT_ROUNDOFF = 2.0 ** -53
_NO_GRAIN = np.inf  # a value with no nonzero sample yet


class RangeAccumulator:
    """One sample range of one AOV, accumulated from single-sample buffer states exactly as a render buffer
    accumulates (sample order, double sums, non-finite samples already dropped by the renderer), plus what the
    certificates need: sum|s_i| and the smallest float32 ulp g of the nonzero samples, per value."""

    def __init__(self, height, width, components):
        self.sums = np.zeros((height, width, components))
        self.counts = np.zeros((height, width))
        self.abs_sums = np.zeros((height, width, components))
        self.grain = np.full((height, width, components), _NO_GRAIN)

    def add(self, sample, present):
        """sample: float64 (h, w, c) holding one sample's float32 values; present: (h, w), 1 where the renderer
        added a sample (it drops non-finite ones), else 0."""
        added = np.broadcast_to(present[..., None] > 0, sample.shape)
        # Only where a sample was added: 0.0 + -0.0 would turn a -0.0 sum into +0.0 where the buffer adds nothing.
        self.sums = np.where(added, self.sums + sample, self.sums)
        self.counts += present
        self.abs_sums = np.where(added, self.abs_sums + np.abs(sample), self.abs_sums)
        _, exponent = np.frexp(sample)  # |s| in [2^(e-1), 2^e): a float32's ulp there is 2^(e-24), >= 2^-149
        ulp = np.ldexp(1.0, np.maximum(exponent - 24, -149))
        self.grain = np.where(added & (sample != 0), np.minimum(self.grain, ulp), self.grain)


def merge(parts):
    """Merges RangeAccumulators of one AOV, in sample order, the way RenderBuffer::AddState does (a zeroed buffer
    plus each part). Returns (sums, counts, abs_sums, grain)."""
    sums, counts = np.zeros_like(parts[0].sums), np.zeros_like(parts[0].counts)
    abs_sums, grain = np.zeros_like(parts[0].abs_sums), np.full_like(parts[0].grain, _NO_GRAIN)
    for p in parts:
        sums, counts = sums + p.sums, counts + p.counts
        abs_sums, grain = abs_sums + p.abs_sums, np.minimum(grain, p.grain)
    return sums, counts, abs_sums, grain


def certify(sums, counts, abs_sums, grain, samples):
    """A boolean array like `sums`: True where the merged sum provably resolves to the value a sequential render
    of `samples` samples per pixel writes (module doc: certificate 1 or 2, or no sample at all)."""
    counts = np.asarray(counts, dtype=np.float64)[..., None]
    # abs_sums was itself summed in doubles; when certificate 1 holds that summing was exact, and the factor 2
    # margin (2^52, not 2^53) covers it when it is not.
    exact_sums = abs_sums < np.ldexp(grain, 52)
    k = max(samples - 1, 1) * UNIT_ROUNDOFF
    radius = 2 * (2 * k / (1 - k) * abs_sums * (1 + 2.0 ** -40))  # x2: lo and hi are rounded themselves
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        lo = ((sums - radius) / counts).astype(np.float32)
        hi = ((sums + radius) / counts).astype(np.float32)
    return np.broadcast_to(counts == 0, sums.shape) | exact_sums | (lo == hi)


__all__ = ["RangeAccumulator", "merge", "certify", "UNIT_ROUNDOFF"]
