"""Numerical limits of lights and eyes: a sphere light shrinking at constant power reaches the point-light limit
smoothly; zero-size, zero-scale, far and overflowing lights give no NaN/Inf samples (with and without an eye); an
analytic eye renders the same at every scene scale from 1e-8 to 1e4 units per millimetre, and a mesh eye the same
whether the scene is in decimetres, centimetres or kilometres.

Every stage is built here, in memory: millimetres scaled by `unit` (scene units per mm), an analytic eye (EyeAPI on
an Xform, gaze +z) or the sample eye asset, a grey card behind, a camera on the gaze axis and one key light 50
degrees off the gaze."""
import math
import pathlib

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

import eyerender  # noqa: F401  (registers the EyeAPI schema)
from eyerender.render_session import RenderSession

ASSET = pathlib.Path(__file__).resolve().parents[2] / "usd_samples" / "assets" / "eye.usda"
KEY_DEGREES = 50.0


def eye_stage(unit=1.0, kind="sphere", radius=1.0, intensity=1000.0, scale=1.0, exposure=0.0, distance=100.0,
              width=2.0, height=2.0, eye=True, card=True):
    """An analytic eye in a stage of `unit` scene units per millimetre (metersPerUnit = 1e-3 / unit)."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 1e-3 / unit)
    if eye:
        prim = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
        prim.AddAppliedSchema("EyeAPI")
        model = Gf.Matrix4d(unit, 0, 0, 0, 0, unit, 0, 0, 0, 0, unit, 0, 0, 0, 0, 1)  # canonical mm to the units
        prim.CreateAttribute("eye:modelTransform", Sdf.ValueTypeNames.Matrix4d).Set(model)
    if card:
        mesh = UsdGeom.Mesh.Define(stage, "/World/card")
        h = 30 * unit
        mesh.CreatePointsAttr([(-h, -h, -20 * unit), (h, -h, -20 * unit), (h, h, -20 * unit), (-h, h, -20 * unit)])
        mesh.CreateFaceVertexCountsAttr([4])
        mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
        mesh.CreateSubdivisionSchemeAttr("none")
    add_key(stage, unit, kind, radius, intensity, scale, exposure, distance, width, height)
    add_camera(stage, unit, focal=50.0, distance=60.0)
    return stage


def add_camera(stage, unit, focal, distance):
    """A camera on the gaze axis `distance` mm from the apex (24 mm film, focal length in mm)."""
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(focal)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.CreateClippingRangeAttr(Gf.Vec2f(1 * unit, 1e6 * unit))
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, distance * unit))


def add_key(stage, unit, kind="sphere", radius=1.0, intensity=1000.0, scale=1.0, exposure=0.0, distance=100.0,
            width=2.0, height=2.0):
    a = math.radians(KEY_DEGREES)
    if kind == "sphere":
        light = UsdLux.SphereLight.Define(stage, "/World/key")
        light.CreateRadiusAttr(radius * unit)
    elif kind == "disk":
        light = UsdLux.DiskLight.Define(stage, "/World/key")
        light.CreateRadiusAttr(radius * unit)
    else:
        light = UsdLux.RectLight.Define(stage, "/World/key")
        light.CreateWidthAttr(width * unit)
        light.CreateHeightAttr(height * unit)
    light.CreateIntensityAttr(intensity)
    light.CreateExposureAttr(exposure)
    light.AddTranslateOp().Set(Gf.Vec3d(distance * unit * math.sin(a), 0, distance * unit * math.cos(a)))
    if kind != "sphere":
        light.AddRotateYOp().Set(KEY_DEGREES)  # facing the eye (rect and disk emit along their -z)
    if scale != 1.0:
        light.AddScaleOp().Set(Gf.Vec3f(scale))


def render(stage, size=32, spp=8):
    session = RenderSession(stage, width=size, height=size, aovs=("irisMnee",), camera="/World/main_cam")
    stats = session.render(spp=spp)
    return stats, session.image("color").astype(np.float64), session.image("irisMnee").astype(np.float64)


def test_a_shrinking_sphere_light_of_constant_power_approaches_the_point_light_limit():
    # Constant power: radiance x radius^2 fixed. Every radius renders the same iris light (same seed, so the
    # comparison is nearly noise-free), down to radii whose cone 1 - cos(theta) is below double's epsilon.
    means = {}
    for radius in (1e-2, 1e-3, 3e-5, 1e-5, 1e-6, 1e-8, 1e-12):
        stats, _, iris = render(eye_stage(radius=radius, intensity=0.1 / radius ** 2))
        assert stats["non_finite_samples"] == 0, radius
        means[radius] = iris.mean()
    reference = means[1e-2]
    assert reference > 0
    for radius, mean in means.items():
        assert abs(mean / reference - 1) < 0.03, f"radius {radius:g}: iris light {mean:.5g} against {reference:.5g}"


@pytest.mark.parametrize("eye", [True, False], ids=["with an eye", "no eye"])
@pytest.mark.parametrize("light", [
    {"kind": "sphere", "radius": 0.0}, {"kind": "sphere", "scale": 0.0}, {"kind": "sphere", "scale": 1e-20},
    {"kind": "sphere", "distance": 1e30}, {"kind": "sphere", "exposure": 1e4}, {"kind": "rect", "width": 0.0},
    {"kind": "rect", "height": 0.0}, {"kind": "rect", "scale": 1e-20}, {"kind": "rect", "distance": 1e30},
    {"kind": "disk", "radius": 0.0}, {"kind": "disk", "scale": 0.0}, {"kind": "disk", "distance": 1e30},
], ids=lambda d: ",".join(f"{k}={v:g}" if not isinstance(v, str) else v for k, v in d.items()))
def test_degenerate_lights_give_no_non_finite_samples(light, eye):
    stats, color, iris = render(eye_stage(eye=eye, **light), size=16, spp=4)
    assert stats["non_finite_samples"] == 0
    assert np.isfinite(color).all() and np.isfinite(iris).all()


def test_the_analytic_eye_renders_the_same_at_every_scene_scale():
    # The eye alone (no card: other surfaces keep an absolute offset, 1e-5 scene units, that no eye decides).
    means = {}
    for unit in (1e-8, 1e-4, 1.0, 1e2, 1e4):
        stats, color, iris = render(eye_stage(unit=unit, card=False), size=32, spp=8)
        assert stats["non_finite_samples"] == 0, unit
        means[unit] = (iris.mean(), color.mean())
    iris_ref, color_ref = means[1.0]
    assert iris_ref > 0
    for unit, (iris_mean, color_mean) in means.items():
        assert abs(iris_mean / iris_ref - 1) < 0.02, f"{unit:g} units/mm: iris light {iris_mean:.5g} vs {iris_ref:.5g}"
        assert abs(color_mean / color_ref - 1) < 0.02, (
            f"{unit:g} units/mm: image mean {color_mean:.5g} vs {color_ref:.5g}")


def mesh_eye_stage(unit):
    """The sample eye asset (centimetres) in a stage of `unit` scene units per millimetre, side-lit."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 1e-3 / unit)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.Xform.Define(stage, "/World")
    eye = UsdGeom.Xform.Define(stage, "/World/Eye")
    eye.GetPrim().GetReferences().AddReference(str(ASSET))
    eye.AddScaleOp().Set(Gf.Vec3f(10 * unit))  # the asset's centimetres to this stage's units
    eye.AddTranslateOp().Set(Gf.Vec3d(0, 0, -1.303270723))  # its apex to the origin (in asset units)
    add_key(stage, unit, radius=3.0, intensity=300.0, distance=150.0)
    add_camera(stage, unit, focal=100.0, distance=70.0)
    return stage


def test_a_mesh_eye_renders_the_same_in_decimetre_centimetre_and_kilometre_scenes():
    images = {unit: render(mesh_eye_stage(unit), size=48, spp=8) for unit in (0.01, 0.1, 1e-6)}
    _, reference, _ = images[0.1]  # centimetres, the asset's own units
    glint = reference.max()
    assert glint > 10 * np.median(reference)  # the corneal highlight is in the image
    for unit, (stats, color, _) in images.items():
        assert stats["non_finite_samples"] == 0
        differ = np.mean(np.abs(color - reference) > 0.05 * (reference + 0.01 * reference.mean()))
        assert differ < 0.02, f"{unit:g} units/mm: {100 * differ:.1f} % of pixel channels differ by over 5 %"
        assert abs(color.max() / glint - 1) < 0.05, f"{unit:g} units/mm: highlight {color.max():.4g} vs {glint:.4g}"
