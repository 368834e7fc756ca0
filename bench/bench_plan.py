"""bench_plan: the sweeps behind the render plan's thresholds (delegate/hdeye/plan/renderPlan.h, docs/render_plan.md).

Each sweep renders small in-memory stages (millimetre units: an analytic eye -- an Xform with EyeAPI -- at the origin
gazing +z, a grey backdrop card behind it, a camera on the gaze axis, and sphere / dome lights) through the installed
eyerender package, and measures render time and error against a converged reference rendered with the feature on:

  1. eye size on screen (pixels): MNEE on vs off, small key light      -> PlanRules::mneeMinPixels
  2. light solid angle (sr) at 30 and 75 degrees (--angles, --radii), and a dome: MNEE on vs off
     -> PlanRules::mneeMaxSolidAngleSr, mneeMaxSolidAngleSrGrazing, grazingAngleDeg
  3. light direction (degrees off the gaze): all-solutions MNEE on vs off -> PlanRules::allSolutions*
  4. path depth (maxDepth) on a side-lit eye: what cutting depth changes -> the chamber/depth decision

Error: relative RMSE over the eye's pixels (the eye's primId) and over the frame: sqrt(mean((img - ref)^2)) /
mean(ref) over RGB, with the worst 0.1% of pixels dropped (single-sample fireflies of sub-pixel highlights). "eff"
is the efficiency 1 / (rel MSE x seconds); the ratio of two methods' efficiencies is their equal-error time ratio
(both estimators are unbiased up to MNEE's missed second paths).
The reference's own noise is subtracted from the MSE (estimated from the feature-on run at spp/ref_spp of its MSE).

  sclera. eye size x side/front key: random-walk sclera + limbal arc vs walk alone vs Lambert, equal time
     -> PlanRules::sssMinPixels, sssMinLimbusPixels, limbalArcMinLightAngleDeg
  refine. eye size x Catmull-Clark level 0-3 of the eye mesh: image and outline error vs level 3, sync cost
     -> PlanRules::refinePixelsLevel1, refineMaxLevel
  chamber. the chamber walk's bound (1-64 events per eye, through PlanOverrides.chamber_events), side/front key
     -> PlanRules::chamberEvents
  allsol-size. eye size (close-ups on the caustic fold) x 80-89 deg key: all-solutions MNEE on vs off
     -> PlanRules::allSolutionsMinPixels
  dome-arc. eye size, a dome alone: walk + limbal arc vs walk without it, equal time -> PlanRules::limbalArc*
  dome-contrast. scene C's dome (bench/scene_c.py), its window 1-20 x the sky, alone and beside a key: MNEE vs BSDF
     sampling, by the dome's radiance contrast about the gaze -> PlanRules::mneeMinDomeContrast
sclera, refine and dome-arc render usd_samples/assets/eye.usda (an eye mesh with the sclera walk), not the analytic eye.

Usage: python3 bench/bench_plan.py [--quick] [--out-dir docs] [--csv PREFIX] [--sweeps 1,2,3,4] [--sweep NAME]
Single-threaded renders by default (--threads), so times compare; the machine is shared.
"""
import argparse
import csv
import math
import os
import sys
import time

import numpy as np

import eyerender  # noqa: F401  (registers the EyeAPI schema before stages are made)

# isort: split
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

from eyerender.plan import make_overrides
from eyerender.render_session import RenderSession

LIGHT_DISTANCE = 200.0  # mm, from the iris centre to the key's centre
IRIS_Z = -3.735  # mm: the iris plane in the canonical frame (lights are placed from the iris centre)


def make_stage(*, camera_distance=40.0, light="sphere", angle_deg=45.0, radius=2.0, intensity=None, focal=50.0,
               aim_x=0.0, aim_y=0.0, dome_texture=None):
    """An analytic eye at the origin (gaze +z), a camera on the axis at camera_distance mm, a backdrop card 30 mm
    behind, and one light: a sphere of `radius` mm at LIGHT_DISTANCE, angle_deg off the gaze in the xz-plane, or a
    dome (constant, or the lat-long image `dome_texture`). Sphere radiance is scaled so the iris irradiance stays
    about constant across radii. focal: the camera's focal length (mm, 24 mm film); aim_x, aim_y: the camera moved
    sideways (mm) for a close-up off the axis."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(focal)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.1, 1e6))
    cam.AddTranslateOp().Set(Gf.Vec3d(aim_x, aim_y, camera_distance))
    eye = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
    eye.AddAppliedSchema("EyeAPI")
    half = 0.6 * camera_distance + 20  # the card fills the view at any distance
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-half, -half, -30), (half, -half, -30), (half, half, -30), (-half, half, -30)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    if light == "dome":
        dome = UsdLux.DomeLight.Define(stage, "/World/dome")
        dome.CreateIntensityAttr(intensity or 1.0)
        if dome_texture:
            dome.CreateTextureFileAttr(Sdf.AssetPath(dome_texture))
    else:
        sphere = UsdLux.SphereLight.Define(stage, "/World/key")
        sphere.CreateRadiusAttr(radius)
        # Irradiance ~ radiance x solid angle: keep it near that of a 2 mm light.
        solid = 2 * math.pi * (1 - math.sqrt(max(0.0, 1 - (radius / LIGHT_DISTANCE) ** 2)))
        ref_solid = 2 * math.pi * (1 - math.sqrt(1 - (2.0 / LIGHT_DISTANCE) ** 2))
        sphere.CreateIntensityAttr(intensity or 3000.0 * ref_solid / solid)
        a = math.radians(angle_deg)
        sphere.AddTranslateOp().Set(Gf.Vec3d(LIGHT_DISTANCE * math.sin(a), 0, IRIS_Z + LIGHT_DISTANCE * math.cos(a)))
    return stage


def solid_angle(radius):
    return 2 * math.pi * (1 - math.sqrt(max(0.0, 1 - (radius / LIGHT_DISTANCE) ** 2)))


def render(stage, width, spp, settings, threads, seed=0):
    """(color image (h, w, 4), primId image, seconds of rendering). settings["chamber_events"] (if present) renders
    with the render plan, every other decision fixed by the settings' switches (PlanOverrides): the chamber walk's
    bound is a per-eye switch, only the plan sets it."""
    s = dict(settings)
    s.update(threads=threads, seed=seed)
    plan = None
    if "chamber_events" in s:
        plan = make_overrides(mnee=s.get("mnee", True), mnee_all_solutions=s.get("mnee_all_solutions", False),
                              chamber_events=s.pop("chamber_events"))
    session = RenderSession(stage, width=width, aovs=("color", "primId"), settings=s, plan_overrides=plan)
    t0 = time.perf_counter()
    session.render(spp=spp)
    return session.image("color"), session.image("primId")[:, :, 0], time.perf_counter() - t0


def errors(img, ref, eye_mask, trim=0.001):
    """(rel MSE over the eye's pixels, rel MSE over the frame, mean relative bias over the eye), RGB. The worst
    `trim` of the pixels by squared difference are dropped from the MSEs: a sub-pixel corneal highlight of a small,
    bright light makes single-sample fireflies (in a test or in the reference) that otherwise decide the number."""
    d2 = ((img[:, :, :3] - ref[:, :, :3]) ** 2).mean(axis=2)

    def trimmed(values):
        return values[values <= np.quantile(values, 1 - trim)].mean()

    eye_mean = ref[:, :, :3][eye_mask].mean()
    frame_mean = ref[:, :, :3].mean()
    eye_mse = trimmed(d2[eye_mask]) / eye_mean ** 2
    frame_mse = trimmed(d2.ravel()) / frame_mean ** 2
    bias = (img[:, :, :3][eye_mask].mean() - eye_mean) / eye_mean
    return eye_mse, frame_mse, bias


class Bench:
    def __init__(self, args):
        self.args = args
        self.rows = {}

    def reference(self, stage, width, settings):
        """The converged reference: `settings` at ref_spp samples (another seed than the tests)."""
        return render(stage, width, self.args.ref_spp, settings, self.args.threads, seed=1000)

    def compare(self, name, stage, width, variants, ref_settings, spp):
        """variants: [(label, settings)]. Returns rows (dict per variant) with time and errors vs the reference."""
        ref, prim, ref_secs = self.reference(stage, width, ref_settings)
        # /World/Eye sorts before /World/card in the render index (std::map by path): the eye is primId 0.
        eye_mask = prim == 0
        if eye_mask.sum() == 0:
            raise RuntimeError(f"{name}: the eye covers no pixel")
        rows = []
        for label, settings in variants:
            img, _, secs = render(stage, width, spp, settings, self.args.threads)
            eye_mse, frame_mse, bias = errors(img, ref, eye_mask)
            rows.append({"variant": label, "spp": spp, "seconds": secs, "eye_mse": eye_mse, "frame_mse": frame_mse,
                         "bias": bias, "eye_pixels": int(eye_mask.sum()), "ref_spp": self.args.ref_spp,
                         "ref_seconds": ref_secs})
        # The reference's own noise, from the run whose settings equal the reference's: its MSE x spp / ref_spp.
        same = [r for (label, s), r in zip(variants, rows) if s == ref_settings]
        ref_eye = same[0]["eye_mse"] * spp / self.args.ref_spp if same else 0.0
        ref_frame = same[0]["frame_mse"] * spp / self.args.ref_spp if same else 0.0
        for r in rows:
            r["eye_rmse"] = math.sqrt(max(r["eye_mse"] - ref_eye, 1e-12))
            r["frame_rmse"] = math.sqrt(max(r["frame_mse"] - ref_frame, 1e-12))
            r["eye_eff"] = 1 / (r["eye_rmse"] ** 2 * r["seconds"])
            r["frame_eff"] = 1 / (r["frame_rmse"] ** 2 * r["seconds"])
        return rows


def table(header, rows):
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" if i == 0 else "--:" for i in range(len(header))) + "|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print()
    sys.stdout.flush()


def progress(msg):
    print(f"[bench_plan] {msg}", file=sys.stderr, flush=True)


def sweep_pixels(b, out):
    """1. Eye size on screen: MNEE on vs off, a 2 mm key at 45 degrees (3.1e-4 sr)."""
    distances = [40, 160, 640] if b.args.quick else [40, 80, 160, 320, 640, 1280]
    width = b.args.width
    print("## Sweep 1: eye size on screen (MNEE on vs off)\n")
    print(f"A 2 mm sphere light at {LIGHT_DISTANCE:g} mm, 45 deg off the gaze ({solid_angle(2):.2g} sr); camera on the "
          f"axis at growing distance; {width} px wide frame with a backdrop; {b.args.spp} spp per test, reference "
          f"MNEE on at {b.args.ref_spp} spp.\n")
    rows_out = []
    for dist in distances:
        progress(f"sweep 1: camera at {dist} mm")
        stage = make_stage(camera_distance=dist, angle_deg=45)
        px = width * 50 * 15.08 / (24 * (dist - IRIS_Z))
        rows = b.compare("pixels", stage, width, [("mnee", {"mnee": True}), ("no mnee", {"mnee": False})],
                         {"mnee": True}, b.args.spp)
        on, off = rows
        rows_out.append({"eye_px": px, "eye_pixels": on["eye_pixels"], "mnee_s": on["seconds"], "pt_s": off["seconds"],
                         "mnee_eye": on["eye_rmse"], "pt_eye": off["eye_rmse"], "mnee_frame": on["frame_rmse"],
                         "pt_frame": off["frame_rmse"], "eye_ratio": on["eye_eff"] / off["eye_eff"],
                         "frame_ratio": on["frame_eff"] / off["frame_eff"], "pt_bias": off["bias"]})
    table(["eye px", "eye pixels", "MNEE s", "PT s", "MNEE eye rRMSE", "PT eye rRMSE", "MNEE frame rRMSE",
           "PT frame rRMSE", "eff ratio eye (MNEE/PT)", "eff ratio frame"],
          [[f"{r['eye_px']:.1f}", str(r["eye_pixels"]), f"{r['mnee_s']:.2f}", f"{r['pt_s']:.2f}",
            f"{r['mnee_eye']:.3f}", f"{r['pt_eye']:.3f}", f"{r['mnee_frame']:.4f}", f"{r['pt_frame']:.4f}",
            f"{r['eye_ratio']:.2f}", f"{r['frame_ratio']:.2f}"] for r in rows_out])
    out["pixels"] = rows_out


def sweep_solid_angle(b, out):
    """2. Light solid angle at 30 and 75 degrees (and a dome): MNEE on vs off."""
    radii = b.args.radii or ([2, 20, 100] if b.args.quick else [1, 4, 16, 50, 100, 150, 190])
    angles = b.args.angles or ([45] if b.args.quick else [30, 75])
    width = b.args.width
    print("## Sweep 2: light solid angle (MNEE on vs off)\n")
    print(f"Sphere lights at {LIGHT_DISTANCE:g} mm (radiance scaled to keep the iris irradiance), and a constant dome; "
          f"camera at 40 mm, {width} px; {b.args.spp} spp per test; reference MNEE on at {b.args.ref_spp} spp.\n")
    rows_out = []
    cases = [(a, r) for a in angles for r in radii] + [(None, None)]
    for angle, radius in cases:
        progress(f"sweep 2: {'dome' if angle is None else f'{radius} mm at {angle} deg'}")
        stage = make_stage(light="dome") if angle is None else make_stage(angle_deg=angle, radius=radius)
        rows = b.compare("solid", stage, width, [("mnee", {"mnee": True}), ("no mnee", {"mnee": False})],
                         {"mnee": True}, b.args.spp)
        on, off = rows
        rows_out.append({"angle": angle, "radius": radius,
                         "solid_angle": 4 * math.pi if angle is None else solid_angle(radius),
                         "mnee_s": on["seconds"], "pt_s": off["seconds"], "mnee_eye": on["eye_rmse"],
                         "pt_eye": off["eye_rmse"], "eye_ratio": on["eye_eff"] / off["eye_eff"],
                         "frame_ratio": on["frame_eff"] / off["frame_eff"], "pt_bias": off["bias"],
                         "mnee_bias": on["bias"]})
    table(["light", "solid angle (sr)", "MNEE s", "PT s", "MNEE eye rRMSE", "PT eye rRMSE", "PT eye bias",
           "eff ratio eye (MNEE/PT)", "eff ratio frame"],
          [["dome" if r["angle"] is None else f"r {r['radius']:g} mm, {r['angle']} deg", f"{r['solid_angle']:.3g}",
            f"{r['mnee_s']:.2f}", f"{r['pt_s']:.2f}", f"{r['mnee_eye']:.3f}", f"{r['pt_eye']:.3f}",
            f"{100 * r['pt_bias']:+.1f}%", f"{r['eye_ratio']:.2f}", f"{r['frame_ratio']:.2f}"] for r in rows_out])
    out["solid_angle"] = rows_out


def sweep_all_solutions(b, out):
    """3. Light direction: all-solutions MNEE on vs off."""
    angles = [30, 85] if b.args.quick else [0, 30, 60, 75, 85]
    width = b.args.width
    print("## Sweep 3: light direction (all-solutions MNEE on vs off)\n")
    print(f"A 2 mm sphere light at {LIGHT_DISTANCE:g} mm; camera at 40 mm, {width} px; {b.args.spp} spp per test; "
          f"reference all-solutions MNEE at {b.args.ref_spp} spp. Bias: mean over the eye relative to the reference "
          f"(its noise about +-{100 / math.sqrt(b.args.ref_spp):.0f}% / sqrt(eye pixels)).\n")
    rows_out = []
    for angle in angles:
        progress(f"sweep 3: {angle} deg")
        stage = make_stage(angle_deg=angle)
        ref = {"mnee": True, "mnee_all_solutions": True}
        rows = b.compare("allsol", stage, width, [("one", {"mnee": True, "mnee_all_solutions": False}), ("all", ref)],
                         ref, b.args.spp)
        one, alls = rows
        rows_out.append({"angle": angle, "one_s": one["seconds"], "all_s": alls["seconds"], "one_eye": one["eye_rmse"],
                         "all_eye": alls["eye_rmse"], "one_bias": one["bias"], "all_bias": alls["bias"],
                         "ratio": one["eye_eff"] / alls["eye_eff"]})
    table(["light (deg)", "one s", "all s", "one eye rRMSE", "all eye rRMSE", "one bias", "all bias",
           "eff ratio (one/all)"],
          [[str(r["angle"]), f"{r['one_s']:.2f}", f"{r['all_s']:.2f}", f"{r['one_eye']:.3f}", f"{r['all_eye']:.3f}",
            f"{100 * r['one_bias']:+.2f}%", f"{100 * r['all_bias']:+.2f}%", f"{r['ratio']:.2f}"] for r in rows_out])
    out["all_solutions"] = rows_out


def sweep_depth(b, out):
    """4. Path depth on a side-lit eye: time and error against maxDepth 8."""
    depths = [1, 2, 8] if b.args.quick else [1, 2, 3, 4, 8]
    width = b.args.width
    print("## Sweep 4: path depth (maxDepth) on a side-lit eye\n")
    print(f"A 2 mm sphere light at 75 deg; camera at 40 mm, {width} px; {b.args.spp} spp per test; reference "
          f"maxDepth 8 at {b.args.ref_spp} spp. The chamber walk is one event for maxDepth: what depth cuts is the "
          f"light that leaves the eye and comes back (backdrop, other eye), not the chamber's own bounces.\n")
    stage = make_stage(angle_deg=75)
    variants = [(f"depth {d}", {"mnee": True, "max_depth": d}) for d in depths]
    progress("sweep 4")
    rows = b.compare("depth", stage, width, variants, {"mnee": True, "max_depth": 8}, b.args.spp)
    rows_out = [{"depth": d, "seconds": r["seconds"], "eye_rmse": r["eye_rmse"], "frame_rmse": r["frame_rmse"],
                 "bias": r["bias"]} for d, r in zip(depths, rows)]
    table(["maxDepth", "s", "eye rRMSE", "frame rRMSE", "eye bias"],
          [[str(r["depth"]), f"{r['seconds']:.2f}", f"{r['eye_rmse']:.3f}", f"{r['frame_rmse']:.4f}",
            f"{100 * r['bias']:+.2f}%"] for r in rows_out])
    out["depth"] = rows_out


CHAMBER_EVENTS = [1, 2, 4, 8, 16, 64]


def sweep_chamber(b, out):
    """Chamber walk bound (EyeRenderOptions::maxChamberEvents, per eye through the plan): side- and front-lit."""
    events = b.args.events or CHAMBER_EVENTS
    lights = [("side 75 deg", 75), ("front 15 deg", 15)]
    width = b.args.width
    print("## Sweep chamber: the chamber walk's bound (events per path)\n")
    print(f"A 2 mm sphere key at {LIGHT_DISTANCE:g} mm, 75 deg (side) or 15 deg (front) off the gaze; analytic eye, "
          f"camera at 40 mm, {width} px; MNEE on, one path; the bound set per eye through the plan "
          f"(PlanOverrides.chamber_events). {b.args.spp} spp per test (seed 0); reference: 64 events at "
          f"{b.args.ref_spp} spp (seed 1000), its noise subtracted. 'eye bias': mean over the eye's pixels vs the "
          f"reference: the light the cut walk loses; the 64-event row's bias is the noise floor. 'ms/spp': "
          f"render seconds per sample per pixel of the whole frame.\n")
    rows_out = []
    for light_name, angle in lights:
        progress(f"sweep chamber: {light_name}")
        stage = make_stage(angle_deg=angle)
        variants = [(f"{n}", {"mnee": True, "mnee_all_solutions": False, "chamber_events": n}) for n in events]
        ref_settings = variants[-1][1] if events[-1] == 64 else {"mnee": True, "mnee_all_solutions": False,
                                                                 "chamber_events": 64}
        rows = b.compare("chamber", stage, width, variants, ref_settings, b.args.spp)
        full = 1 + rows[-1]["bias"]  # the longest walk's test (same seed): what the cut changes, paired
        for n, r in zip(events, rows):
            rows_out.append({"light": light_name, "angle": angle, "events": n, "seconds": r["seconds"],
                             "ms_per_spp": 1000 * r["seconds"] / r["spp"], "eye_rmse": r["eye_rmse"],
                             "frame_rmse": r["frame_rmse"], "bias": r["bias"], "eye_pixels": r["eye_pixels"],
                             "change": (1 + r["bias"]) / full - 1})
    table(["light", "events", "eye pixels", "s", "ms/spp", "eye rRMSE", "frame rRMSE", "eye bias",
           f"eye mean vs {events[-1]} events (same seed)"],
          [[r["light"], str(r["events"]), str(r["eye_pixels"]), f"{r['seconds']:.2f}", f"{r['ms_per_spp']:.1f}",
            f"{r['eye_rmse']:.3f}", f"{r['frame_rmse']:.4f}", f"{100 * r['bias']:+.2f}%", f"{100 * r['change']:+.2f}%"]
           for r in rows_out])
    out["chamber"] = rows_out


FOLD_AIM = (-1.5, 3.0)  # mm: where one-path MNEE misses light under 80-89 deg light (paired one/all difference, 90 px)


def sweep_all_solutions_size(b, out):
    """All-solutions MNEE on vs off by eye size (close-ups through the focal length) and grazing light angle."""
    sizes = b.args.sizes or ([48, 200, 800] if b.args.quick else [48, 100, 200, 400, 800])
    angles = b.args.angles or ([80, 89] if b.args.quick else [80, 85, 89])
    width, spp = b.args.width, b.args.spp
    cam = 40.0
    print("## Sweep allsol-size: all-solutions MNEE on vs off by eye size and grazing light angle\n")
    print(f"A 2 mm sphere key at {LIGHT_DISTANCE:g} mm, 80-89 deg off the gaze (+x); analytic eye; camera {cam:g} mm "
          f"away, the focal length setting the iris circle's size on screen; {width} px frames. An eye wider than the "
          f"frame is a close-up of the caustic fold where one path misses light, at x {FOLD_AIM[0]:g}, y "
          f"{FOLD_AIM[1]:g} mm (found from a paired one/all difference at 90 px). {spp} spp per test; reference: all "
          f"solutions at {b.args.ref_spp} spp (another seed), its noise subtracted. rRMSE over the eye's pixels, "
          f"untrimmed (second paths make a thin caustic: trimming the worst 0.1% would drop it). 'eff one/all': "
          f"equal-error time ratio at this budget (> 1: one path wins). 'missed': the one-path test against the "
          f"all-solutions test with the same seed (paired: the same paths up to the extra solutions): the eye's "
          f"mean, the worst pixel, and the share of eye pixels missing more than 5% -- a bias no budget removes.\n")
    rows_out = []
    for angle in angles:
        for px in sizes:
            aim = (0.0, 0.0) if px <= width else FOLD_AIM
            focal = px * 24.0 * (cam - IRIS_Z) / (width * 15.08)
            progress(f"sweep allsol-size: {angle} deg, {px} px")
            stage = make_stage(camera_distance=cam, angle_deg=angle, focal=focal, aim_x=aim[0], aim_y=aim[1])
            ref_set = {"mnee": True, "mnee_all_solutions": True}
            ref, prim, _ = render(stage, width, b.args.ref_spp, ref_set, b.args.threads, seed=1000)
            mask = prim == 0
            if mask.sum() == 0:
                raise RuntimeError(f"allsol-size: the eye covers no pixel at {px} px")
            row = {"angle": angle, "eye_px": px, "aim": aim, "eye_pixels": int(mask.sum())}
            imgs = {}
            for label, alls in (("one", False), ("all", True)):
                img, _, secs = render(stage, width, spp, {"mnee": True, "mnee_all_solutions": alls},
                                      b.args.threads, seed=0)
                imgs[label] = img[:, :, :3].mean(axis=2)
                mse_u, _, bias = errors(img, ref, mask, trim=0.0)
                row[label] = {"seconds": secs, "mse_u": mse_u, "bias": bias}
            noise = row["all"]["mse_u"] * spp / b.args.ref_spp
            for label in ("one", "all"):
                row[label]["rmse_u"] = math.sqrt(max(row[label]["mse_u"] - noise, 1e-12))
            row["eff_u"] = (row["all"]["rmse_u"] ** 2 * row["all"]["seconds"]) / (
                row["one"]["rmse_u"] ** 2 * row["one"]["seconds"])
            one, alls = imgs["one"][mask], imgs["all"][mask]
            missed = (alls - one) / np.maximum(alls, 1e-9)
            row["missed_mean"] = (alls.sum() - one.sum()) / alls.sum()
            row["missed_max"] = float(missed.max())
            row["missed_5pct"] = float((missed > 0.05).mean())
            rows_out.append(row)
    table(["light (deg)", "eye px", "framing", "eye pixels", "one s", "all s", "one rRMSE", "all rRMSE",
           "eff one/all", "missed: eye mean", "missed: worst pixel", "eye pixels missing > 5%"],
          [[f"{r['angle']:g}", f"{r['eye_px']:g}", "whole eye" if r["aim"] == (0.0, 0.0) else "fold close-up",
            str(r["eye_pixels"]), f"{r['one']['seconds']:.2f}", f"{r['all']['seconds']:.2f}",
            f"{r['one']['rmse_u']:.3f}", f"{r['all']['rmse_u']:.3f}", f"{r['eff_u']:.2f}",
            f"{100 * r['missed_mean']:.2f}%", f"{100 * r['missed_max']:.0f}%", f"{100 * r['missed_5pct']:.1f}%"]
           for r in rows_out])
    out["allsol_size"] = [{"angle": r["angle"], "eye_px": r["eye_px"], "closeup": r["aim"] != (0.0, 0.0),
                           "eye_pixels": r["eye_pixels"],
                           **{f"{m}_{k}": r[m][k] for m in ("one", "all") for k in ("seconds", "rmse_u", "bias")},
                           "eff_u": r["eff_u"], "missed_mean": r["missed_mean"], "missed_max": r["missed_max"],
                           "missed_5pct": r["missed_5pct"]} for r in rows_out]


# -- eye-mesh sweeps (sclera, refine): the referenced eye asset, not the analytic eye ------------------------------

EYE_ASSET = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "usd_samples", "assets", "eye.usda")
MESH_CAMERA_DISTANCE = 150.0  # mm from the corneal apex; the eye's size on screen is set by the focal length
MESH_IRIS_Z = -3.735  # mm: the iris plane below the apex (the asset's canonical frame)


def make_mesh_stage(*, pixels, width, angle_deg, limbal_arc=True, radius=2.0, aim_x=0.0, light="sphere"):
    """usd_samples/assets/eye.usda (centimetres) referenced under /World/Eye, scaled to millimetres, corneal apex at
    the origin, gaze +z; a camera on the axis at MESH_CAMERA_DISTANCE whose focal length makes the 15.08 mm iris
    circle `pixels` wide in a `width` px frame; a grey card 30 mm behind; a `radius` mm sphere key at LIGHT_DISTANCE,
    angle_deg off the gaze. limbal_arc: eye:limbalArc authored on the eyeball (the cylinder of the walk). aim_x: the
    camera moved sideways (mm, -x: away from the key) so that a close-up frames the shadowed limbus or the outline.
    light "dome": a constant dome (intensity 1) and no key."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    focal = pixels * 24.0 * (MESH_CAMERA_DISTANCE - MESH_IRIS_Z) / (width * 15.08)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(focal)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.1, 1e6))
    cam.AddTranslateOp().Set(Gf.Vec3d(aim_x, 0, MESH_CAMERA_DISTANCE))
    eye = UsdGeom.Xform.Define(stage, "/World/Eye")
    eye.GetPrim().GetReferences().AddReference(os.path.abspath(EYE_ASSET))
    eye.AddTranslateOp().Set(Gf.Vec3d(0, 0, -13.03270723))  # the asset's eyeball centre is 1.3033 cm behind the apex
    eye.AddScaleOp().Set(Gf.Vec3f(10, 10, 10))  # cm -> mm
    stage.OverridePrim("/World/Eye/Eyeball").CreateAttribute("eye:limbalArc", Sdf.ValueTypeNames.Bool).Set(limbal_arc)
    # The card fills the view at any focal length.
    half = (MESH_CAMERA_DISTANCE + 30) * 12.0 / focal * 1.2 + 20 + abs(aim_x)
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-half, -half, -30), (half, -half, -30), (half, half, -30), (-half, half, -30)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    if light == "dome":
        UsdLux.DomeLight.Define(stage, "/World/dome").CreateIntensityAttr(1.0)
        return stage
    sphere = UsdLux.SphereLight.Define(stage, "/World/key")
    sphere.CreateRadiusAttr(radius)
    sphere.CreateIntensityAttr(3000.0)
    a = math.radians(angle_deg)
    sphere.AddTranslateOp().Set(Gf.Vec3d(LIGHT_DISTANCE * math.sin(a), 0, MESH_IRIS_Z + LIGHT_DISTANCE * math.cos(a)))
    return stage


def render_session(stage, width, settings, threads, seed, refine_level=2):
    s = dict(settings)
    s.update(threads=threads, seed=seed)
    return RenderSession(stage, width=width, aovs=("color", "primId"), settings=s, refine_level=refine_level)


def equal_time_variants(variants, spp, ref, mask, ref_spp):
    """Renders each (label, make_session) in turn: the first for `spp` samples, the others for the same wall time.
    Returns {label: {seconds, spp, eye_mse, bias, eye_rmse}}, eye_rmse with the reference's own noise subtracted
    (estimated from the first variant, the same estimator: its MSE x spp / ref_spp)."""
    result, budget = {}, None
    for label, make_session in variants:
        session = make_session()
        if budget is None:
            img, _, secs, done = session_render(session, spp)
            budget = secs
        else:
            img, _, secs, done = session_render(session, 100000, time_limit=budget)
        eye_mse, _, bias = errors(img, ref, mask)
        result[label] = {"seconds": secs, "spp": done, "eye_mse": eye_mse, "bias": bias}
    ref_noise = result[variants[0][0]]["eye_mse"] * spp / ref_spp
    for v in result.values():
        v["eye_rmse"] = math.sqrt(max(v["eye_mse"] - ref_noise, 1e-12))
    return result


def session_render(session, spp, time_limit=0.0):
    t0 = time.perf_counter()
    stats = session.render(spp=spp, time_limit=time_limit)
    seconds = time.perf_counter() - t0
    return session.image("color"), session.image("primId")[:, :, 0], seconds, stats["samples_per_pixel"]


def eye_pixels_mask(session, prim_image, prefix="/World/Eye"):
    ids = [i for i, p in enumerate(session.index.rprim_ids()) if p.startswith(prefix)]
    return np.isin(np.rint(prim_image).astype(int), ids)


WALK_ARC = {"mnee": True, "sclera_scattering": True}  # + eye:limbalArc authored true
SCLERA_VARIANTS = (("walk + arc", True, True), ("walk, no arc", True, False), ("Lambert", False, True))


def sweep_sclera(b, out):
    """Sclera: random walk + limbal-arc cylinder vs walk without the cylinder vs a Lambertian sclera, by eye size,
    side-lit and front-lit, at equal time."""
    sizes = b.args.sizes or ([2, 8, 32, 128] if b.args.quick else [2, 4, 8, 16, 32, 64, 128, 200])
    lights = [("side 70 deg", 70), ("front 15 deg", 15)]
    width, spp = b.args.width, b.args.spp
    print("## Sweep sclera: random-walk sclera and limbal arc vs a Lambertian sclera, by eye size\n")
    print(f"usd_samples/assets/eye.usda (Catmull-Clark level 2) in a {width} px frame, camera 150 mm away on the gaze "
          f"axis (the iris size set by the focal length), a 2 mm key at {LIGHT_DISTANCE:g} mm. Reference: walk + arc "
          f"at {b.args.ref_spp} spp (another seed). The walk + arc test renders {spp} spp; the other two render for "
          f"the same wall time (equal-time). Errors over the eye's pixels (primId), worst 0.1% trimmed, the "
          f"reference's noise subtracted; bias = mean over the eye vs the reference. 'MSE / walk+arc' < 1: the variant "
          f"is closer to the reference than the full model at equal time (its bias hides in that render's noise).\n")
    rows_out = []
    for light_name, angle in lights:
        for px in sizes:
            progress(f"sweep sclera: {light_name}, {px} px")
            # An iris wider than 0.6 of the frame: a close-up framed on the limbus away from the key (x = -6 mm, the
            # outer limbus radius is 6.445 mm), where the walk and the arc show; else the whole eye is in frame.
            aim = -6.0 if px > 0.6 * width else 0.0
            ref_stage = make_mesh_stage(pixels=px, width=width, angle_deg=angle, limbal_arc=True, aim_x=aim)
            ref_session = render_session(ref_stage, width, WALK_ARC, b.args.threads, seed=1000)
            ref, prim, ref_secs, _ = session_render(ref_session, b.args.ref_spp)
            mask = eye_pixels_mask(ref_session, prim)
            if mask.sum() == 0:
                raise RuntimeError(f"sclera sweep: the eye covers no pixel at {px} px")
            row = {"light": light_name, "angle": angle, "eye_px": px, "eye_pixels": int(mask.sum()), "aim_x": aim}
            row.update(equal_time_variants(
                [(label, lambda walk=walk, arc=arc, px=px, angle=angle, aim=aim: render_session(
                    make_mesh_stage(pixels=px, width=width, angle_deg=angle, limbal_arc=arc, aim_x=aim), width,
                    {"mnee": True, "sclera_scattering": walk}, b.args.threads, 0))
                 for label, walk, arc in SCLERA_VARIANTS], spp, ref, mask, b.args.ref_spp))
            for label in ("walk, no arc", "Lambert"):
                row[label]["mse_ratio"] = row[label]["eye_rmse"] ** 2 / row["walk + arc"]["eye_rmse"] ** 2
            rows_out.append(row)
    table(["light", "eye px", "framing", "eye pixels", "s (each)", "spp walk+arc / no arc / Lambert",
           "rRMSE walk+arc", "rRMSE no arc", "rRMSE Lambert", "bias no arc", "bias Lambert",
           "MSE / walk+arc: no arc", "MSE / walk+arc: Lambert"],
          [[r["light"], f"{r['eye_px']:g}", "limbus close-up" if r["aim_x"] else "whole eye", str(r["eye_pixels"]),
            f"{r['walk + arc']['seconds']:.2f}",
            f"{r['walk + arc']['spp']} / {r['walk, no arc']['spp']} / {r['Lambert']['spp']}",
            f"{r['walk + arc']['eye_rmse']:.3f}", f"{r['walk, no arc']['eye_rmse']:.3f}",
            f"{r['Lambert']['eye_rmse']:.3f}",
            f"{100 * r['walk, no arc']['bias']:+.1f}%", f"{100 * r['Lambert']['bias']:+.1f}%",
            f"{r['walk, no arc']['mse_ratio']:.2f}", f"{r['Lambert']['mse_ratio']:.2f}"] for r in rows_out])
    out["sclera"] = [{"light": r["light"], "angle": r["angle"], "eye_px": r["eye_px"], "eye_pixels": r["eye_pixels"],
                      "aim_x": r["aim_x"],
                      **{f"{k.replace(' ', '').replace(',', '_').replace('+', 'plus')}_{m}": r[k][m]
                         for k, _, _ in SCLERA_VARIANTS for m in ("seconds", "spp", "eye_rmse", "bias")},
                      "noarc_mse_ratio": r["walk, no arc"]["mse_ratio"], "lambert_mse_ratio": r["Lambert"]["mse_ratio"]}
                     for r in rows_out]


def sweep_dome_arc(b, out):
    """The limbal arc under a dome alone (no key light): walk + arc vs walk without the arc, equal time."""
    sizes = b.args.sizes or ([8, 32, 128] if b.args.quick else [4, 8, 16, 32, 64, 128])
    width, spp = b.args.width, b.args.spp
    print("## Sweep dome-arc: the limbal arc on an eye lit by a dome alone\n")
    print("usd_samples/assets/eye.usda (level 2), camera 150 mm on the gaze axis, a constant dome (intensity 1) and "
          f"no key; {width} px; an iris wider than 0.6 of the frame is a close-up of the limbus at x = -6 mm. "
          f"Reference: walk + arc at {b.args.ref_spp} spp (another seed). Walk + arc renders {spp} spp, walk without "
          "the arc the same wall time. Errors over the eye's pixels, worst 0.1% trimmed, the reference's noise "
          "subtracted; 'MSE no arc / arc' < 1: dropping the arc is closer at equal time.\n")
    rows_out = []
    for px in sizes:
        progress(f"sweep dome-arc: {px} px")
        aim = -6.0 if px > 0.6 * width else 0.0
        ref_stage = make_mesh_stage(pixels=px, width=width, angle_deg=0, limbal_arc=True, aim_x=aim, light="dome")
        ref_session = render_session(ref_stage, width, WALK_ARC, b.args.threads, seed=1000)
        ref, prim, _, _ = session_render(ref_session, b.args.ref_spp)
        mask = eye_pixels_mask(ref_session, prim)
        if mask.sum() == 0:
            raise RuntimeError(f"dome-arc sweep: the eye covers no pixel at {px} px")
        row = {"eye_px": px, "aim_x": aim, "eye_pixels": int(mask.sum())}
        row.update(equal_time_variants(
            [(label, lambda arc=arc, px=px, aim=aim: render_session(
                make_mesh_stage(pixels=px, width=width, angle_deg=0, limbal_arc=arc, aim_x=aim, light="dome"),
                width, WALK_ARC, b.args.threads, 0))
             for label, arc in (("arc", True), ("no arc", False))], spp, ref, mask, b.args.ref_spp))
        row["mse_ratio"] = row["no arc"]["eye_rmse"] ** 2 / row["arc"]["eye_rmse"] ** 2
        rows_out.append(row)
    table(["eye px", "framing", "eye pixels", "s (each)", "spp arc / no arc", "rRMSE arc", "rRMSE no arc",
           "bias arc", "bias no arc", "MSE no arc / arc"],
          [[f"{r['eye_px']:g}", "limbus close-up" if r["aim_x"] else "whole eye", str(r["eye_pixels"]),
            f"{r['arc']['seconds']:.2f}", f"{r['arc']['spp']} / {r['no arc']['spp']}", f"{r['arc']['eye_rmse']:.3f}",
            f"{r['no arc']['eye_rmse']:.3f}", f"{100 * r['arc']['bias']:+.1f}%", f"{100 * r['no arc']['bias']:+.1f}%",
            f"{r['mse_ratio']:.2f}"] for r in rows_out])
    out["dome_arc"] = [{"eye_px": r["eye_px"], "aim_x": r["aim_x"], "eye_pixels": r["eye_pixels"],
                        **{f"{k.replace(' ', '')}_{m}": r[k][m] for k in ("arc", "no arc")
                           for m in ("seconds", "spp", "eye_rmse", "bias")}, "mse_ratio": r["mse_ratio"]}
                       for r in rows_out]


def add_key(stage):
    """Sweep 1's key: a 2 mm sphere light at LIGHT_DISTANCE, 45 degrees off the gaze, irradiance as make_stage's."""
    keyed = make_stage(angle_deg=45)  # held: its prims live with it
    key = keyed.GetPrimAtPath("/World/key")
    sphere = UsdLux.SphereLight.Define(stage, "/World/key")
    sphere.CreateRadiusAttr(2.0)
    sphere.CreateIntensityAttr(key.GetAttribute("inputs:intensity").Get())
    sphere.AddTranslateOp().Set(key.GetAttribute("xformOp:translate").Get())


def dome_strategies(stage, width, spp, ref_spp, threads):
    """The dome by MNEE and by BSDF sampling (the plan's dome rule moved: mnee_min_dome_contrast 0 or infinite; every
    other light as the plan decides) against a reference of the dome by MNEE at ref_spp (another seed; its noise, the
    MNEE run's MSE x spp / ref_spp, subtracted): seconds, rRMSE over the eye and its iris (where the iris AOV is most
    of the pixel), the BSDF run's bias, and each efficiency ratio MNEE / BSDF."""
    def session(dome_by_mnee, seed, aovs=("color",)):
        s = RenderSession(stage, width=width, aovs=("primId", *aovs), plan_overrides=make_overrides(),
                          settings={"threads": threads, "seed": seed})
        s.plan_rules.mnee_min_dome_contrast = 0.0 if dome_by_mnee else math.inf
        return s

    reference = session(True, 1000, ("color", "iris"))
    reference.render(spp=ref_spp)
    ref, eye = reference.image("color"), reference.image("primId")[:, :, 0] == 0
    iris = eye & (reference.image("iris")[:, :, :3].mean(axis=2) > 0.5 * ref[:, :, :3].mean(axis=2))
    row = {}
    for label, by_mnee in (("mnee", True), ("bsdf", False)):
        run = session(by_mnee, 0)
        t0 = time.perf_counter()
        run.render(spp=spp)
        row[f"{label}_s"] = time.perf_counter() - t0
        img = run.image("color")
        row[f"{label}_eye_mse"], _, row[f"{label}_bias"] = errors(img, ref, eye)
        row[f"{label}_iris_mse"], _, _ = errors(img, ref, iris)
    for part in ("eye", "iris"):
        own = row[f"mnee_{part}_mse"] * spp / ref_spp
        for label in ("mnee", "bsdf"):
            row[f"{label}_{part}"] = math.sqrt(max(row[f"{label}_{part}_mse"] - own, 1e-12))
        row[f"{part}_ratio"] = (row[f"bsdf_{part}"] ** 2 * row["bsdf_s"]) / (row[f"mnee_{part}"] ** 2 * row["mnee_s"])
    return row


def sweep_dome_contrast(b, out):
    """A textured dome, alone and beside a key: MNEE (every sample) vs BSDF sampling, by the dome's radiance contrast
    about the gaze."""
    import tempfile

    import scene_c  # bench/scene_c.py: scene C's dome image

    gains = [1, 4, 20] if b.args.quick else [1, 2, 4, 6, 8, 12, 20]
    # Twice the other sweeps' width and four times their samples: MNEE's chamber-light cache is built once per
    # frame, a fixed cost the shorter renders would charge to MNEE.
    width, spp, threads = 2 * b.args.width, 4 * b.args.spp, b.args.threads
    print("## Sweep dome-contrast: a textured dome, MNEE vs BSDF sampling\n")
    print(f"Scene C's dome (bench/scene_c.py: sky, floor, a soft window 45 deg up) with the window `gain` x the sky, "
          f"alone and beside sweep 1's key (MNEE either way); the analytic eye, camera at 40 mm, {width} px; {spp} spp "
          f"per test; reference MNEE at {b.args.ref_spp} spp (another seed, its noise subtracted). Contrast: the "
          "plan's radianceContrast (E[L^2] / E[L]^2 about the gaze). Errors over the eye's pixels and over its iris "
          "(where the iris AOV is most of the pixel: what the strategy changes; the eye's white is the same for "
          "both). 'eff ratio' > 1: MNEE reaches an error in less time.\n")
    rows_out = []
    with tempfile.TemporaryDirectory() as tmp:
        for gain in gains:
            progress(f"sweep dome-contrast: window {gain} x the sky")
            texture = os.path.join(tmp, f"dome_{gain}.exr")
            scene_c.write_exr(texture, scene_c.dome_image(*scene_c.DOME_SIZE, gain=gain))
            stage = make_stage(light="dome", dome_texture=texture)
            planned = RenderSession(stage, width=width, plan_overrides=make_overrides()).plan()
            contrast = planned.eyes[0].lights[0].radiance_contrast
            row = {"gain": gain, "contrast": contrast, **dome_strategies(stage, width, spp, b.args.ref_spp, threads)}
            # The same dome beside sweep 1's 2 mm key at 45 degrees, which MNEE takes either way.
            keyed = make_stage(light="dome", dome_texture=texture)
            add_key(keyed)
            row.update({f"key_{k}": v for k, v in dome_strategies(keyed, width, spp, b.args.ref_spp, threads).items()})
            rows_out.append(row)
    for title, k in (("the dome alone", ""), ("the dome beside an MNEE key", "key_")):
        print(f"{title}:\n")
        table(["window gain", "radiance contrast", "MNEE s", "BSDF s", "rRMSE eye MNEE / BSDF",
               "rRMSE iris MNEE / BSDF", "BSDF bias", "eff ratio eye (MNEE/BSDF)", "eff ratio iris"],
              [[f"{r['gain']:g}", f"{r['contrast']:.2f}", f"{r[k + 'mnee_s']:.2f}", f"{r[k + 'bsdf_s']:.2f}",
                f"{r[k + 'mnee_eye']:.3f} / {r[k + 'bsdf_eye']:.3f}",
                f"{r[k + 'mnee_iris']:.3f} / {r[k + 'bsdf_iris']:.3f}", f"{100 * r[k + 'bsdf_bias']:+.1f}%",
                f"{r[k + 'eye_ratio']:.2f}", f"{r[k + 'iris_ratio']:.2f}"] for r in rows_out])
    out["dome_contrast"] = rows_out


def sweep_refine(b, out):
    """Subdivision level of the eye mesh by eye size: image error against level 3 (the --complexity ceiling), the
    eye silhouette's pixel error, and the sync (refinement) cost."""
    sizes = b.args.sizes or ([16, 64, 200] if b.args.quick else [8, 16, 32, 64, 128, 200])
    levels = [0, 1, 2, 3]
    width, spp = b.args.width, b.args.spp
    print("## Sweep refine: eye-mesh subdivision level by eye size\n")
    print(f"The same stage (side key at 70 deg), Lambertian sclera (the walk's noise would hide geometry), {width} px, "
          f"{spp} spp per level; reference: level 3 at {b.args.ref_spp} spp (another seed). 'silhouette px': pixels "
          f"covered by the eye at one level and not at level 3, summed (primId coverage, every level rendered "
          f"with the same seed: the same camera rays, so no noise), a measure of the outline; 'rRMSE': eye pixels vs "
          f"the reference, noise subtracted (the level-3 test's MSE x spp/ref_spp); 'sync s': building the session "
          f"(populate + first sync, the refinement) at that level.\n")
    rows_out = []
    settings = {"mnee": True, "sclera_scattering": False}
    for px in sizes:
        progress(f"sweep refine: {px} px")
        # The eyeball is ~1.6x the iris circle: once it overfills the frame, aim at its outline away from the key.
        stage = make_mesh_stage(pixels=px, width=width, angle_deg=70, aim_x=-11.0 if 1.6 * px > width else 0.0)
        ref_session = render_session(stage, width, settings, b.args.threads, 1000, refine_level=3)
        ref, ref_prim, _, _ = session_render(ref_session, b.args.ref_spp)
        ref_mask = eye_pixels_mask(ref_session, ref_prim)
        rows, coverage = [], {}
        for level in levels:
            t0 = time.perf_counter()
            session = render_session(stage, width, settings, b.args.threads, 0, refine_level=level)
            session.index.sync_all()
            sync_s = time.perf_counter() - t0
            img, prim, secs, _ = session_render(session, spp)
            ids = session.index.rprim_ids()
            if ids != ["/World/Eye/Eyeball", "/World/card"]:
                raise RuntimeError(f"refine sweep: unexpected rprims {ids}")
            # primId resolves to the mean id over a pixel's samples: eye 0, card 1 (the card fills the view), so
            # 1 - mean is the eye's coverage of the pixel. Every level renders with seed 0: the same camera rays.
            coverage[level] = 1.0 - prim
            eye_mse, _, bias = errors(img, ref, ref_mask)
            tri = session.index.mesh_stats("/World/Eye/Eyeball")["triangles"]
            rows.append({"eye_px": px, "level": level, "triangles": tri, "sync_s": sync_s, "render_s": secs,
                         "eye_pixels": int(ref_mask.sum()), "eye_mse": eye_mse, "bias": bias})
        for r in rows:
            # Outline error in pixels: the summed coverage difference against level 3 for the same rays.
            r["silhouette_px"] = float(np.abs(coverage[r["level"]] - coverage[levels[-1]]).sum())
        ref_noise = rows[-1]["eye_mse"] * spp / b.args.ref_spp
        for r in rows:
            r["eye_rmse"] = math.sqrt(max(r["eye_mse"] - ref_noise, 1e-12))
        rows_out += rows
    table(["eye px", "level", "triangles", "sync s", "render s", "eye pixels", "silhouette px", "eye rRMSE",
           "eye bias"],
          [[f"{r['eye_px']:g}", str(r["level"]), str(r["triangles"]), f"{r['sync_s']:.2f}", f"{r['render_s']:.2f}",
            str(r["eye_pixels"]), f"{r['silhouette_px']:.2f}", f"{r['eye_rmse']:.3f}", f"{100 * r['bias']:+.2f}%"]
           for r in rows_out])
    out["refine"] = rows_out


def plot(out, out_dir):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        progress("matplotlib not available: no plots")
        return []
    written = []
    if "pixels" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["pixels"]
        ax.loglog([r["eye_px"] for r in rows], [r["eye_ratio"] for r in rows], "o-", label="eye pixels")
        ax.loglog([r["eye_px"] for r in rows], [r["frame_ratio"] for r in rows], "s--", label="frame")
        ax.axhline(1, color="grey", lw=0.8)
        ax.set_xlabel("eye diameter on screen (px)")
        ax.set_ylabel("efficiency MNEE / path tracing")
        ax.set_title("Sweep 1: eye size (2 mm key, 45 deg)")
        ax.legend()
        written.append(_save(fig, out_dir, "render_plan_pixels.png"))
    if "solid_angle" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["solid_angle"]
        for angle in sorted({r["angle"] for r in rows if r["angle"] is not None}):
            sel = [r for r in rows if r["angle"] == angle]
            ax.loglog([r["solid_angle"] for r in sel], [r["eye_ratio"] for r in sel], "o-",
                      label=f"sphere, {angle} deg")
        dome = [r for r in rows if r["angle"] is None]
        if dome:
            ax.loglog([dome[0]["solid_angle"]], [dome[0]["eye_ratio"]], "k*", ms=10, label="dome")
        ax.axhline(1, color="grey", lw=0.8)
        ax.set_xlabel("light solid angle seen from the eye (sr)")
        ax.set_ylabel("efficiency MNEE / path tracing (eye)")
        ax.set_title("Sweep 2: light size")
        ax.legend()
        written.append(_save(fig, out_dir, "render_plan_solid_angle.png"))
    if "all_solutions" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["all_solutions"]
        ax.plot([r["angle"] for r in rows], [100 * r["one_bias"] for r in rows], "o-", label="one path: bias (%)")
        ax.plot([r["angle"] for r in rows], [r["ratio"] for r in rows], "s--", label="efficiency one / all")
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_xlabel("light angle off the gaze (deg)")
        ax.set_title("Sweep 3: all-solutions MNEE")
        ax.legend()
        written.append(_save(fig, out_dir, "render_plan_all_solutions.png"))
    if "chamber" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["chamber"]
        ax2 = ax.twinx()
        for i, light in enumerate(dict.fromkeys(r["light"] for r in rows)):
            sel = [r for r in rows if r["light"] == light]
            ax.semilogx([r["events"] for r in sel], [100 * r["change"] for r in sel], "o-", color=f"C{i}",
                        label=f"{light}: eye mean vs longest walk (%)")
            ax2.semilogx([r["events"] for r in sel], [r["ms_per_spp"] for r in sel], "s:", color=f"C{i}", alpha=0.6)
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_xlabel("chamber events per path (bound)")
        ax.set_ylabel("eye light vs 64 events (%)")
        ax2.set_ylabel("ms per spp (dotted)")
        ax.set_title("Sweep chamber: the walk's bound")
        ax.legend(fontsize=7, loc="lower right")
        written.append(_save(fig, out_dir, "render_plan_chamber.png"))
    if "allsol_size" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["allsol_size"]
        for i, angle in enumerate(sorted({r["angle"] for r in rows})):
            sel = [r for r in rows if r["angle"] == angle]
            ax.loglog([r["eye_px"] for r in sel], [r["eff_u"] for r in sel], "o-", color=f"C{i}",
                      label=f"{angle:g} deg: efficiency one / all")
            ax.loglog([r["eye_px"] for r in sel], [max(100 * r["missed_5pct"], 1e-2) for r in sel], "s--",
                      color=f"C{i}", label=f"{angle:g} deg: % eye pixels missing > 5%")
        ax.axhline(1, color="grey", lw=0.8)
        ax.set_xlabel("iris circle on screen (px)")
        ax.set_title("Sweep allsol-size: one path vs all solutions")
        ax.legend(fontsize=7)
        written.append(_save(fig, out_dir, "render_plan_allsol_size.png"))
    if "dome_arc" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["dome_arc"]
        ax.semilogx([r["eye_px"] for r in rows], [r["mse_ratio"] for r in rows], "o-", label="MSE no arc / arc")
        ax.semilogx([r["eye_px"] for r in rows], [100 * r["noarc_bias"] for r in rows], "s--", label="no-arc bias (%)")
        ax.axhline(1, color="grey", lw=0.8)
        ax.set_xlabel("iris circle on screen (px)")
        ax.set_title("Sweep dome-arc: limbal arc, dome only")
        ax.legend(fontsize=7)
        written.append(_save(fig, out_dir, "render_plan_dome_arc.png"))
    if "depth" in out:
        fig, ax = plt.subplots(figsize=(5, 3.5))
        rows = out["depth"]
        ax.plot([r["depth"] for r in rows], [100 * r["bias"] for r in rows], "o-", label="eye bias (%)")
        ax2 = ax.twinx()
        ax2.plot([r["depth"] for r in rows], [r["seconds"] for r in rows], "s--", color="C1", label="seconds")
        ax.set_xlabel("maxDepth")
        ax.set_ylabel("eye bias vs depth 8 (%)")
        ax2.set_ylabel("render seconds")
        ax.set_title("Sweep 4: path depth, side-lit eye")
        written.append(_save(fig, out_dir, "render_plan_depth.png"))
    return written


def _save(fig, out_dir, name):
    path = os.path.join(out_dir, name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def write_csv(prefix, out):
    for name, rows in out.items():
        if not rows:
            continue
        with open(f"{prefix}_{name}.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="fewer points and samples: a smoke run (about a minute)")
    p.add_argument("--sweeps", default="1,2,3,4",
                   help="which sweeps to run (comma-separated: 1-4, sclera, refine, chamber, allsol-size, dome-arc, "
                   "dome-contrast)")
    p.add_argument("--sweep", help="one sweep by name (sclera, refine, chamber, allsol-size, dome-arc, "
                   "dome-contrast) or number; overrides --sweeps")
    p.add_argument("--width", type=int, default=None, help="frame width in pixels (default 64; quick 48)")
    p.add_argument("--spp", type=int, default=None, help="samples per pixel of each test render (default 32)")
    p.add_argument("--ref-spp", type=int, default=None, help="reference samples per pixel (default 512)")
    p.add_argument("--sizes", type=lambda v: [float(x) for x in v.split(",")],
                   help="sweeps sclera and refine: the iris sizes on screen (px, comma-separated)")
    p.add_argument("--angles", type=lambda v: [float(x) for x in v.split(",")],
                   help="sweeps 2 and allsol-size: light angles off the gaze (deg, comma-separated)")
    p.add_argument("--radii", type=lambda v: [float(x) for x in v.split(",")],
                   help="sweep 2: sphere light radii (mm at 200 mm, comma-separated)")
    p.add_argument("--events", type=lambda v: [int(x) for x in v.split(",")],
                   help="sweep chamber: the walk bounds (events per path, comma-separated; the last one 64)")
    p.add_argument("--threads", type=int, default=1, help="render threads (default 1: comparable times)")
    p.add_argument("--out-dir", default=os.path.join(os.path.dirname(__file__), "..", "docs"),
                   help="where the plots go (default docs/)")
    p.add_argument("--csv", metavar="PREFIX", help="also write PREFIX_<sweep>.csv")
    args = p.parse_args(argv)
    args.width = args.width or (48 if args.quick else 64)
    args.spp = args.spp or (8 if args.quick else 32)
    args.ref_spp = args.ref_spp or (128 if args.quick else 512)
    b = Bench(args)
    out = {}
    start = time.perf_counter()
    sweeps = {"1": sweep_pixels, "2": sweep_solid_angle, "3": sweep_all_solutions, "4": sweep_depth,
              "sclera": sweep_sclera, "refine": sweep_refine, "chamber": sweep_chamber,
              "allsol-size": sweep_all_solutions_size, "dome-arc": sweep_dome_arc,
              "dome-contrast": sweep_dome_contrast}
    if args.sweep:
        args.sweeps = args.sweep
    print(f"# bench_plan ({'quick' if args.quick else 'full'}): {args.width} px frames, {args.spp} spp tests, "
          f"{args.ref_spp} spp references, {args.threads} thread(s)\n")
    for key in args.sweeps.split(","):
        sweeps[key.strip()](b, out)
    for path in plot(out, args.out_dir):
        print(f"plot: {os.path.relpath(path)}")
    if args.csv:
        write_csv(args.csv, out)
    print(f"\ntotal {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
