"""Error of a rendered image against a reference: a relative RMSE that dark pixels cannot blow up, split into noise
and bias with two renders of different seeds.

The per-element error is e = (x - r) / sqrt(r^2 + eps) over RGB, with eps = k * mean(r)^2 over the counted pixels:
where r is well above k^0.5 * mean(r) it is the plain relative error (x - r) / r; at r = 0 it is (x - r) relative
to k^0.5 * mean(r), not a division by zero (a side-lit eye's black background otherwise made the RMSE 266 %). It
does not depend on the image's exposure. k = 0.01 (default): a pixel at a tenth of the mean is weighed as if it were
at 0.14 of the mean.

With two renders a, b of independent seeds (the decomposition of the shared sceneB compare.py):
  noise = sqrt(mean((e_a - e_b)^2) / 2)   the per-render noise (the seeds' differences hold only noise)
  bias  = sqrt(max(mean(e_a * e_b), 0))   the part of the error both seeds share: the render's bias, plus the
                                          reference's own noise (a reference of few samples raises this floor)
  rmse  = sqrt((mean(e_a^2) + mean(e_b^2)) / 2), so rmse^2 = noise^2 + bias^2 (exactly, while mean(e_a e_b) >= 0).
Over n elements an unbiased render still reads bias ~ noise / n^(1/4) (mean(e_a e_b) scatters by noise^2 / sqrt(n)):
a bias is resolved only above that.
"""
import numpy as np

DEFAULT_K = 0.01  # eps = k * mean(ref)^2: dimensionless, relative to the reference's mean squared


def relative_errors(img, ref, mask=None, k=DEFAULT_K):
    """Per-element robust relative errors (img - ref) / sqrt(ref^2 + k * mean(ref)^2), flattened, over the RGB
    of the pixels in `mask` (bool (h, w); None: the frame). Images are (h, w, >=3) arrays in any one unit.
    Empty mask or a reference whose mean is not positive: an empty array."""
    a, b = np.asarray(img, np.float64)[:, :, :3], np.asarray(ref, np.float64)[:, :, :3]
    if mask is not None:
        a, b = a[mask], b[mask]
    a, b = a.reshape(-1), b.reshape(-1)
    mean = float(b.mean()) if b.size else 0.0
    if not mean > 0:
        return np.empty(0)
    return (a - b) / np.sqrt(b * b + k * mean * mean)


def rel_rmse(img, ref, mask=None, k=DEFAULT_K):
    """sqrt(mean(relative_errors^2)): NaN when nothing is counted (empty mask, black reference)."""
    e = relative_errors(img, ref, mask, k)
    return float(np.sqrt(np.mean(e * e))) if e.size else float("nan")


def error_noise_bias(img_a, img_b, ref, mask=None, k=DEFAULT_K):
    """(rmse, noise, bias) of two renders of independent seeds against `ref` (see the module's doc); NaNs when
    nothing is counted."""
    ea, eb = relative_errors(img_a, ref, mask, k), relative_errors(img_b, ref, mask, k)
    if not ea.size:
        return float("nan"), float("nan"), float("nan")
    rmse = np.sqrt((np.mean(ea * ea) + np.mean(eb * eb)) / 2)
    noise = np.sqrt(np.mean((ea - eb) ** 2) / 2)
    bias = np.sqrt(max(float(np.mean(ea * eb)), 0.0))
    return float(rmse), float(noise), float(bias)
