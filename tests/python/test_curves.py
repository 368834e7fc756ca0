"""BasisCurves and Points through the USD scene delegate (curves.py): rendered with their material, casting shadows
(MNEE's shadow rays to the iris meet them), animated points re-pushed, bad prims skipped with one warning."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade  # noqa: E402

from eyerender import RenderSession  # noqa: E402
from eyerender.curves import _curves_data as curves_data  # noqa: E402
from shading_stages import preview_material  # noqa: E402


def eye_stage():
    """An analytic eye (mm, gaze +z) seen from 40 mm, lit by a small sphere light up and to the right."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(50.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim().AddAppliedSchema("EyeAPI")
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateRadiusAttr(1.0)
    light.CreateIntensityAttr(2000.0)
    light.AddTranslateOp().Set(Gf.Vec3d(10, 10, 30))
    return stage


def lash(stage, offset=(0.0, 0.0), path="/World/lash"):
    """A thick pinned bspline curve across the light's path to the eye (7 mm off the camera's view of the iris)."""
    curve = UsdGeom.BasisCurves.Define(stage, path)
    curve.CreateTypeAttr(UsdGeom.Tokens.cubic)
    curve.CreateBasisAttr(UsdGeom.Tokens.bspline)
    curve.CreateWrapAttr(UsdGeom.Tokens.pinned)
    curve.CreateCurveVertexCountsAttr([5])
    curve.CreatePointsAttr([(5 + t + offset[0], 5 - t + offset[1], 15) for t in (-8, -4, 0, 4, 8)])
    curve.CreateWidthsAttr([4.0])
    curve.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    return curve


def iris_light(stage):
    s = RenderSession(stage, width=40, height=40, aovs=["irisMnee"], refine_level=1)
    s.render(spp=8)
    return float(s.image("irisMnee").mean()), s


def test_a_curve_between_the_light_and_the_eye_darkens_the_iris_mnee_light():
    open_light, _ = iris_light(eye_stage())
    stage = eye_stage()
    lash(stage)
    shadowed, s = iris_light(stage)
    stage = eye_stage()
    lash(stage, offset=(30, 30))  # the same curve far from the light's path
    aside, _ = iris_light(stage)
    assert open_light > 0
    assert shadowed < 0.5 * open_light, (shadowed, open_light)  # measured 0.25: light passes beside the tube
    assert aside == pytest.approx(open_light, rel=1e-6), (aside, open_light)
    assert not s.scene.warnings


def flat_stage():
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateHorizontalApertureAttr(20.0)
    cam.CreateVerticalApertureAttr(20.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    UsdLux.DomeLight.Define(stage, "/World/dome")
    return stage


def test_curves_and_points_render_with_their_material():
    stage = flat_stage()
    curve = UsdGeom.BasisCurves.Define(stage, "/World/hair")
    curve.CreateTypeAttr(UsdGeom.Tokens.linear)
    curve.CreateCurveVertexCountsAttr([2])
    curve.CreatePointsAttr([(-3, 0, 0), (3, 0, 0)])
    curve.CreateWidthsAttr([0.5, 0.5])
    curve.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    UsdShade.MaterialBindingAPI.Apply(curve.GetPrim()).Bind(preview_material(stage, "/World/red", (0.8, 0.1, 0.1)))
    dots = UsdGeom.Points.Define(stage, "/World/dots")
    dots.CreatePointsAttr([(0, 2, 0)])
    dots.CreateWidthsAttr([1.0])
    UsdShade.MaterialBindingAPI.Apply(dots.GetPrim()).Bind(preview_material(stage, "/World/green", (0.1, 0.7, 0.2)))
    s = RenderSession(stage, width=41, height=41, aovs=["albedo", "depth"])
    s.render(spp=1)
    albedo, depth = s.image("albedo"), s.image("depth")
    assert albedo[20, 20] == pytest.approx((0.8, 0.1, 0.1), abs=1e-6)
    assert depth[20, 20, 0] == pytest.approx(10 - 0.25, abs=1e-3)  # the tube's radius in front of its axis
    # World y = 2 at 10 units: 2 / (20 / 50 * 10 / 41) = 20.5 rows above the centre.
    assert albedo[20 - 20, 20] == pytest.approx((0.1, 0.7, 0.2), abs=1e-6)
    assert albedo[5, 5].sum() == 0  # nothing else in view


def test_one_width_on_a_vertex_interpolated_curve_is_a_constant_width_as_in_storm():
    # OpenUSD's basicDrawing and testUsdImagingGLCurves stages author widths = [w] with the default (vertex)
    # interpolation on curves of many vertices; they were skipped.
    stage = flat_stage()
    curve = UsdGeom.BasisCurves.Define(stage, "/World/hair")
    curve.CreateTypeAttr(UsdGeom.Tokens.linear)
    curve.CreateCurveVertexCountsAttr([3])
    curve.CreatePointsAttr([(-3, 0, 0), (0, 0, 0), (3, 0, 0)])
    curve.CreateWidthsAttr([0.5])
    assert curve.GetWidthsInterpolation() == UsdGeom.Tokens.vertex
    s = RenderSession(stage, width=41, height=41, aovs=["depth"])
    assert s.scene.warnings == []
    s.render(spp=1)
    assert s.image("depth")[20, 20, 0] == pytest.approx(10 - 0.25, abs=1e-3)  # a tube of radius 0.25


def test_animated_curve_points_are_re_pushed_and_bad_curves_skipped_with_a_warning():
    stage = flat_stage()
    curve = lash(stage)
    points = curve.GetPointsAttr().Get()
    curve.GetPointsAttr().Set(points, 1)
    curve.GetPointsAttr().Set([p + Gf.Vec3f(0, 0, 1) for p in points], 2)
    bad = UsdGeom.BasisCurves.Define(stage, "/World/bad")
    bad.CreateCurveVertexCountsAttr([5])
    bad.CreatePointsAttr([(0, 0, 0)] * 4)
    thin = UsdGeom.BasisCurves.Define(stage, "/World/thin")
    thin.CreateCurveVertexCountsAttr([4, 4])
    thin.CreatePointsAttr([(i, 0, 0) for i in range(8)])
    thin.CreateWidthsAttr([1.0, 1.0, 1.0])
    thin.SetWidthsInterpolation(UsdGeom.Tokens.varying)  # cubic bezier: 2 per curve
    # OpenUSD's pinnedCurves stage: one curve too short among good ones; Storm draws the good ones.
    partly = UsdGeom.BasisCurves.Define(stage, "/World/partly")
    partly.CreateTypeAttr(UsdGeom.Tokens.cubic)
    partly.CreateBasisAttr(UsdGeom.Tokens.bspline)
    partly.CreateWrapAttr(UsdGeom.Tokens.pinned)
    partly.CreateCurveVertexCountsAttr([3, 1, 2])
    partly.CreatePointsAttr([(0, 0, 0), (1, 1, 0), (2, 0, 0), (9, 9, 9), (0, -2, 0), (2, -2, 0)])
    partly.CreateWidthsAttr([0.1, 0.2, 0.3, 9.0, 0.5, 0.6])
    partly.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    UsdGeom.PrimvarsAPI(partly).CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray,
                                              UsdGeom.Tokens.uniform).Set([(1, 0, 0), (0, 1, 0), (0, 0, 1)])
    s = RenderSession(stage, width=8, height=8)
    assert s.scene.warnings == [
        "/World/bad: curveVertexCounts add up to 5, there are 4 points (skipped)",
        "/World/thin: widths has 3 values, varying needs 4 (skipped)",
        "/World/partly: 1 of 3 curves (1) have a vertex count cubic bspline pinned curves cannot take: left out"]
    counts, _, points, primvars = curves_data(partly.GetPrim(), Usd.TimeCode.Default(), lambda message: None)
    assert list(counts) == [3, 2] and len(points) == 5 and (points != 9).all()
    assert dict(primvars)["widths"][1].ravel().tolist() == pytest.approx([0.1, 0.2, 0.3, 0.5, 0.6])
    assert dict(primvars)["displayColor"][1].tolist() == [[1, 0, 0], [0, 0, 1]]
    s.render(spp=1, time=2)
    assert s.stats["updated"] == {"points": 1}
    assert "/World/bad" not in s.index.rprim_ids() and "/World/thin" not in s.index.rprim_ids()
    assert "/World/lash" in s.index.rprim_ids() and "/World/partly" in s.index.rprim_ids()
    assert np.isfinite(s.image("color")).all()


def colour_stage():
    """A camera at z = 8 looking down -z (its view about 3.4 wide at z = 0), and a light, in scene units."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 8))
    light = UsdLux.DistantLight.Define(stage, "/World/sun")
    light.CreateIntensityAttr(2.0)
    return stage


def albedo_row(stage, row):
    s = RenderSession(stage, width=48, height=24, aovs=["albedo"])
    s.render(spp=1)
    return s.image("albedo")[row, :, :3], s


def test_curves_and_points_without_a_material_show_their_display_color():
    # Storm's fallback surface: constant, per curve and per vertex (blended along each segment) for curves, per point
    # for points (OpenUSD's BasisCurvesWithColor and Points stages rendered grey).
    stage = colour_stage()
    curves = UsdGeom.BasisCurves.Define(stage, "/World/curves")
    curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    curves.CreateCurveVertexCountsAttr([2, 2])
    curves.CreatePointsAttr([(-1.5, 0.6, 0), (1.5, 0.6, 0), (-1.5, 0.2, 0), (1.5, 0.2, 0)])
    curves.CreateWidthsAttr([0.25])
    colors = UsdGeom.PrimvarsAPI(curves).CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray,
                                                       UsdGeom.Tokens.vertex)
    colors.Set([(1, 0, 0), (0, 0, 1), (0, 1, 0), (0, 1, 0)])
    points = UsdGeom.Points.Define(stage, "/World/points")
    points.CreatePointsAttr([(-1, -0.5, 0), (1, -0.5, 0)])
    points.CreateWidthsAttr([0.5, 0.5])
    points.CreateDisplayColorAttr([(1, 1, 0), (0, 1, 1)])
    points.GetDisplayColorPrimvar().SetInterpolation(UsdGeom.Tokens.vertex)
    top, s = albedo_row(stage, 3)  # y = 0.6: red blending to blue from left to right
    assert not s.scene.warnings
    covered = np.flatnonzero(top.sum(axis=1) > 0)
    left, right = top[covered[0] + 1], top[covered[-1] - 1]
    assert left[0] > 0.85 and left[2] < 0.15 and right[2] > 0.85 and right[0] < 0.15, (left, right)
    middle = top[24]
    assert middle == pytest.approx((0.5, 0, 0.5), abs=0.05)
    second, _ = albedo_row(stage, 9)  # y = 0.2: green all along
    assert second[24] == pytest.approx((0, 1, 0), abs=1e-5)
    bottom, _ = albedo_row(stage, 19)  # y = -0.5: the points, yellow and cyan
    assert bottom[10] == pytest.approx((1, 1, 0), abs=1e-5) and bottom[38] == pytest.approx((0, 1, 1), abs=1e-5)
    # A displayColor that does not fit is left out with one warning; the curves still render (grey).
    colors.Set([(1, 0, 0)] * 3)
    top, s = albedo_row(stage, 3)
    assert s.scene.warnings == ["/World/curves: displayColor has 3 values, vertex needs 4: ignored"]
    assert top[24] == pytest.approx((0.18, 0.18, 0.18), abs=1e-5)
