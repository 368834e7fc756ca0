"""The limbal arc through eyerender: the EyeAPI's eye:limbalArc and eye:scleraMeanFreePath reach the
delegate, the limbalArc AOV holds the light of teleported sclera walks, and bad values are one-line errors naming the
attribute and the prim. The stage is built in memory around the sample eye asset (usd_samples/assets/eye.usda),
lit as usd_samples/side_lit.usda is: a small key light 75 degrees off the gaze on +x, the limbus on -x in the
cornea's shadow."""
import math
import pathlib

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux

from eyerender import _hdeye
from eyerender.errors import EyeRenderError
from eyerender.eyes import read_eye_params
from eyerender.render_session import AOV_CHANNELS, RenderSession

ASSET = pathlib.Path(__file__).resolve().parents[2] / "usd_samples" / "assets" / "eye.usda"
EYEBALL = "/World/Eye/Eyeball"
CAMERA_Z = 7.0  # cm from the corneal apex (at the origin), 100 mm lens, 24 mm aperture: +-8.4 mm at the apex


def side_lit_stage(limbal_arc=True, mean_free_path=None):
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.Xform.Define(stage, "/World")
    eye = UsdGeom.Xform.Define(stage, "/World/Eye")
    eye.GetPrim().GetReferences().AddReference(str(ASSET))
    eye.AddTranslateOp().Set(Gf.Vec3d(0, 0, -1.303270723))  # the asset's apex to the origin
    key = UsdLux.SphereLight.Define(stage, "/World/Key")
    key.CreateIntensityAttr(300.0)
    key.CreateRadiusAttr(0.3)
    a = math.radians(75)
    key.AddTranslateOp().Set(Gf.Vec3d(15 * math.sin(a), 0, 15 * math.cos(a)))
    cam = UsdGeom.Camera.Define(stage, "/World/Camera")
    cam.CreateFocalLengthAttr(100.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, CAMERA_Z))
    prim = stage.GetPrimAtPath(EYEBALL)
    prim.CreateAttribute("eye:limbalArc", Sdf.ValueTypeNames.Bool).Set(limbal_arc)
    if mean_free_path is not None:
        prim.CreateAttribute("eye:scleraMeanFreePath", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*mean_free_path))
    return stage


def limbus_bands(size):
    """Masks of the sclera just outside the outer limbus (6.6-7.6 mm from the axis on the apex plane), within 45
    degrees of -x (shadowed) and of +x (lit)."""
    half = 0.12 * CAMERA_Z * 10  # mm at the apex plane
    c = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(c * half, -c * half)
    r = np.hypot(x, y)
    ring = (r > 6.6) & (r < 7.6)
    return ring & (-x > np.abs(y)), ring & (x > np.abs(y))


def test_bindings_carry_the_switches():
    eye = _hdeye.EyeParams()
    assert eye.limbal_arc is True
    assert tuple(round(v, 6) for v in eye.sclera_mean_free_path) == (1.0, 0.8, 0.6)
    eye.limbal_arc, eye.sclera_mean_free_path = False, (2.0, 1.5, 1.0)
    assert eye.limbal_arc is False and tuple(eye.sclera_mean_free_path) == (2.0, 1.5, 1.0)
    settings = _hdeye.RenderSettings()
    assert settings.sclera_scattering is True
    assert hasattr(_hdeye.RenderStats, "capped_walks")
    assert AOV_CHANNELS["limbalArc"] == ("limbalArc.R", "limbalArc.G", "limbalArc.B")


def test_eye_attributes_are_read_and_checked():
    stage = side_lit_stage(limbal_arc=False, mean_free_path=(2.0, 1.0, 0.5))
    params = read_eye_params(stage.GetPrimAtPath(EYEBALL))
    assert params.limbal_arc is False
    assert np.allclose(params.sclera_mean_free_path, (2.0, 1.0, 0.5))
    for bad in ((1.0, 0.0, 1.0), (1.0, -2.0, 1.0), (1.0, float("nan"), 1.0), (float("inf"), 1.0, 1.0)):
        bad_stage = side_lit_stage(mean_free_path=bad)  # held: a prim does not keep its stage alive
        with pytest.raises(EyeRenderError) as e:
            read_eye_params(bad_stage.GetPrimAtPath(EYEBALL))
        message = str(e.value)
        assert "eye:scleraMeanFreePath" in message and EYEBALL in message and "\n" not in message


def test_the_arc_lights_the_shadowed_limbus_and_fills_its_aov():
    size, spp = 40, 6
    shadow, lit = limbus_bands(size)
    rows = {}
    for name, arc, scattering in (("on", True, True), ("off", False, True), ("lambert", True, False)):
        session = RenderSession(side_lit_stage(limbal_arc=arc), width=size, height=size, aovs=("limbalArc",),
                                settings={"sclera_scattering": scattering, "seed": 1})
        stats = session.render(spp=spp)
        assert stats["non_finite_samples"] == 0
        color, arc_aov = session.image("color")[..., :3], session.image("limbalArc")
        rows[name] = (color[shadow].mean(), color[lit].mean(), arc_aov[shadow].mean(), arc_aov.sum())
    on, off, lambert = rows["on"], rows["off"], rows["lambert"]
    print(f"shadowed limbus: arc on {on[0]:.4f} (limbalArc AOV {on[2]:.4f}), off {off[0]:.4f}, "
          f"Lambert {lambert[0]:.4f}; lit limbus: {on[1]:.4f} / {off[1]:.4f} / {lambert[1]:.4f}")
    assert shadow.sum() > 20 and lit.sum() > 20
    assert on[0] > 3 * off[0]            # the arc: measured about 10x
    assert on[2] > 0.7 * on[0]           # and it is the teleported paths' light
    assert off[3] == 0 and lambert[3] == 0  # no cylinder, no walk: an empty AOV
