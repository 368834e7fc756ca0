"""Figure 4's scene, renders and measurements, shared by scripts/figures/fig4_iris_depth.py and the regression test
tests/python/test_paper_figures.py.

Scene (millimetres: metersPerUnit 0.001, identity eye:modelTransform, so the stage frame is the canonical eye frame):
the analytic anterior segment (an Xform with EyeAPI) with a flat grey iris (no texture, so the caustic is the only
structure), one small SphereLight (radius 2 mm, 200 mm away: 1.15 degrees wide) in the xz-plane `angle` degrees off
the gaze towards +x, no other light, and an orthographic camera on the gaze axis looking down -z at a 16 mm field.
The orthographic front view makes the pixel -> iris-plane mapping a single refraction that `project_to_iris`
computes in Python from the paper's formulas (eye_profile.py), independently of the renderer.
"""
import math
import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import eye_profile as ep  # noqa: E402

FIELD_MM = 16.0  # orthographic field of view (square), covers the 15.08 mm rim
LIGHT_DISTANCE_MM, LIGHT_RADIUS_MM = 200.0, 2.0
# Radiance; gives iris irradiance of order 1 (pi * (2/200)^2 * 3000 ~ 0.94 at normal incidence).
LIGHT_INTENSITY = 3000.0
IRIS_ALBEDO = 0.5  # grey


def limbus_depth(chord_mm):
    """Depth below the apex (mm) of the ellipsoid-cone surface at a chord: where an iris plane aligned with it sits."""
    return float(-ep.ellipsoid_cone_sag(chord_mm / 2))


# The paper's figure 4: (a) iris at the beginning of the limbus (11.64 mm chord), (b) at its end (12.89 mm chord),
# (c) at the anatomical 3.735 mm, all with the ellipsoid-cone cornea; (d) the paraboloid at 3.735 mm.
VARIANTS = {
    "a": ("ellipsoidCone", limbus_depth(ep.LIMBUS_INNER_CHORD),
          "ellipsoid-cone, iris at the limbus start (11.64 mm chord)"),
    "b": ("ellipsoidCone", limbus_depth(ep.LIMBUS_OUTER_CHORD),
          "ellipsoid-cone, iris at the limbus end (12.89 mm chord)"),
    "c": ("ellipsoidCone", ep.ANATOMICAL_IRIS_DEPTH, "ellipsoid-cone, anatomical iris depth 3.735 mm"),
    "d": ("paraboloid", ep.ANATOMICAL_IRIS_DEPTH, "paraboloid 14.5 z + r^2 = 0, iris depth 3.735 mm"),
}


def build_stage(model, iris_depth, angle_deg):
    """An in-memory millimetre stage: eye, key light `angle_deg` off the gaze towards +x, orthographic camera."""
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    eye = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
    eye.AddAppliedSchema("EyeAPI")
    eye.CreateAttribute("eye:corneaModel", Sdf.ValueTypeNames.Token).Set(model)
    eye.CreateAttribute("eye:irisDepth", Sdf.ValueTypeNames.Float).Set(float(iris_depth))
    eye.CreateAttribute("eye:irisColor", Sdf.ValueTypeNames.Color3f).Set(
        Gf.Vec3f(IRIS_ALBEDO, IRIS_ALBEDO, IRIS_ALBEDO))
    light = UsdLux.SphereLight.Define(stage, "/World/Key")
    a = math.radians(angle_deg)
    UsdGeom.Xformable(light).AddTranslateOp().Set(
        Gf.Vec3d(LIGHT_DISTANCE_MM * math.sin(a), 0.0, LIGHT_DISTANCE_MM * math.cos(a)))
    light.CreateRadiusAttr(LIGHT_RADIUS_MM)
    light.CreateIntensityAttr(LIGHT_INTENSITY)
    camera = UsdGeom.Camera.Define(stage, "/World/Camera")
    camera.CreateProjectionAttr(UsdGeom.Tokens.orthographic)
    # UsdGeomCamera apertures are in tenths of a scene unit: 160 -> a 16 mm film.
    camera.CreateHorizontalApertureAttr(FIELD_MM * 10)
    camera.CreateVerticalApertureAttr(FIELD_MM * 10)
    camera.CreateClippingRangeAttr(Gf.Vec2f(1.0, 1000.0))
    UsdGeom.Xformable(camera).AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 100.0))
    return stage


def render(model, iris_depth, angle_deg, width, spp, seed, threads=2):
    """Renders one variant; returns (color RGB, irisMnee RGB, seconds), float32 (width, width, 3)."""
    import eyerender

    stage = build_stage(model, iris_depth, angle_deg)
    session = eyerender.RenderSession(stage, width=width, height=width, aovs=("irisMnee",),
                                      settings={"seed": seed, "threads": threads})
    start = time.perf_counter()
    stats = session.render(spp=spp)
    seconds = time.perf_counter() - start
    if stats["non_finite_samples"]:
        raise RuntimeError(f"{model} depth {iris_depth}: {stats['non_finite_samples']} non-finite samples")
    return session.image("color")[:, :, :3].copy(), session.image("irisMnee").copy(), seconds


def luminance(rgb):
    return rgb.mean(axis=2)  # the iris and light are grey; a plain mean keeps it simple and unit-free


def pixel_grid(width):
    """Canonical-frame (x, y) in mm of each pixel centre of the orthographic view; row 0 is the top (+y)."""
    c = ((np.arange(width) + 0.5) / width - 0.5) * FIELD_MM
    return np.meshgrid(c, -c)


def project_to_iris(model, iris_depth, width):
    """For each pixel: the cornea radius r_s where the view ray (0, 0, -1) enters, and the point (x_i, y_i) where the
    refracted ray meets the iris plane z = -iris_depth (mm). Snell's law at the outward normal of z = f(r)."""
    x, y = pixel_grid(width)
    rs = np.hypot(x, y)
    f, fp = ep.SAG[model](np.minimum(rs, ep.RIM_R)), ep.SLOPE[model](np.minimum(rs, ep.RIM_R))
    with np.errstate(invalid="ignore", divide="ignore"):
        ux, uy = np.where(rs > 0, x / rs, 0.0), np.where(rs > 0, y / rs, 0.0)
    n = np.stack([-fp * ux, -fp * uy, np.ones_like(fp)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    eta = 1.0 / ep.CORNEA_IOR
    cos_i = n[..., 2]  # -d . n with d = (0, 0, -1)
    k = 1 - eta * eta * (1 - cos_i * cos_i)  # > 0 always: entering the denser medium
    t = eta * np.array([0.0, 0.0, -1.0]) + (eta * cos_i - np.sqrt(k))[..., None] * n
    s = (f + iris_depth) / -t[..., 2]  # distance to the plane along t
    return rs, x + s * t[..., 0], y + s * t[..., 1]


def iris_mask(model, iris_depth, width):
    """Pixels that see the iris through clear cornea: entry radius inside the limbus' inner edge (5.82 mm, where the
    sclera blend starts) and landing between the pupil (2 mm) and the iris edge, each with a margin of one
    pixel's footprint so no pixel straddles an edge."""
    rs, xi, yi = project_to_iris(model, iris_depth, width)
    ri = np.hypot(xi, yi)
    px = FIELD_MM / width
    iris_r = ep.inverse_sag(model, iris_depth)
    return (rs < ep.LIMBUS_INNER_CHORD / 2 - px) & (ri > ep.PUPIL_DIAMETER / 2 + px) & (ri < iris_r - px)


def relative_rmse(x, ref, mask):
    """sqrt(mean (x - ref)^2) / mean(ref) over the mask (luminance)."""
    d = (x - ref)[mask]
    return float(np.sqrt(np.mean(d * d)) / max(float(np.mean(ref[mask])), 1e-12))


def box3(img, mask):
    """3x3 box filter of img restricted to the mask (normalized by the masked weights), to tame noise before
    thresholding."""
    w = mask.astype(float)
    num, den = np.zeros_like(img, dtype=float), np.zeros_like(img, dtype=float)
    p, q = np.pad(img * w, 1), np.pad(w, 1)
    h, wd = img.shape
    for dy in range(3):
        for dx in range(3):
            num += p[dy:dy + h, dx:dx + wd]
            den += q[dy:dy + h, dx:dx + wd]
    return np.where(den > 0, num / np.maximum(den, 1e-12), 0.0)


def crescent(lum, model, iris_depth, mask, percentile=90.0, profile_angle_deg=180.0):
    """Where the bright caustic sits, in iris-plane coordinates (mm; angle 0 = towards the light, +x):
    the pixels above `percentile` of the (3x3-smoothed) iris radiance. Returns the radiance-weighted circular mean
    angle of those pixels, the 10-90% range of their radius and of their angle around the mean; and, from the radial
    profile within 20 degrees of `profile_angle_deg` (default: away from the light, where the paper's crescent is;
    0.1 mm bins), the peak radius and the outer edge (where the profile falls to half way between its peak and its
    minimum further out, interpolated)."""
    width = lum.shape[0]
    _, xi, yi = project_to_iris(model, iris_depth, width)
    ri, phi = np.hypot(xi, yi), np.arctan2(yi, xi)
    smooth = box3(lum, mask)
    threshold = np.percentile(smooth[mask], percentile)
    bright = mask & (smooth >= threshold)
    w = smooth[bright]
    mean_angle = math.atan2(np.sum(w * np.sin(phi[bright])), np.sum(w * np.cos(phi[bright])))
    rel = np.degrees(np.angle(np.exp(1j * (phi[bright] - mean_angle))))
    direction = math.radians(profile_angle_deg)
    sector = mask & (np.abs(np.angle(np.exp(1j * (phi - direction)))) < math.radians(20))
    bins = np.arange(ep.PUPIL_DIAMETER / 2, ep.RIM_R + 0.1, 0.1)
    idx = np.digitize(ri[sector], bins)
    profile = np.array([smooth[sector][idx == k].mean() if np.any(idx == k) else np.nan for k in range(1, len(bins))])
    centres = 0.5 * (bins[1:] + bins[:-1])
    i_peak = int(np.nanargmax(profile))
    outer = profile[i_peak:]
    half = 0.5 * (profile[i_peak] + np.nanmin(outer))
    below = np.nonzero(outer <= half)[0]
    edge = float("nan")
    if below.size:
        j = i_peak + int(below[0])  # first bin at or below half; interpolate with the bin before
        p0, p1 = profile[j - 1], profile[j]
        edge = float(centres[j - 1] + (p0 - half) / (p0 - p1) * (centres[j] - centres[j - 1])) if p0 != p1 \
            else float(centres[j])
    return {
        "angle_deg": math.degrees(mean_angle) % 360.0,
        "r10_mm": float(np.percentile(ri[bright], 10)), "r90_mm": float(np.percentile(ri[bright], 90)),
        "width_deg": float(np.percentile(rel, 90) - np.percentile(rel, 10)),
        "peak_r_mm": float(centres[i_peak]), "edge_r_mm": edge, "pixels": int(bright.sum()),
        "threshold": float(threshold), "profile_r": centres, "profile": profile,
    }
