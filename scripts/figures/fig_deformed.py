#!/usr/bin/env python3
"""The paper's deformed-eye claim (section 2, "Implementation"; no figure in the paper): hits on an animated,
deformed eye surface are re-projected onto the analytic eye through an iris projection, so the iris caustic stays
plausible however the eyeball is squashed or stretched. Shown on usd_samples/squash_stretch.usda (points animated
over frames 1-24: scale s along the gaze and 1/sqrt(s) across, s = 1 -> 1.5 -> 0.67 -> 1) with re-projection on
(EyeParams.reprojection, the default) and off (the comparison baseline: the analytic eye carried by the mesh's
best-fit affine deformation, docs/deformed_eyes.md), at frames 1 (rest), 7 (stretch 1.5), 13 (about 1) and
18 (squash 0.67).

Two kinds of renders, both through eyerender.RenderSession with explicit settings and no render plan:
- pictures: the sample's own camera (60 degrees off the gaze), its iris texture and lights, sclera scattering and
  MNEE on;
- measurement (the method of docs/deformed_eyes.md and tests/python/test_deformed_eye.py): a camera on the gaze
  (session layer), the iris textured with (R, G, B) = (u, v, 1) so that each pixel's irisMnee AOV gives the iris
  texture position it sees (R/B, G/B) and its iris radiance (B); pixels binned by iris position, a bin's value the
  median radiance of its pixels; the departure of a frame's caustic from the rest frame's is the relative RMS of
  the bin values over bins 2.6-4.4 mm from the axis that both see. Noise: the rest frame again with another seed.
  These renders turn sclera scattering off and cap the depth at 2: irisMnee is the iris' direct light through the
  cornea, which neither changes (the same settings as the test, so the numbers compare).

There is no eye:reprojection attribute (the switch is a comparison baseline, not an artist control), so the switch
is set through the Python API: the session's scene delegate reads the eye's params, the script flips
`reprojection` and pushes them with SceneStore.set_eye_params after every frame change.

Writes docs/figures/fig_deformed_sheet.png and the fragment docs/figures/fig_deformed.md.
Run: python3 scripts/figures/fig_deformed.py [--quick]
"""
import argparse
import json
import pathlib
import sys
import tempfile
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
import fig5_limbal_arc as f5  # noqa: E402  (session options, tone mapping, contact sheet)

OUT = REPO / "docs" / "figures"
SAMPLE = REPO / "usd_samples" / "squash_stretch.usda"
EYE_ID = "/World/Eye/Eyeball"
FRAMES = (1, 7, 13, 18)
IRIS_DIAMETER_MM = 15.08
BAND_MM = (2.6, 4.4)  # bins compared: past the pupil edge, inside the limbus (docs/deformed_eyes.md)


def stretch(frame):
    """The sample's scale along the gaze at a frame: s = 1.5^sin(2 pi (f - 1) / 23)."""
    return 1.5 ** np.sin(2 * np.pi * (frame - 1) / 23)


def uv_texture(path, n=128):
    """(R, G, B) = (u, v, 1): the iris position as colour (v up, USD's convention)."""
    from eyerender._hdeye import write_exr

    u = np.tile((np.arange(n, dtype=np.float32) + 0.5) / n, (n, 1))
    v = 1 - np.tile(((np.arange(n, dtype=np.float32) + 0.5) / n)[:, None], (1, n))
    write_exr(str(path), [("R", u), ("G", v), ("B", np.ones((n, n), np.float32))])


def iris_bins(image, bins):
    """irisMnee binned by the iris texture position each pixel sees: per bin the median radiance (MNEE's per-pixel
    estimates are heavy-tailed near caustic folds; means do not converge) and the pixel count; and each bin
    centre's distance from the iris centre (mm)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    seen = b > 1e-9
    u, v, w = r[seen] / b[seen], g[seen] / b[seen], b[seen]
    i = np.clip((u * bins).astype(int), 0, bins - 1)
    j = np.clip((v * bins).astype(int), 0, bins - 1)
    out, count = np.zeros((bins, bins)), np.zeros((bins, bins))
    for jj in range(bins):
        for ii in range(bins):
            sel = (i == ii) & (j == jj)
            count[jj, ii] = sel.sum()
            out[jj, ii] = np.median(w[sel]) if sel.any() else 0.0
    centres = ((np.arange(bins) + 0.5) / bins - 0.5) * IRIS_DIAMETER_MM
    return out, count, np.hypot(*np.meshgrid(centres, centres))


def relative_rms(a, ref, min_count=3):
    """sqrt(sum (a - ref)^2 / sum ref^2) over bins both see (>= min_count pixels) within BAND_MM; (value, bins)."""
    (va, ca, radius), (vr, cr, _) = a, ref
    sel = (ca >= min_count) & (cr >= min_count) & (radius >= BAND_MM[0]) & (radius <= BAND_MM[1])
    return float(np.sqrt(((va[sel] - vr[sel]) ** 2).sum() / (vr[sel] ** 2).sum())), int(sel.sum())


def open_stage(gaze_camera):
    from pxr import Gf, Usd, UsdGeom

    stage = Usd.Stage.Open(str(SAMPLE))
    if gaze_camera:
        # On the gaze axis, 8 cm from the eyeball centre (session layer; the sample is not changed). Head-on the
        # entry Fresnel is flat over the inner iris, so what the bins hold is the caustic.
        with Usd.EditContext(stage, stage.GetSessionLayer()):
            cam = UsdGeom.Camera.Define(stage, "/World/GazeCamera")
            cam.GetFocalLengthAttr().Set(100.0)
            cam.GetHorizontalApertureAttr().Set(24.0)
            cam.GetVerticalApertureAttr().Set(24.0)
            cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 8))
    return stage


def render_frames(reprojection, *, measure, width, spp, uv_path, log):
    """Renders FRAMES (and frame 1 with a second seed when measuring) with one session; returns
    {(frame, seed): (image, seconds)}: the colour for pictures, irisMnee for the measurement."""
    import eyerender  # before pxr: it registers the EyeAPI schema
    # isort: split
    from pxr import Usd

    stage = open_stage(gaze_camera=measure)
    settings = ({"sclera_scattering": False, "max_depth": 2, "mnee": True} if measure
                else {"sclera_scattering": True, "mnee": True})
    settings["threads"] = 2
    session = eyerender.RenderSession(stage, width=width, height=width, aovs=("irisMnee",), refine_level=1,
                                      camera="/World/GazeCamera" if measure else "/World/Camera", time=1,
                                      settings=settings, **f5.session_options())
    prim = stage.GetPrimAtPath(EYE_ID)
    out = {}
    jobs = [(1, 0), (1, 1)] + [(f, 0) for f in FRAMES[1:]] if measure else [(f, 0) for f in FRAMES]
    for frame, seed in jobs:
        session.scene.set_time(frame)
        eye = session.scene.adapters.eye.mesh_params(prim, Usd.TimeCode(frame))  # the params the sample authors
        eye.reprojection = reprojection
        if measure:
            eye.iris_texture, eye.iris_color = str(uv_path), (1.0, 1.0, 1.0)
        session.store.set_eye_params(EYE_ID, eye)
        session.delegate.settings.seed = seed
        stats = session.render(spp=spp)
        if stats["non_finite_samples"]:
            raise RuntimeError(f"frame {frame}: {stats['non_finite_samples']} non-finite samples")
        image = session.image("irisMnee" if measure else "color")[..., :3].copy()
        out[(frame, seed)] = (image, stats["seconds"])
        log(f"  {'measure' if measure else 'picture'} re-projection {'on ' if reprojection else 'off'} frame "
            f"{frame:2d} seed {seed}: {stats['seconds']:.1f} s")
    mesh = session.index.mesh_stats(EYE_ID)
    return out, mesh


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small, noisy renders (a smoke run, not for the page)")
    args = parser.parse_args()
    command = "python3 scripts/figures/fig_deformed.py" + (" --quick" if args.quick else "")
    print(f"$ {command}")
    start = time.perf_counter()
    pic_width, pic_spp, m_width, m_spp, bins = (64, 4, 64, 8, 8) if args.quick else (128, 32, 128, 24, 12)
    OUT.mkdir(parents=True, exist_ok=True)

    with tempfile.TemporaryDirectory() as tmp:
        uv = pathlib.Path(tmp) / "uv.exr"
        uv_texture(uv)
        pictures, measured, mesh_stats = {}, {}, {}
        for on in (True, False):
            pictures[on], _ = render_frames(on, measure=False, width=pic_width, spp=pic_spp, uv_path=uv, log=print)
            measured[on], mesh_stats[on] = render_frames(on, measure=True, width=m_width, spp=m_spp, uv_path=uv,
                                                         log=print)

        binned = {on: {k: iris_bins(img, bins) for k, (img, _) in measured[on].items()} for on in (True, False)}
        ref = binned[True][(1, 0)]
        noise, noise_bins = relative_rms(binned[True][(1, 1)], ref)
        rows = []
        for frame in FRAMES:
            row = {"frame": frame, "s": float(stretch(frame))}
            for on in (True, False):
                key = "on" if on else "off"
                row[key], row[f"{key}_bins"] = relative_rms(binned[on][(frame, 0)], ref)
                row[f"{key}_pic_s"] = pictures[on][(frame, 0)][1]
                row[f"{key}_meas_s"] = measured[on][(frame, 0)][1]
            rows.append(row)
            print(f"  frame {frame:2d} (s = {row['s']:.3f}): departure re-projection {row['on']:.3f} "
                  f"({row['on_bins']} bins), baseline {row['off']:.3f} ({row['off_bins']} bins); noise {noise:.3f}")

        # Contact sheet: rows re-projection / baseline pictures, then re-projection / baseline caustic (irisMnee B,
        # the iris radiance, gaze camera); columns the frames. One exposure per kind.
        pic_scale = 0.9 / np.percentile(f5.luminance(pictures[True][(1, 0)][0]), 99.5)
        caustic_scale = 0.9 / np.percentile(measured[True][(1, 0)][0][..., 2], 99.5)
        tiles = []
        for kind, on in (("pic", True), ("pic", False), ("caustic", True), ("caustic", False)):
            for frame in FRAMES:
                p = pathlib.Path(tmp) / f"{kind}_{int(on)}_{frame}.png"
                if kind == "pic":
                    f5.save_rgb(p, pictures[on][(frame, 0)][0], pic_scale)
                else:
                    b = measured[on][(frame, 0)][0][..., 2]
                    f5.save_rgb(p, np.repeat(b[..., None], 3, -1), caustic_scale)
                tiles.append(p)
        f5.contact_sheet(OUT / "fig_deformed_sheet.png", tiles, len(FRAMES))

    total = time.perf_counter() - start
    write_markdown(rows, noise, noise_bins, measured, mesh_stats, pic_width, pic_spp, m_width, m_spp, bins, total,
                   command)
    (OUT / "fig_deformed_numbers.json").write_text(json.dumps(
        {"noise": noise, "rows": rows, "mesh_stats": {str(k): v for k, v in mesh_stats.items()}}, indent=1,
        default=float) + "\n")
    print(f"  wrote docs/figures/fig_deformed_sheet.png and fig_deformed.md in {total:.0f} s")
    return 0


def write_markdown(rows, noise, noise_bins, measured, mesh_stats, pic_width, pic_spp, m_width, m_spp, bins, total,
                   command):
    md = ["<!-- generated by scripts/figures/fig_deformed.py; do not edit by hand -->", ""]
    md += ["![deformed eye contact sheet](figures/fig_deformed_sheet.png)", ""]
    md += ["Columns: frames " + ", ".join(f"{r['frame']} (s = {r['s']:.2f})" for r in rows) + ". Rows: the sample's "
           f"camera (60° off the gaze; {pic_width}x{pic_width} px, {pic_spp} spp, sclera scattering and MNEE on) with "
           "re-projection, then with the baseline; then the iris radiance (irisMnee) seen from a camera on the gaze, "
           "with re-projection, then with the baseline (the measurement renders below). One exposure per kind.", ""]
    md += ["| frame | stretch s | departure, re-projection | / noise | departure, baseline | / noise | bins (on / off) "
           "| render s, pictures (on / off) | render s, measurement (on / off) |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        # Frame 1 with re-projection is the reference itself (its departure is 0 by definition).
        on = "reference | -" if r["frame"] == 1 else f"{r['on']:.3f} | {r['on'] / noise:.2f}"
        md.append(f"| {r['frame']} | {r['s']:.3f} | {on} | {r['off']:.3f} | "
                  f"{r['off'] / noise:.2f} | {r['on_bins']} / {r['off_bins']} | {r['on_pic_s']:.1f} / "
                  f"{r['off_pic_s']:.1f} | {r['on_meas_s']:.1f} / {r['off_meas_s']:.1f} |")
    seed_s = measured[True][(1, 1)][1]
    md += ["", f"Departure: the relative RMS of the caustic read back in iris texture space ({bins}x{bins} bins over "
           f"the 15.08 mm iris square, median radiance per bin, bins {BAND_MM[0]}-{BAND_MM[1]} mm from the axis seen "
           f"by both with >= 3 pixels) against frame 1 with re-projection; measurement renders {m_width}x{m_width} "
           f"px, {m_spp} spp, camera on the gaze, sclera scattering off, depth 2. Noise: frame 1 with another seed, "
           f"{noise:.3f} over {noise_bins} bins ({seed_s:.1f} s). Frame 1 is the rest pose, where the two modes "
           "should agree (the affine fit is the identity); its baseline render uses the reference's seed, so that "
           "difference is not noise-limited.", ""]
    on = mesh_stats[True]
    md += [f"One session per mode renders every frame: the mesh was refined {on['refinements']} time(s), its topology "
           f"built {on['topology_builds']} time(s), its stencils evaluated {on['stencil_evaluations']} times "
           "(the re-projection measurement session).", ""]
    md += [f"Regenerate: `{command}` ({total:.0f} s on this machine, 2 threads; numbers also in "
           "`docs/figures/fig_deformed_numbers.json`).", ""]
    (OUT / "fig_deformed.md").write_text("\n".join(md) + "\n")


if __name__ == "__main__":
    sys.exit(main())
