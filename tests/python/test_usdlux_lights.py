"""UsdLux and UsdGeomCamera as authored, through the scene delegate: a sun at the schema's fallbacks renders at
order 1, colour temperature, ShapingAPI, the dome's poleAxis and visibility, depth of field, and the features the
renderer skips warned about by prim (docs/lights.md)."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender import RenderSession  # noqa: E402
from eyerender.cameras import read_camera  # noqa: E402
from eyerender.lights import read_light  # noqa: E402


def card_stage(size=20.0):
    """A camera 10 units above a card in the xy plane (looking down -z), nothing else."""
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    card = UsdGeom.Mesh.Define(stage, "/card")
    h = size / 2
    card.CreatePointsAttr([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    return stage


def render(stage, spp=4, **kwargs):
    s = RenderSession(stage, width=kwargs.pop("width", 16), height=kwargs.pop("height", 16), **kwargs)
    s.render(spp=spp)
    return s


def test_a_sun_at_the_schema_fallbacks_lights_the_card_at_order_one():
    # DistantLight's fallbacks, as McUsd's sun has them: intensity 50000, the radiance of a 0.53 degree disc.
    stage = card_stage()
    UsdLux.DistantLight.Define(stage, "/sun")
    mean = render(stage).image("color")[:, :, :3].mean()
    # E = 50000 pi sin^2(0.265 deg) = 3.36 lux on the 0.18 card: radiance 0.19 plus its 4 % coat.
    assert 0.15 < mean < 0.35, mean


def test_colour_temperature_warms_the_light_and_6500_k_is_white():
    stage = card_stage()
    sun = UsdLux.DistantLight.Define(stage, "/sun")
    sun.CreateAngleAttr(0.0)
    sun.CreateEnableColorTemperatureAttr(True)
    sun.CreateColorTemperatureAttr(3000.0)
    r, g, b = render(stage).image("color")[:, :, :3].reshape(-1, 3).mean(axis=0)
    assert r > g > b, (r, g, b)
    sun.CreateColorTemperatureAttr(6500.0)
    r, g, b = render(stage).image("color")[:, :, :3].reshape(-1, 3).mean(axis=0)
    assert r == pytest.approx(g, rel=1e-4) and g == pytest.approx(b, rel=1e-4)


def test_a_spot_cone_lights_the_middle_of_the_card_and_not_its_corners():
    stage = card_stage()
    spot = UsdLux.SphereLight.Define(stage, "/spot")
    spot.CreateRadiusAttr(0.1)
    spot.CreateIntensityAttr(1000.0)
    spot.AddTranslateOp().Set(Gf.Vec3d(0, 0, 5))
    shaping = UsdLux.ShapingAPI.Apply(spot.GetPrim())
    shaping.CreateShapingConeAngleAttr(20.0)  # tan 20 deg x 5 = 1.8 units of the card's 20
    image = render(stage, width=32, height=32).image("color")[:, :, 0]
    assert image[14:18, 14:18].min() > 0.1
    assert image[:6, :6].max() == 0 and image[-6:, -6:].max() == 0


def test_dome_pole_axis_follows_dome_light_1_and_the_stage_up_axis():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    scene_pole = UsdLux.DomeLight_1.Define(stage, "/scene")
    y_pole = UsdLux.DomeLight_1.Define(stage, "/y")
    y_pole.CreatePoleAxisAttr("Y")
    old = UsdLux.DomeLight.Define(stage, "/old")
    t = Usd.TimeCode.Default()
    assert read_light(scene_pole.GetPrim(), t).dome_pole_z
    assert not read_light(y_pole.GetPrim(), t).dome_pole_z
    assert not read_light(old.GetPrim(), t).dome_pole_z  # DomeLight's pole is always +y


def test_camera_rays_see_the_dome_only_when_asked():
    stage = card_stage(size=1.0)  # the card fills the middle of the view; the rest is sky
    UsdLux.DomeLight.Define(stage, "/sky").CreateIntensityAttr(0.5)
    hidden = render(stage).image("color")
    shown = render(stage, dome_light_visible=True).image("color")
    sky = hidden[:, :, 3] == 0
    assert sky.any() and (hidden[sky][:, :3] == 0).all()
    assert np.allclose(shown[sky][:, :3], 0.5)
    card = hidden[:, :, 3] == 1
    assert card.any() and np.array_equal(hidden[card], shown[card])  # the dome still lights the card the same


def test_camera_depth_of_field_is_read_and_a_missing_focus_distance_warned_about():
    stage = card_stage()
    cam = UsdGeom.Camera(stage.GetPrimAtPath("/cam"))
    cam.CreateFStopAttr(2.8)
    cam.CreateFocusDistanceAttr(10.0)
    p = read_camera(cam, Usd.TimeCode.Default())
    assert (p.f_stop, p.focus_distance) == (pytest.approx(2.8), 10.0)
    assert eyerender._hdeye.lens_aperture_diameter(p) == pytest.approx(50 * 0.1 / 2.8)
    cam.CreateFocusDistanceAttr(0.0)
    UsdLux.DistantLight.Define(stage, "/sun")
    s = render(stage, spp=1)
    assert any("/cam: fStop 2.8 with focusDistance 0" in w for w in s.scene.warnings)


def test_lights_the_renderer_skips_are_warned_about_by_prim():
    stage = card_stage()
    UsdLux.PortalLight.Define(stage, "/portal")
    warnings = render(stage, spp=1).scene.warnings
    assert any(w.startswith("/portal: PortalLight is not rendered") for w in warnings), warnings


def test_a_cylinder_light_lights_the_card_along_its_axis_and_treat_as_line_is_read():
    stage = card_stage()
    tube = UsdLux.CylinderLight.Define(stage, "/tube")  # along x, 1 unit above the card
    tube.CreateLengthAttr(3.0)
    tube.CreateRadiusAttr(0.05)
    tube.CreateIntensityAttr(50.0)
    tube.AddTranslateOp().Set(Gf.Vec3d(0, 0, 1))
    s = render(stage, spp=64, width=33, height=33)
    assert s.scene.warnings == []
    image = s.image("color")[:, :, 0]
    # Row 16 sees the tube itself: the card is read two rows (0.25 units) beside it, then 1 unit along and across.
    middle, along, across = image[18, 16], image[18, 24], image[24, 16]
    assert middle > along > 1.5 * across > 0, (middle, along, across)
    tube.CreateTreatAsLineAttr(True)
    p = read_light(tube.GetPrim(), Usd.TimeCode.Default())
    assert p.treat_as_line and (p.length, p.radius) == (3.0, pytest.approx(0.05))


def test_a_catch_light_linked_to_one_card_lights_that_card_alone():
    stage = card_stage(size=1.0)  # the left card
    right = UsdGeom.Mesh.Define(stage, "/right")
    right.CreatePointsAttr([(1, -0.5, 0), (2, -0.5, 0), (2, 0.5, 0), (1, 0.5, 0)])
    right.CreateFaceVertexCountsAttr([4])
    right.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    catch = UsdLux.DistantLight.Define(stage, "/catch")
    catch.CreateAngleAttr(0.0)
    link = Usd.CollectionAPI(catch.GetPrim(), "lightLink")
    link.CreateIncludeRootAttr(False)
    link.CreateIncludesRel().AddTarget("/card")
    s = render(stage, width=48, height=48)
    image, ids = s.image("color")[:, :, 0], s.scene
    left_px, right_px = image[20:28, 18:22], image[20:28, 38:42]  # the cards' middles (x grows to the right)
    assert left_px.min() > 0.1 and right_px.max() == 0, (left_px.min(), right_px.max())
    assert ids.warnings == []


def test_geometry_shadow_unlinked_from_a_light_casts_no_shadow_for_it():
    stage = card_stage()
    blocker = UsdGeom.Mesh.Define(stage, "/lashes")
    blocker.CreatePointsAttr([(-30, -30, 5), (30, -30, 5), (30, 30, 5), (-30, 30, 5)])
    blocker.CreateFaceVertexCountsAttr([4])
    blocker.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    UsdGeom.Camera(stage.GetPrimAtPath("/cam")).CreateClippingRangeAttr(Gf.Vec2f(6, 100))  # sees past the lashes
    sun = UsdLux.DistantLight.Define(stage, "/sun")
    sun.CreateAngleAttr(0.0)
    sun.CreateIntensityAttr(2.0)
    shadowed = render(stage).image("color")[:, :, 0].max()
    link = Usd.CollectionAPI(sun.GetPrim(), "shadowLink")
    link.CreateExcludesRel().AddTarget("/lashes")
    lit = render(stage).image("color")[:, :, 0]
    assert shadowed < 0.05 * lit.mean() and lit.min() > 0


@pytest.mark.parametrize("kind", ["points", "curves"])
def test_points_and_curves_take_part_in_light_and_shadow_linking(kind):
    # A sphere point or a tube, above the camera's near plane, shadows the card's middle from a sun straight down;
    # in the sun's shadowLink excludes it casts none; in its lightLink excludes it is not lit (seen from below).
    stage = card_stage()
    UsdGeom.Camera(stage.GetPrimAtPath("/cam")).CreateClippingRangeAttr(Gf.Vec2f(6, 100))  # sees past the blocker
    if kind == "points":
        blocker = UsdGeom.Points.Define(stage, "/blocker")
        blocker.CreatePointsAttr([(0, 0, 8.5)])
    else:
        blocker = UsdGeom.BasisCurves.Define(stage, "/blocker")
        blocker.CreateTypeAttr("linear")
        blocker.CreateCurveVertexCountsAttr([2])
        blocker.CreatePointsAttr([(0, -5, 8.5), (0, 5, 8.5)])
    blocker.CreateWidthsAttr([2.0] * (1 if kind == "points" else 2))
    sun = UsdLux.DistantLight.Define(stage, "/sun")
    sun.CreateAngleAttr(0.0)
    sun.CreateIntensityAttr(2.0)
    middle = (slice(6, 10), slice(6, 10))
    session = render(stage)
    assert session.scene.warnings == []
    shadowed = session.image("color")[:, :, 0]
    Usd.CollectionAPI(sun.GetPrim(), "shadowLink").CreateExcludesRel().AddTarget("/blocker")
    session.render(spp=4)  # the same session: the stage edit re-resolves the sun's links
    lit = session.image("color")[:, :, 0]
    assert session.scene.adapters.light.link_excludes["/sun"][1] == ["/blocker"]
    assert shadowed[middle].max() < 0.05 * lit.mean() and lit[middle].min() > 0.9 * lit.mean(), \
        (shadowed[middle].max(), lit[middle].min(), lit.mean())
    # Without the near plane the camera, 1.5 units above it, sees only the blocker's sunlit top; in the sun's
    # lightLink excludes that top is dark (only the card's bounce, which the top barely faces).
    UsdGeom.Camera(stage.GetPrimAtPath("/cam")).CreateClippingRangeAttr(Gf.Vec2f(0.1, 100))
    top = render(stage).image("color")[:, :, 0]
    Usd.CollectionAPI(sun.GetPrim(), "lightLink").CreateExcludesRel().AddTarget("/blocker")
    unlit = render(stage)
    assert unlit.scene.adapters.light.link_excludes["/sun"][0] == ["/blocker"]
    dark = unlit.image("color")[:, :, 0]
    assert top.min() > 0.05 and dark.max() < 0.05 * top.mean(), (top.min(), dark.max(), top.mean())
