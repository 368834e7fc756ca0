#!/usr/bin/env python3
"""Figures 1 and 5 of Chiang and Burley 2018, the limbal arc: the sample eye lit from the side, rendered with the
teleportation cylinder (eye:limbalArc true) and without it (false), with the limbalArc AOV (the light of camera
paths after their first teleported sclera walk), under four light directions; then the brightness of the shadowed
limbus against the lit one, and the share of the shadowed limbus' light that came through the cylinder.

Scene (built in memory, like usd_samples/side_lit.usda: centimetres, the sample asset usd_samples/assets/eye.usda
referenced with its corneal apex at the world origin and the gaze along +z): a small SphereLight (radius 0.3 cm,
intensity 1500, 15 cm from the apex) `angle` degrees off the gaze towards the azimuth `azimuth` (0 = +x, right in
the image; 90 = +y, up), a dome fill of 0.05 as in the sample, and a 100 mm camera on the gaze 7 cm in front of the
apex (24 mm aperture: +-8.4 mm at the apex). Rendered through eyerender.RenderSession with explicit settings
(sclera scattering on, MNEE on) and no render plan, so the pictures do not depend on what a plan would choose.

Bands, in the canonical eye frame (mm, apex at the origin, gaze +z) projected to pixels through the camera onto the
eye's surface (the asset's target surface: the ellipsoid-cone cornea, the 12 mm sclera sphere): the limbus ring is
the sclera 6.6-7.6 mm from the gaze axis (just outside the outer limbus edge, 6.445 mm); the shadowed band is the
part of it within 45 degrees of the azimuth away from the light, the lit band within 45 degrees of the light's.

This module is also the scene of the regression test tests/python/test_paper_figures.py (figure 5, small).
Writes docs/figures/fig5_*.png and the fragment docs/figures/fig5.md.
Run: python3 scripts/figures/fig5_limbal_arc.py [--quick]
"""
import argparse
import inspect
import json
import math
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
import eye_profile as ep  # noqa: E402

OUT = REPO / "docs" / "figures"
ASSET = REPO / "usd_samples" / "assets" / "eye.usda"
APEX_OFFSET_CM = 1.303270723  # the asset's apex is this far in front of its eyeball centre (usd_samples/README.md)
CAMERA_Z_MM, FOCAL_MM, APERTURE_MM = 70.0, 100.0, 24.0
LIGHT_DISTANCE_CM, LIGHT_RADIUS_CM, LIGHT_INTENSITY, FILL = 15.0, 0.3, 1500.0, 0.05  # as usd_samples/side_lit.usda
SCLERA_CENTRE_Z_MM, SCLERA_RADIUS_MM = -13.033, 12.0  # the asset's sclera sphere (usd_samples/README.md)
LIMBUS_OUTER_R = ep.LIMBUS_OUTER_CHORD / 2  # 6.445 mm: the cylinder's radius
BAND_R = (6.6, 7.6)  # mm from the gaze axis: sclera just outside the limbus (as docs/limbal_arc.md measured)
BAND_HALF_ANGLE = 45.0  # degrees either side of the away-from / towards-the-light azimuth
# (label, degrees off the gaze, azimuth of the light in degrees: 0 = +x, right; 90 = +y, up)
LIGHTS = [("60°, right", 60.0, 0.0), ("75°, right", 75.0, 0.0), ("85°, right", 85.0, 0.0), ("75°, above", 75.0, 90.0)]
SEED, NOISE_SEED = 1, 2


def build_stage(limbal_arc, angle_deg, azimuth_deg=0.0, fill=FILL):
    """The side-lit eye as an in-memory stage (centimetres, Y up): the sample asset referenced with its apex at the
    origin, eye:limbalArc authored on the eyeball, the key light, the fill dome and the camera on the gaze."""
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.Xform.Define(stage, "/World")
    eye = UsdGeom.Xform.Define(stage, "/World/Eye")
    eye.GetPrim().GetReferences().AddReference(str(ASSET))
    eye.AddTranslateOp().Set(Gf.Vec3d(0, 0, -APEX_OFFSET_CM))
    stage.GetPrimAtPath("/World/Eye/Eyeball").CreateAttribute("eye:limbalArc", Sdf.ValueTypeNames.Bool).Set(
        bool(limbal_arc))
    key = UsdLux.SphereLight.Define(stage, "/World/Lights/Key")
    key.CreateIntensityAttr(LIGHT_INTENSITY)
    key.CreateRadiusAttr(LIGHT_RADIUS_CM)
    a, b = math.radians(angle_deg), math.radians(azimuth_deg)
    key.AddTranslateOp().Set(Gf.Vec3d(LIGHT_DISTANCE_CM * math.sin(a) * math.cos(b),
                                      LIGHT_DISTANCE_CM * math.sin(a) * math.sin(b), LIGHT_DISTANCE_CM * math.cos(a)))
    if fill > 0:
        UsdLux.DomeLight.Define(stage, "/World/Lights/Fill").CreateIntensityAttr(fill)
    cam = UsdGeom.Camera.Define(stage, "/World/Camera")
    cam.CreateFocalLengthAttr(FOCAL_MM)
    cam.CreateHorizontalApertureAttr(APERTURE_MM)
    cam.CreateVerticalApertureAttr(APERTURE_MM)
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.1, 10000.0))
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, CAMERA_Z_MM / 10))
    return stage


def session_options():
    """Keyword arguments that keep RenderSession from planning: plan_overrides None means "the settings as given".
    A render planner is being added; if RenderSession grows an automatic-plan switch, it is turned off here, so the
    figures show the features they ask for (sclera scattering, MNEE, the cylinder) whatever a plan would pick."""
    import eyerender

    params = inspect.signature(eyerender.RenderSession.__init__).parameters
    options = {"plan_overrides": None} if "plan_overrides" in params else {}
    for name in ("auto_plan", "plan"):
        if name in params:
            options[name] = False
    return options


def render(limbal_arc, angle_deg, azimuth_deg, width, spp, seed, threads=2):
    """One render; returns (colour RGB, limbalArc RGB, seconds, rays), float32 (width, width, 3)."""
    import eyerender

    stage = build_stage(limbal_arc, angle_deg, azimuth_deg)
    session = eyerender.RenderSession(stage, width=width, height=width, aovs=("limbalArc",),
                                      settings={"sclera_scattering": True, "mnee": True, "seed": seed,
                                                "threads": threads}, **session_options())
    start = time.perf_counter()
    stats = session.render(spp=spp)
    seconds = time.perf_counter() - start
    if stats["non_finite_samples"]:
        raise RuntimeError(f"limbal arc {limbal_arc}, {angle_deg} deg: {stats['non_finite_samples']} "
                           "non-finite samples")
    return session.image("color")[:, :, :3].copy(), session.image("limbalArc").copy(), seconds, stats["rays"]


def luminance(rgb):
    """Rec. 709 luminance of linear RGB (the sclera is not grey, so a plain mean would over-weight blue)."""
    return rgb @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float64)


def surface_z(r):
    """Height (mm) of the eye's front surface at distance r from the gaze axis: the ellipsoid-cone cornea inside the
    outer limbus, the 12 mm sclera sphere past the 0.5 mm blend, linear in between (the two differ by < 0.03 mm
    there, far below a pixel)."""
    r = np.asarray(r, dtype=float)
    cornea = ep.ellipsoid_cone_sag(np.minimum(r, ep.RIM_R))
    sphere = SCLERA_CENTRE_Z_MM + np.sqrt(np.maximum(SCLERA_RADIUS_MM ** 2 - r * r, 0.0))
    t = np.clip((r - LIMBUS_OUTER_R) / 0.5, 0.0, 1.0)
    return np.where(r < LIMBUS_OUTER_R, cornea, (1 - t) * cornea + t * sphere)


def pixel_to_canonical(width):
    """For each pixel centre: the distance from the gaze axis (mm) and the azimuth (degrees, 0 = +x, 90 = +y) of
    the point where its camera ray meets the eye's front surface. The camera sits on the axis, so a ray's
    direction has slope q = (film radius / focal length) and meets the surface at r with r / (z_cam - z(r)) = q;
    q(r) is monotonic on the visible front, so it is inverted by interpolation."""
    c = ((np.arange(width) + 0.5) / width - 0.5) * APERTURE_MM / FOCAL_MM
    qx, qy = np.meshgrid(c, -c)  # row 0 is the top (+y)
    q = np.hypot(qx, qy)
    r_table = np.linspace(0.0, 11.0, 4001)
    q_table = r_table / (CAMERA_Z_MM - surface_z(r_table))
    return np.interp(q, q_table, r_table), np.degrees(np.arctan2(qy, qx)) % 360.0


def bands(width, azimuth_deg=0.0, band_r=BAND_R):
    """Masks (ring, shadowed, lit) of the limbus ring's pixels, the shadowed band (away from the light) and the lit
    band (towards it)."""
    r, phi = pixel_to_canonical(width)
    ring = (r > band_r[0]) & (r < band_r[1])
    rel = (phi - azimuth_deg + 180.0) % 360.0 - 180.0  # -180..180, 0 = towards the light
    return ring, ring & (np.abs(np.abs(rel) - 180.0) < BAND_HALF_ANGLE), ring & (np.abs(rel) < BAND_HALF_ANGLE)


def ring_profile(lum, width, azimuth_deg, step=15.0, band_r=BAND_R):
    """Mean of `lum` over the limbus ring in azimuth bins of `step` degrees, measured from the light's azimuth."""
    r, phi = pixel_to_canonical(width)
    ring = (r > band_r[0]) & (r < band_r[1])
    rel = (phi - azimuth_deg) % 360.0
    edges = np.arange(0.0, 360.0 + step, step)
    idx = np.digitize(rel[ring], edges) - 1
    return 0.5 * (edges[1:] + edges[:-1]), np.array([lum[ring][idx == k].mean() for k in range(len(edges) - 1)])


def measure(color, arc, width, azimuth_deg):
    """Band means (luminance) of colour and of the limbalArc AOV."""
    _, shadow, lit = bands(width, azimuth_deg)
    lc, la = luminance(color), luminance(arc)
    return {"shadow": float(lc[shadow].mean()), "lit": float(lc[lit].mean()),
            "arc_shadow": float(la[shadow].mean()), "arc_lit": float(la[lit].mean()), "arc_sum": float(la.sum()),
            "shadow_px": int(shadow.sum()), "lit_px": int(lit.sum())}


def tone(rgb, scale):
    """Linear RGB -> 8-bit (gamma 2.2) after multiplying by `scale`; clipped."""
    return (np.clip(rgb * scale, 0, 1) ** (1 / 2.2) * 255 + 0.5).astype(np.uint8)


def save_rgb(path, rgb, scale):
    from PIL import Image

    Image.fromarray(tone(rgb, scale), mode="RGB").save(path)


def contact_sheet(out, tiles, columns):
    """scripts/contact_sheet.py tiles the PNGs; the sheet is then re-encoded as a 256-colour PNG to keep the docs
    small (noisy renders compress badly; the palette costs less than the noise)."""
    from PIL import Image

    subprocess.run([sys.executable, str(REPO / "scripts" / "contact_sheet.py"), str(out)] + [str(t) for t in tiles]
                   + ["--columns", str(columns)], check=True, cwd=REPO)
    Image.open(out).convert("RGB").quantize(256, dither=Image.Dither.NONE).save(out, optimize=True)


def plot_profiles(path, profiles):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, len(profiles), figsize=(6.4, 1.7), dpi=100, sharey=True)
    for ax, (label, prof) in zip(axes, profiles.items()):
        x = prof["angle"]
        ax.plot(x, prof["on"], "-", color="tab:orange", lw=1.0, label="arc on")
        ax.plot(x, prof["off"], "--", color="k", lw=1.0, label="arc off")
        ax.plot(x, prof["aov"], ":", color="tab:blue", lw=1.2, label="limbalArc AOV (on)")
        ax.axvspan(180 - BAND_HALF_ANGLE, 180 + BAND_HALF_ANGLE, color="0.9", lw=0)
        ax.set_yscale("log")
        ax.set_title(label, fontsize=6.5)
        ax.set_xticks([0, 90, 180, 270, 360])
        ax.tick_params(which="both", labelsize=5.5)
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("azimuth from the light (deg)", fontsize=5.5)
    axes[0].set_ylabel("limbus ring luminance", fontsize=6)
    axes[0].legend(fontsize=5, frameon=False, loc="lower left")
    fig.tight_layout(pad=0.3)
    fig.savefig(path)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small, noisy renders (a smoke run, not for the page)")
    args = parser.parse_args()
    command = "python3 scripts/figures/fig5_limbal_arc.py" + (" --quick" if args.quick else "")
    print(f"$ {command}")
    start = time.perf_counter()
    width, spp = (64, 8) if args.quick else (160, 48)
    OUT.mkdir(parents=True, exist_ok=True)

    rows, images, profiles = [], {}, {}
    for label, angle, azimuth in LIGHTS:
        row = {"label": label, "angle": angle, "azimuth": azimuth}
        for arc in (True, False):
            color, aov, seconds, rays = render(arc, angle, azimuth, width, spp, SEED)
            key = "on" if arc else "off"
            images[(label, key)] = (color, aov)
            row[key], row[f"{key}_s"], row[f"{key}_rays"] = measure(color, aov, width, azimuth), seconds, rays
            m = row[key]
            print(f"  {label:11s} arc {key:3s}: shadowed {m['shadow']:.4f}, lit {m['lit']:.4f}, limbalArc shadowed "
                  f"{m['arc_shadow']:.4f} ({m['shadow_px']} / {m['lit_px']} px), {seconds:.1f} s, "
                  f"{rays / 1e6:.1f} M rays")
        angles, on_p = ring_profile(luminance(images[(label, "on")][0]), width, azimuth)
        profiles[label] = {"angle": angles, "on": on_p,
                           "off": ring_profile(luminance(images[(label, "off")][0]), width, azimuth)[1],
                           "aov": ring_profile(luminance(images[(label, "on")][1]), width, azimuth)[1]}
        rows.append(row)

    # Seed-to-seed spread of the band means: the 75 deg light, arc on, again with another seed.
    label, angle, azimuth = LIGHTS[1]
    color2, aov2, seconds2, _ = render(True, angle, azimuth, width, spp, NOISE_SEED)
    m1, m2 = rows[1]["on"], measure(color2, aov2, width, azimuth)
    spread = {k: abs(m2[k] - m1[k]) / m1[k] for k in ("shadow", "lit", "arc_shadow")}
    print(f"  seed spread ({label}, arc on, seeds {SEED} / {NOISE_SEED}): " + ", ".join(
        f"{k} {v:.1%}" for k, v in spread.items()) + f" ({seconds2:.1f} s)")

    # One exposure for every colour image: the 99.5th percentile of the 75-degree arc-off render over the ring at
    # 0.9 (the lit sclera), the limbalArc AOV included, so its tile reads as the part of the arc-on tile that came
    # through the cylinder.
    ring75 = bands(width, 0.0)[0]
    scale = 0.9 / np.percentile(luminance(images[(LIGHTS[1][0], "off")][0])[ring75], 99.5)
    tiles = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, (label, _, _) in enumerate(LIGHTS):
            (on, aov), (off, _) = images[(label, "on")], images[(label, "off")]
            for name, img, s in (("on", on, scale), ("off", off, scale), ("aov", aov, scale)):
                p = pathlib.Path(tmp) / f"{i}_{name}.png"
                save_rgb(p, img, s)
                tiles.append(p)
        contact_sheet(OUT / "fig5_sheet.png", tiles, 3)
    plot_profiles(OUT / "fig5_profiles.png", profiles)
    total = time.perf_counter() - start
    write_markdown(rows, spread, width, spp, total, command, seconds2)
    (OUT / "fig5_numbers.json").write_text(json.dumps(
        {"width": width, "spp": spp, "rows": rows, "seed_spread_75_on": spread}, indent=1, default=float) + "\n")
    print(f"  wrote docs/figures/fig5_sheet.png, fig5_profiles.png, fig5.md in {total:.0f} s")
    return 0


def write_markdown(rows, spread, width, spp, total, command, noise_seconds):
    md = ["<!-- generated by scripts/figures/fig5_limbal_arc.py; do not edit by hand -->", ""]
    md += [f"The sample eye (`usd_samples/assets/eye.usda`, its textured sclera), head-on, {width}x{width} px, {spp} "
           "spp, a small sphere light 15 cm away (radius 0.3 cm, as `usd_samples/side_lit.usda`) and a 0.05 dome "
           "fill; sclera scattering and MNEE on, no render plan.", ""]
    md += ["![limbal arc contact sheet](figures/fig5_sheet.png)", ""]
    md += ["Columns: arc on (`eye:limbalArc = true`), arc off, the `limbalArc` AOV of the arc-on render. Rows: "
           + "; ".join(f"{r['label']} (light {r['angle']:.0f}° off the gaze, towards "
                       f"{'+x' if r['azimuth'] == 0 else '+y'})" for r in rows)
           + ". One exposure for every tile, the AOV's included.", ""]
    md += ["| light | render on / off (s) | shadowed limbus, on | shadowed, off | arc gain (on / off) | lit limbus, on "
           "| lit, off | lit change | shadowed / lit, on | shadowed / lit, off | through the cylinder (AOV / colour, "
           "shadowed, on) | same, lit band |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        on, off = r["on"], r["off"]
        md.append(f"| {r['label']} | {r['on_s']:.1f} / {r['off_s']:.1f} | {on['shadow']:.4f} | {off['shadow']:.4f} | "
                  f"{on['shadow'] / off['shadow']:.1f}x | {on['lit']:.4f} | {off['lit']:.4f} | "
                  f"{on['lit'] / off['lit'] - 1:+.0%} | {on['shadow'] / on['lit']:.3f} | "
                  f"{off['shadow'] / off['lit']:.3f} | {on['arc_shadow'] / on['shadow']:.0%} | "
                  f"{on['arc_lit'] / on['lit']:.0%} |")
    n = rows[0]["on"]
    md += ["", f"Brightness: Rec. 709 luminance of the linear colour, averaged over the band's pixels. Bands "
           f"(canonical frame, projected to pixels through the camera onto the eye's surface): the sclera "
           f"{BAND_R[0]}-{BAND_R[1]} mm from the gaze axis (the cylinder's radius is {LIMBUS_OUTER_R:.3f} mm), within "
           f"{BAND_HALF_ANGLE:.0f}° of the azimuth away from the light (shadowed) or towards it (lit); "
           f"{n['shadow_px']} and {n['lit_px']} pixels. "
           "\"Through the cylinder\": the limbalArc AOV (everything a camera path gathers after its first teleported "
           "walk) over the colour, in the shadowed band, arc on. With the arc off the AOV is 0 everywhere (sum: "
           + ", ".join(f"{r['off']['arc_sum']:g}" for r in rows) + ").", ""]
    md += [f"Noise: the {rows[1]['label']} arc-on render again with another seed ({noise_seconds:.1f} s) moves the "
           f"shadowed band's mean by {spread['shadow']:.1%}, the lit band's by {spread['lit']:.1%} and the shadowed "
           f"limbalArc mean by {spread['arc_shadow']:.1%}: the differences in the table are far outside the noise "
           "unless they are of that size.", ""]
    md += ["![limbus ring profiles](figures/fig5_profiles.png)", "",
           "Luminance around the limbus ring (log scale; 15° bins; 0° = towards the light, grey: the shadowed band): "
           "arc on (orange), off (black dashed), and the limbalArc AOV (blue dotted).", ""]
    md += [f"Regenerate: `{command}` ({total:.0f} s on this machine, 2 threads; "
           "numbers also in `docs/figures/fig5_numbers.json`).", ""]
    (OUT / "fig5.md").write_text("\n".join(md) + "\n")


if __name__ == "__main__":
    sys.exit(main())
