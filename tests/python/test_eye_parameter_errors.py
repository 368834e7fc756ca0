"""An eye that cannot be rendered fails the render (docs/eyerecord.md, "An eye is never skipped"): every EyeAPI value
outside its range (schemas/README.md) is one line naming the prim, the attribute, the value and the valid range;
RenderSession raises it as an EyeRenderError, eyerecord prints it and exits 1 without writing. Checked for the
analytic eye (EyeAPI on an Xform) and the mesh eye (EyeAPI on a Mesh), at the first frame, at a later frame and
after a live edit."""
import math

import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender import EyeRenderError, RenderSession  # noqa: E402
from eyerender.cli.eyerecord import main  # noqa: E402

EYE = "/World/Eye"
FLOAT, COLOR, MATRIX, TOKEN = (Sdf.ValueTypeNames.Float, Sdf.ValueTypeNames.Color3f, Sdf.ValueTypeNames.Matrix4d,
                               Sdf.ValueTypeNames.Token)
# (attribute, type, bad value, what the one line says after "<prim>: ")
BAD_VALUES = [
    ("eye:corneaIor", FLOAT, 0.9, "eye:corneaIor = 0.9 is outside its valid range [1, inf)"),
    ("eye:corneaIor", FLOAT, math.inf, "eye:corneaIor = inf is outside its valid range [1, inf)"),
    ("eye:irisDepth", FLOAT, -1.0, "eye:irisDepth = -1 mm is outside its valid range (0, inf) mm"),
    ("eye:irisDepth", FLOAT, 0.0, "eye:irisDepth = 0 mm is outside its valid range (0, inf) mm"),
    ("eye:limbusInnerRatio", FLOAT, 0.9,
     "eye:limbusInnerRatio = 0.9 is outside its valid range (0, eye:limbusOuterRatio = 0.855]"),
    ("eye:limbusInnerRatio", FLOAT, 0.0, "eye:limbusInnerRatio = 0 is outside its valid range (0, 1]"),
    ("eye:limbusOuterRatio", FLOAT, 1.2, "eye:limbusOuterRatio = 1.2 is outside its valid range (0, 1]"),
    ("eye:limbusOuterRatio", FLOAT, 0.5,
     "eye:limbusInnerRatio = 0.772 is outside its valid range (0, eye:limbusOuterRatio = 0.5]"),
    ("eye:pupilDiameter", FLOAT, 16.0, "eye:pupilDiameter = 16 mm is outside its valid range [0, 15.08) mm"),
    ("eye:pupilDiameter", FLOAT, -0.5, "eye:pupilDiameter = -0.5 mm is outside its valid range [0, 15.08) mm"),
    ("eye:pupilDiameter", FLOAT, math.nan, "eye:pupilDiameter = nan mm is outside its valid range [0, 15.08) mm"),
    ("eye:irisColor", COLOR, Gf.Vec3f(1.5, 0.2, 0.1),
     "eye:irisColor = (1.5, 0.2, 0.1) is outside its valid range [0, 1] per channel"),
    ("eye:scleraColor", COLOR, Gf.Vec3f(0.8, -0.1, 0.7),
     "eye:scleraColor = (0.8, -0.1, 0.7) is outside its valid range [0, 1] per channel"),
    ("eye:scleraMeanFreePath", COLOR, Gf.Vec3f(1, 0, 1),
     "eye:scleraMeanFreePath = (1, 0, 1) mm is outside its valid range (0, 1000] mm per channel"),
    ("eye:scleraMeanFreePath", COLOR, Gf.Vec3f(1, 1, 2000),
     "eye:scleraMeanFreePath = (1, 1, 2000) mm is outside its valid range (0, 1000] mm per channel"),
    ("eye:corneaModel", TOKEN, "sphere", "eye:corneaModel = 'sphere' is not one of ellipsoidCone, paraboloid"),
    ("eye:modelTransform", MATRIX, Gf.Matrix4d(1).SetScale(Gf.Vec3d(1, 0, 1)), "eye:modelTransform is singular"),
]
CASE_IDS = [f"{a}={v}" for a, _, v, _ in BAD_VALUES]


def _grid_mesh(stage, path, n=2, size=20.0):
    """An n x n quad grid facing the camera, size mm across."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr([(size * (i / n - 0.5), size * (j / n - 0.5), 0.0) for j in range(n + 1)
                           for i in range(n + 1)])
    mesh.CreateFaceVertexCountsAttr([4] * n * n)
    mesh.CreateFaceVertexIndicesAttr([k for j in range(n) for i in range(n) for k in (
        j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)])
    mesh.CreateSubdivisionSchemeAttr("none")
    return mesh.GetPrim()


def eye_stage(kind, path=None):
    """A millimetre stage with one eye at EYE: the analytic eye (an Xform) or a mesh eye, a camera and a light.
    Saved to `path` when given."""
    stage = Usd.Stage.CreateNew(str(path)) if path else Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(2)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 60))
    UsdLux.SphereLight.Define(stage, "/World/key").AddTranslateOp().Set(Gf.Vec3d(10, 10, 30))
    prim = UsdGeom.Xform.Define(stage, EYE).GetPrim() if kind == "analytic" else _grid_mesh(stage, EYE)
    prim.AddAppliedSchema("EyeAPI")
    return stage, prim


def _author(prim, attribute, kind, value, time=Usd.TimeCode.Default()):
    prim.CreateAttribute(attribute, kind).Set(value, time)


def _assert_one_line(message, expected):
    assert message == f"{EYE}: {expected}", message
    assert "\n" not in message and len(message) < 200


@pytest.mark.parametrize("kind", ["analytic", "mesh"])
def test_the_valid_eye_renders(kind):
    stage, _ = eye_stage(kind)
    session = RenderSession(stage, width=8, height=8)
    assert session.scene.eyes == [EYE] and not session.scene.warnings
    session.render(spp=1)


@pytest.mark.parametrize("kind", ["analytic", "mesh"])
@pytest.mark.parametrize("attribute,type_name,value,expected", BAD_VALUES, ids=CASE_IDS)
def test_an_out_of_range_eye_value_fails_the_python_session(kind, attribute, type_name, value, expected):
    stage, prim = eye_stage(kind)
    _author(prim, attribute, type_name, value)
    with pytest.raises(EyeRenderError) as error:
        RenderSession(stage, width=8, height=8)
    _assert_one_line(str(error.value), expected)


@pytest.mark.parametrize("kind", ["analytic", "mesh"])
@pytest.mark.parametrize("attribute,type_name,value,expected", BAD_VALUES, ids=CASE_IDS)
def test_an_out_of_range_eye_value_is_one_error_line_and_exit_1_from_eyerecord(kind, attribute, type_name, value,
                                                                               expected, tmp_path, capsys):
    stage, prim = eye_stage(kind, tmp_path / "eye.usda")
    _author(prim, attribute, type_name, value)
    stage.GetRootLayer().Save()
    out = tmp_path / "out.exr"
    assert main([str(tmp_path / "eye.usda"), str(out), "-w", "8", "--spp", "1", "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"eyerecord: error: {EYE}: {expected}"], err
    assert not out.exists()


@pytest.mark.parametrize("case,expected", [
    ("rest time", "eye:restTime = nan is outside its valid range: a finite time code"),
    ("projection", "eye:irisProjection target /World/Nowhere does not exist"),
    ("points", "points holds NaN or infinite values"),
])
def test_a_mesh_eyes_rest_time_projection_or_points_that_cannot_be_used_fail_the_render(case, expected):
    stage, prim = eye_stage("mesh")
    if case == "rest time":
        _author(prim, "eye:restTime", Sdf.ValueTypeNames.Double, math.nan)
    elif case == "projection":
        prim.CreateRelationship("eye:irisProjection").SetTargets(["/World/Nowhere"])
    else:  # the same points skip a mesh that is not an eye (test_usd_scene_delegate.py)
        points = list(UsdGeom.Mesh(prim).GetPointsAttr().Get())
        UsdGeom.Mesh(prim).GetPointsAttr().Set([Gf.Vec3f(math.nan, 0, 0)] + points[1:])
    with pytest.raises(EyeRenderError) as error:
        RenderSession(stage, width=8, height=8)
    _assert_one_line(str(error.value), expected)


@pytest.mark.parametrize("kind", ["analytic", "mesh"])
def test_a_pupil_animated_out_of_range_fails_at_that_frame_after_writing_the_good_one(kind, tmp_path, capsys):
    stage, prim = eye_stage(kind, tmp_path / "eye.usda")
    _author(prim, "eye:pupilDiameter", FLOAT, 4.0, 1)
    _author(prim, "eye:pupilDiameter", FLOAT, 20.0, 2)
    stage.GetRootLayer().Save()
    assert main([str(tmp_path / "eye.usda"), str(tmp_path / "f.#.exr"), "-f", "1:2", "-w", "8", "--spp", "1",
                 "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"eyerecord: error: wrote {tmp_path / 'f.1.exr'}, then: "), err
    assert "eye:pupilDiameter = 20 mm is outside its valid range [0, 15.08) mm" in err[0]
    assert (tmp_path / "f.1.exr").exists() and not (tmp_path / "f.2.exr").exists()


@pytest.mark.parametrize("kind", ["analytic", "mesh"])
def test_a_live_edit_out_of_range_fails_the_next_render_and_a_fix_brings_the_eye_back(kind):
    stage, prim = eye_stage(kind)
    session = RenderSession(stage, width=8, height=8)
    prim.GetAttribute("eye:corneaIor").Set(0.5)
    with pytest.raises(EyeRenderError) as error:
        session.render(spp=1)
    _assert_one_line(str(error.value), "eye:corneaIor = 0.5 is outside its valid range [1, inf)")
    prim.GetAttribute("eye:corneaIor").Set(1.4)
    session.render(spp=1)
    assert session.scene.eyes == [EYE]
