"""bench_denoise: what Intel Open Image Denoise (eyerecord --denoise) does to the error of our sample renders.

For each sample stage it renders a reference (--ref-spp samples per pixel, seed 1), then the same frame at a few
sample counts (seed 2), denoises each with the albedo and normal AOVs as guides (eyerender.denoise), and prints the
relative RMSE against the reference before and after, over the frame and over the iris caustic (the pixels where
the reference's irisMnee AOV, the light MNEE brought to the iris, is above a quarter of its 99th percentile), and
the caustic's light kept by the denoised image (its sum over the caustic pixels over the reference's: below 1, the
denoiser has blurred the caustic into the dark iris around it). The key light's sub-pixel highlights on the cornea
(reference radiance above --highlight, with their neighbours) are left out of both: their few pixels, thousands of
times brighter than the eye, would be all the error there is. Relative RMSE: sqrt(mean((img - ref)^2)) /
mean(ref) over RGB; the reference's own noise is in every number (at 256 spp it is the floor: about 1/4 of the
16 spp error).

Writes docs/denoise_side_lit.png: the side-lit eye's iris at the lowest sample count, raw | denoised | reference.

Usage: python3 bench/bench_denoise.py [--width 96] [--ref-spp 256] [--spp 4,16,64] [--out docs/denoise_side_lit.png]
About 1.5 minutes on 2 cores at the defaults.
"""
import argparse
import os
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAMPLES = ("closeup.usda", "side_lit.usda")


def render(stage_path, width, spp, seed):
    """(beauty RGB, albedo, normal, irisMnee RGB, seconds) of a stage at `spp`."""
    from pxr import Usd

    import eyerender.plan

    session = eyerender.RenderSession(Usd.Stage.Open(stage_path), width=width,
                                      aovs=("albedo", "normal", "irisMnee"), settings={"seed": seed},
                                      plan_overrides=eyerender.plan.make_overrides())
    stats = session.render(spp=spp)
    return (session.image("color")[:, :, :3], session.image("albedo"), session.image("normal"),
            session.image("irisMnee"), stats["seconds"])


def rel_rmse(img, ref, mask):
    d = (img - ref)[mask]
    return float(np.sqrt(np.mean(d * d)) / max(np.mean(ref[mask]), 1e-12))


def caustic_mask(iris_mnee):
    lum = iris_mnee.mean(axis=2)
    if not (lum > 0).any():
        return np.zeros(lum.shape, dtype=bool)
    return lum > 0.25 * np.percentile(lum[lum > 0], 99)


def highlight_mask(ref, level):
    """The key light's specular highlights on the cornea and their neighbours: sub-pixel images of a light
    thousands of times brighter than the eye, whose few pixels would otherwise be all the error there is."""
    bright = ref.mean(axis=2) > level
    grown = bright.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(bright, dy, axis=0), dx, axis=1)
    return grown


def crop_around(mask, images, pad=4):
    """The images cropped to the mask's bounding box (plus pad pixels)."""
    ys, xs = np.nonzero(mask)
    y0, y1 = max(ys.min() - pad, 0), min(ys.max() + pad + 1, mask.shape[0])
    x0, x1 = max(xs.min() - pad, 0), min(xs.max() + pad + 1, mask.shape[1])
    return [im[y0:y1, x0:x1] for im in images]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=96)
    ap.add_argument("--ref-spp", type=int, default=256)
    ap.add_argument("--spp", default="4,16,64")
    ap.add_argument("--highlight", type=float, default=2.0,
                    help="reference radiance above which a pixel (and its 8 neighbours) is a highlight, left out")
    ap.add_argument("--out", default=os.path.join(REPO, "docs", "denoise_side_lit.png"))
    args = ap.parse_args(argv)
    import eyerender
    from eyerender.denoise import denoise_beauty

    counts = [int(s) for s in args.spp.split(",")]
    print(f"{'stage':<14} {'spp':>4} {'render s':>8} {'denoise s':>9} {'frame raw':>9} {'frame dn':>9} "
          f"{'caustic raw':>11} {'caustic dn':>10} {'caustic light kept':>18}")
    sheet = None
    for name in SAMPLES:
        path = os.path.join(REPO, "usd_samples", name)
        ref, _, _, ref_mnee, _ = render(path, args.width, args.ref_spp, 1)
        highlight = highlight_mask(ref, args.highlight)
        frame = ~highlight
        caustic = caustic_mask(ref_mnee) & ~highlight
        for spp in counts:
            img, albedo, normal, _, seconds = render(path, args.width, spp, 2)
            start = time.perf_counter()
            dn = denoise_beauty(img, albedo, normal)
            dn_seconds = time.perf_counter() - start
            kept = float(dn[caustic].sum() / max(ref[caustic].sum(), 1e-12)) if caustic.any() else float("nan")
            cr = rel_rmse(img, ref, caustic) if caustic.any() else float("nan")
            cd = rel_rmse(dn, ref, caustic) if caustic.any() else float("nan")
            print(f"{name:<14} {spp:>4} {seconds:>8.1f} {dn_seconds:>9.2f} {rel_rmse(img, ref, frame):>9.3f} "
                  f"{rel_rmse(dn, ref, frame):>9.3f} {cr:>11.3f} {cd:>10.3f} {kept:>18.3f}")
            if name == "side_lit.usda" and spp == counts[0] and caustic.any():
                # The iris region (the caustic's box widened), raw | denoised | reference, 4x nearest upscale.
                parts = crop_around(np.pad(caustic, 0), [img, dn, ref], pad=10)
                gap = np.zeros((parts[0].shape[0], 2, 3), dtype=np.float32)
                sheet = np.concatenate([parts[0], gap, parts[1], gap, parts[2]], axis=1)
                sheet = np.repeat(np.repeat(sheet, 4, axis=0), 4, axis=1)
        print(f"{name}: caustic {int(caustic.sum())} px, highlights left out {int(highlight.sum())} px, "
              f"reference {args.ref_spp} spp")
    if sheet is not None and args.out:
        eyerender.write_png_preview(args.out, np.ascontiguousarray(sheet, dtype=np.float32), 0.0)
        print(f"wrote {args.out} (raw {counts[0]} spp | denoised | reference {args.ref_spp} spp, iris crop, 4x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
