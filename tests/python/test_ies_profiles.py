"""IES profiles on UsdLux lights (ShapingAPI's shaping:ies:file) through the scene delegate: resolved through Ar
beside the layer and inside a .usdz, their shape in the render, and a file that cannot be read (one warning, the
light unshaped; --strict fails). The profiles are authored here."""
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdUtils  # noqa: E402

from eyerender import RenderSession  # noqa: E402
from eyerender.errors import EyeRenderError  # noqa: E402
from eyerender.lights import read_light  # noqa: E402

# A downlight: 1000 cd at the nadir, linear to 0 at 20 degrees, dark beyond (rotationally symmetric).
DOWNLIGHT = """IESNA:LM-63-2002
[TEST] authored by test_ies_profiles
[MANUFAC] none
TILT=NONE
1 -1 1.0 4 1 1 2 0.1 0.1 0.0
1.0 1.0 20
0 10 20 90
0
1000 500 0 0
"""


def stage_with_spot(path, ies_file):
    """A stage file: a camera 30 units above a 20-unit card (the view 12.6 units across), a point-like sphere
    light 5 units above it with ShapingAPI's shaping:ies:file = ies_file (as authored, relative to the layer)."""
    stage = Usd.Stage.CreateNew(str(path))
    cam = UsdGeom.Camera.Define(stage, "/cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 30))
    card = UsdGeom.Mesh.Define(stage, "/card")
    card.CreatePointsAttr([(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    spot = UsdLux.SphereLight.Define(stage, "/spot")
    spot.CreateRadiusAttr(0.01)
    spot.CreateTreatAsPointAttr(True)
    spot.CreateIntensityAttr(1.0)
    spot.AddTranslateOp().Set(Gf.Vec3d(0, 0, 5))
    shaping = UsdLux.ShapingAPI.Apply(spot.GetPrim())
    shaping.CreateShapingConeAngleAttr(180.0)
    shaping.CreateShapingIesFileAttr(Sdf.AssetPath(ies_file))
    stage.Save()
    return stage


def render(stage, **kwargs):
    s = RenderSession(stage, width=32, height=32, **kwargs)
    s.render(spp=1)
    return s


def test_a_profile_beside_the_layer_is_read_and_shapes_the_light(tmp_path):
    (tmp_path / "profiles").mkdir()
    (tmp_path / "profiles" / "down.ies").write_text(DOWNLIGHT)
    stage = stage_with_spot(tmp_path / "s.usda", "profiles/down.ies")
    p = read_light(stage.GetPrimAtPath("/spot"), Usd.TimeCode.Default())
    assert list(p.shaping.ies.vertical) == [0, 10, 20, 90]
    assert p.shaping.ies.intensity(5, 0) == pytest.approx(750)
    s = render(stage)
    assert s.scene.warnings == []
    image = s.image("color")[:, :, 0]
    # tan 20 deg x 5 = 1.8 units (4.6 of the 32 pixels each side of the middle): lit there only.
    assert image[15:17, 15:17].min() > 0
    assert image[:9, :].max() == 0 and image[-9:, :].max() == 0 and image[:, :9].max() == 0


def test_a_profile_inside_a_usdz_package_is_read_through_ar(tmp_path):
    (tmp_path / "down.ies").write_text(DOWNLIGHT)
    stage_with_spot(tmp_path / "asset.usda", "down.ies")
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(tmp_path / "asset.usda")), str(tmp_path / "asset.usdz"))
    (tmp_path / "down.ies").unlink()  # only the package holds the profile now
    stage = Usd.Stage.Open(str(tmp_path / "asset.usdz"))
    warnings = []
    p = read_light(stage.GetPrimAtPath("/spot"), Usd.TimeCode.Default(), warnings)
    assert warnings == []
    assert p.shaping.ies.intensity(0, 0) == pytest.approx(1000)


@pytest.mark.parametrize("name, content, reason", [
    ("missing.ies", None, "file not found"),
    ("cut.ies", DOWNLIGHT[:DOWNLIGHT.index("0 10 20")], "ends before"),
    ("typeb.ies", DOWNLIGHT.replace("4 1 1 2", "4 1 2 2"), "type B"),
])
def test_an_unreadable_profile_is_one_warning_and_the_light_renders_unshaped(tmp_path, name, content, reason):
    if content is not None:
        (tmp_path / name).write_text(content)
    stage = stage_with_spot(tmp_path / "s.usda", name)
    s = render(stage)
    problems = [w for w in s.scene.warnings if "shaping:ies:file" in w]
    assert len(problems) == 1 and len(s.scene.warnings) == 1, s.scene.warnings
    assert problems[0].startswith("/spot: inputs:shaping:ies:file") and name in problems[0] and reason in problems[0]
    assert "without its profile" in problems[0]
    image = s.image("color")[:, :, 0]
    assert image[0, 0] > 0  # unshaped: the corners are lit too
    with pytest.raises(EyeRenderError, match=name):
        render(stage_with_spot(tmp_path / "strict.usda", name), strict=True)
