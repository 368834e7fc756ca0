"""Merging a frame's sample-range renders, and proving the merge gives the single-machine image bit for bit.

A render buffer adds each float sample s_i into a double sum in sample order; a frame split into ranges adds the
ranges' double partial sums instead. Double addition is not associative, so the two sums S_seq and S_merged can differ
in their last bits; both are summation trees of the same n addends, so each is within gamma(n-1) * sum|s_i| of the
exact sum (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., eq. 4.4; gamma(k) = k u / (1 - k u),
u = 2^-53), hence |S_seq - S_merged| <= 2 gamma(n-1) sum|s_i|. The image holds float32(S / count), a monotone
function of S; where it takes the same value at both ends of that interval, the merged output value is the
single-machine one exactly. `certify` checks this for every value; a frame with any value it cannot certify is
re-rendered unsplit by the caller, so outputs are bit-identical either way (at 64 spp about one value in 10^7
falls near enough to a float32 rounding boundary to be uncertified).

sum|s_i| is not in the buffer state, so `AbsSumBound` bounds it from the successive partial sums S_k of one
range: S_k = fl(S_{k-1} + s_k) gives |s_k| <= |S_k - S_{k-1}| + 2u |S_k|.
"""
import numpy as np

UNIT_ROUNDOFF = 2.0 ** -53


class AbsSumBound:
    """An upper bound on sum|s_i| per value, fed with a buffer's sums (float64 array) after every sample."""

    def __init__(self):
        self._previous = None
        self._bound = None

    def update(self, sums):
        sums = np.asarray(sums, dtype=np.float64)
        if self._previous is None:
            self._previous = np.zeros_like(sums)
            self._bound = np.zeros_like(sums)
        # 4u instead of 2u, and the final factor below, cover the rounding of this bookkeeping itself.
        self._bound += np.abs(sums - self._previous) + 4 * UNIT_ROUNDOFF * np.abs(sums)
        self._previous = sums.copy()

    def bound(self, shape):
        """The bound so far, zeros (nothing rendered) if update was never called."""
        if self._bound is None:
            return np.zeros(shape, dtype=np.float64)
        return self._bound * (1 + 2.0 ** -40)


def certify(sums, counts, abs_bound, samples):
    """A boolean array like `sums` (height, width, components): True where float32(S / count) is the same for
    every S within 2 gamma(samples - 1) * abs_bound of the merged sum `sums`, i.e. where the merged value is
    provably the one a single sequential render of `samples` samples per pixel produces."""
    sums = np.asarray(sums, dtype=np.float64)
    counts = np.asarray(counts, dtype=np.float64)[..., None]
    k = max(samples - 1, 1) * UNIT_ROUNDOFF
    gamma = k / (1 - k)
    # x2: lo and hi are themselves rounded; the denormal keeps a zero bound from making lo == hi trivially wrong.
    radius = 2 * (2 * gamma * np.asarray(abs_bound, dtype=np.float64)) + 5e-324
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        lo = ((sums - radius) / counts).astype(np.float32)
        hi = ((sums + radius) / counts).astype(np.float32)
    return np.broadcast_to(counts == 0, sums.shape) | (lo == hi)


__all__ = ["AbsSumBound", "certify", "UNIT_ROUNDOFF"]
