"""eyerecord's usdrecord flags mean what usdrecord (OpenUSD pxr/usdImaging/bin/usdrecord/usdrecord.py and
usdAppUtils' argument modules) makes them mean."""
import zlib

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdRender  # noqa: E402

from eyerender.camera_light import CAMERA_LIGHT_ID, NOTE  # noqa: E402
from eyerender.cli.eyerecord import build_parser, main  # noqa: E402
from eyerender.frames import output_path, parse_frames  # noqa: E402
from eyerender.job import parse_purposes  # noqa: E402


def run(*args):
    return main([str(a) for a in args])


def error_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert err and err[-1].startswith("eyerecord: error: ") and len(err[-1]) < 200, err
    return err[-1]


def lit_card(path, light=True, start=None):
    """A white card facing main_cam; with `light`, a distant light from the camera's side (normalized: intensity 1
    is 1 lux, where unnormalized it would be the radiance of its 0.53 degree disc). Returns the stage."""
    stage = Usd.Stage.CreateNew(str(path))
    if start is not None:
        stage.SetStartTimeCode(start)
        stage.SetEndTimeCode(start + 10)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateHorizontalApertureAttr(20.0)
    cam.CreateVerticalApertureAttr(20.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 30))
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    card.CreateDisplayColorAttr([(1.0, 1.0, 1.0)])
    if light:
        sun = UsdLux.DistantLight.Define(stage, "/World/sun")
        sun.CreateIntensityAttr(1.0)
        sun.CreateNormalizeAttr(True)
    stage.GetRootLayer().Save()
    return stage


def mean_color(path):
    return float(np.mean(eyerender.read_exr(str(path))["R"]))


def test_r_is_the_renderer_flag_and_abbreviations_are_off(tmp_path, capsys):
    args = build_parser().parse_args(["in.usda", "out.exr", "-r", "Eye"])
    assert args.renderer == "Eye" and args.renderSettingsPrimPath is None
    for bad in (["-r", "Storm"], ["--rend", "Eye"], ["--imageW", "8"]):
        with pytest.raises(SystemExit) as e:
            build_parser().parse_args(["in.usda", "out.exr", *bad])
        assert e.value.code == 2


def test_purposes_split_on_commas_and_spaces_like_usdrecord(capsys):
    assert parse_purposes(["proxy render"]) == ("proxy", "render")
    assert parse_purposes(["proxy,guide", "render"]) == ("proxy", "guide", "render")
    assert parse_purposes(None) == ("proxy",)
    with pytest.raises(eyerender.EyeRenderError, match="'bogus' is not a UsdGeom purpose"):
        parse_purposes(["bogus"])


def test_frames_follow_usdrecords_placeholder_rules(tmp_path, capsys):
    stage_path = tmp_path / "s.usda"
    lit_card(stage_path)
    # -f 1:2x0.5 with a placeholder of no decimals would write frame 1.5 over frame 1: refused.
    assert run(stage_path, tmp_path / "r.#.exr", "-f", "1:2x0.5", "-w", 8, "--spp", 1, "-q") == 1
    assert "needs 1 decimal(s)" in error_line(capsys)
    assert run(stage_path, tmp_path / "r.#.#.exr", "-f", "1:2x0.5", "-w", 8, "--spp", 1, "-q") == 0
    assert sorted(p.name for p in tmp_path.glob("r.*")) == ["r.1.0.exr", "r.1.5.exr", "r.2.0.exr"]
    # A placeholder without --frames, and --frames without a placeholder, are errors.
    assert run(stage_path, tmp_path / "r.#.png", "-w", 8, "--spp", 1, "-q") == 1
    assert "placeholder needs --frames" in error_line(capsys)
    assert run(stage_path, tmp_path / "one.exr", "-f", "1", "-w", 8, "--spp", 1, "-q") == 1
    assert "placeholder" in error_line(capsys)
    assert output_path("a.###.exr", 7) == "a.007.exr" and output_path("a.#.##.exr", 1.5) == "a.1.50.exr"
    assert parse_frames("101:105x2,3") == [101, 103, 105, 3]


def test_without_frames_the_render_is_at_the_start_time_code_and_defaultTime_at_the_default(tmp_path):
    stage_path = tmp_path / "s.usda"
    stage = lit_card(stage_path, start=5)
    visibility = UsdGeom.Imageable(stage.GetPrimAtPath("/World/card")).GetVisibilityAttr()
    visibility.Set(UsdGeom.Tokens.invisible)  # default time: hidden
    visibility.Set(UsdGeom.Tokens.invisible, 0)  # the earliest sample: hidden
    visibility.Set(UsdGeom.Tokens.inherited, 5)  # the start time code: visible
    stage.GetRootLayer().Save()
    assert run(stage_path, tmp_path / "start.exr", "-w", 8, "--spp", 1, "-q") == 0
    assert run(stage_path, tmp_path / "default.exr", "-d", "-w", 8, "--spp", 1, "-q") == 0
    assert mean_color(tmp_path / "start.exr") > 0.01 and mean_color(tmp_path / "default.exr") == 0
    with pytest.raises(SystemExit) as e:  # exclusive flags: a usage error
        run(stage_path, tmp_path / "f.#.exr", "-d", "-f", "1", "-w", 8, "-q")
    assert e.value.code == 2


def test_width_zero_is_an_error(tmp_path, capsys):
    stage_path = tmp_path / "s.usda"
    lit_card(stage_path)
    assert run(stage_path, tmp_path / "out.exr", "-w", 0, "--spp", 1, "-q") == 1
    assert "--imageWidth 0" in error_line(capsys)
    assert not (tmp_path / "out.exr").exists()


def test_session_layer_picks_a_variant_and_mask_limits_the_stage(tmp_path):
    stage_path = tmp_path / "s.usda"
    stage = lit_card(stage_path)
    card = stage.GetPrimAtPath("/World/card")
    variants = card.GetVariantSets().AddVariantSet("look")
    for name, visibility in (("shown", UsdGeom.Tokens.inherited), ("hidden", UsdGeom.Tokens.invisible)):
        variants.AddVariant(name)
        variants.SetVariantSelection(name)
        with variants.GetVariantEditContext():
            UsdGeom.Imageable(card).CreateVisibilityAttr().Set(visibility)
    variants.SetVariantSelection("shown")
    stage.GetRootLayer().Save()
    session = Sdf.Layer.CreateNew(str(tmp_path / "session.usda"))
    over = Sdf.CreatePrimInLayer(session, "/World/card")
    over.variantSelections["look"] = "hidden"
    session.Save()
    assert run(stage_path, tmp_path / "shown.exr", "-w", 8, "--spp", 1, "-q") == 0
    assert run(stage_path, tmp_path / "hidden.exr", "--sessionLayer", tmp_path / "session.usda", "-w", 8,
               "--spp", 1, "-q") == 0
    assert mean_color(tmp_path / "shown.exr") > 0.01 and mean_color(tmp_path / "hidden.exr") == 0
    assert run(stage_path, tmp_path / "masked.exr", "--mask", "/World/main_cam, /World/sun", "-w", 8,
               "--spp", 1, "-q") == 0
    assert mean_color(tmp_path / "masked.exr") == 0  # the card is outside the mask


def test_render_settings_from_stage_metadata_and_from_a_render_pass(tmp_path, capsys):
    stage_path = tmp_path / "s.usda"
    stage = lit_card(stage_path)
    settings = UsdRender.Settings.Define(stage, "/Render/settings")
    settings.CreateResolutionAttr(Gf.Vec2i(12, 6))
    render_pass = UsdRender.Pass.Define(stage, "/Render/pass")
    render_pass.CreateRenderSourceRel().SetTargets([settings.GetPath()])
    stage.SetMetadata("renderSettingsPrimPath", "/Render/settings")
    stage.GetRootLayer().Save()
    assert run(stage_path, tmp_path / "meta.exr", "--spp", 1, "-q") == 0
    assert eyerender.read_exr(str(tmp_path / "meta.exr"))["R"].shape == (6, 12)
    stage.SetMetadata("renderSettingsPrimPath", "")
    stage.GetRootLayer().Save()
    assert run(stage_path, tmp_path / "pass.exr", "-rp", "/Render/pass", "--spp", 1, "-q") == 0
    assert eyerender.read_exr(str(tmp_path / "pass.exr"))["R"].shape == (6, 12)
    assert run(stage_path, tmp_path / "x.exr", "-rp", "/Render/pass", "-rs", "/Render/settings", "-q") == 1
    assert "contradict" in error_line(capsys)


def test_an_unlit_stage_gets_a_camera_light_with_a_note_and_disableCameraLight_removes_it(tmp_path, capsys):
    stage_path = tmp_path / "s.usda"
    lit_card(stage_path, light=False)
    assert run(stage_path, tmp_path / "lit.exr", "-w", 8, "--spp", 2, "-q", "--no-auto-plan") == 0
    assert f"eyerecord: {NOTE}" in capsys.readouterr().out.splitlines()
    lit = mean_color(tmp_path / "lit.exr")
    # Irradiance pi on a white diffuse card facing the camera: radiance 1 (its albedo), plus the default
    # UsdPreviewSurface's few percent of specular reflection.
    assert 1.0 <= lit < 1.1, lit
    assert run(stage_path, tmp_path / "dark.exr", "-w", 8, "--spp", 1, "-q", "--disableCameraLight") == 0
    assert NOTE not in capsys.readouterr().out and mean_color(tmp_path / "dark.exr") == 0
    lit_stage = tmp_path / "lit_stage.usda"
    lit_card(lit_stage, light=True)
    session = eyerender.job.open_session(Usd.Stage.Open(str(lit_stage)), eyerender.job.SessionOptions(width=8))
    assert not session.camera_light and CAMERA_LIGHT_ID not in session.index.sprim_ids()


def test_dome_lights_are_hidden_from_the_camera_unless_enableDomeLightVisibility(tmp_path):
    stage_path = tmp_path / "s.usda"
    stage = Usd.Stage.CreateNew(str(stage_path))
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateHorizontalApertureAttr(20.0)
    cam.CreateVerticalApertureAttr(20.0)
    UsdGeom.Sphere.Define(stage, "/World/ball").AddTranslateOp().Set(Gf.Vec3d(0, 0, -1000))
    UsdLux.DomeLight.Define(stage, "/World/sky").CreateIntensityAttr(1.0)
    stage.GetRootLayer().Save()
    assert run(stage_path, tmp_path / "hidden.exr", "-w", 8, "--spp", 1, "-q") == 0
    assert run(stage_path, tmp_path / "shown.exr", "-w", 8, "--spp", 1, "-q", "--enableDomeLightVisibility") == 0
    hidden, shown = eyerender.read_exr(str(tmp_path / "hidden.exr")), eyerender.read_exr(str(tmp_path / "shown.exr"))
    corner = (0, 0)  # the background: only the dome is there
    assert hidden["R"][corner] == 0 and shown["R"][corner] == pytest.approx(1.0, rel=1e-3)


def one_pixel_png(path):
    """The RGB bytes of a 1x1 PNG (every PNG row filter is the identity on a lone first pixel)."""
    data, pos, idat = path.read_bytes(), 8, b""
    while pos < len(data):
        length, kind = int.from_bytes(data[pos:pos + 4], "big"), data[pos + 4:pos + 8]
        idat += data[pos + 8:pos + 8 + length] if kind == b"IDAT" else b""
        pos += 12 + length
    return tuple(zlib.decompress(idat)[1:4])


def test_color_correction_disabled_writes_linear_values_to_the_png(tmp_path):
    from eyerender.render_session import write_images

    images = {"color": np.full((1, 1, 4), 0.2, dtype=np.float32)}
    write_images(str(tmp_path / "srgb.png"), images)
    write_images(str(tmp_path / "linear.png"), images, color_correction="disabled")
    write_images(str(tmp_path / "ocio.png"), images, color_correction="openColorIO")
    srgb, linear, ocio = (one_pixel_png(tmp_path / f"{n}.png") for n in ("srgb", "linear", "ocio"))
    assert linear[0] == round(0.2 * 255), linear
    assert srgb[0] == round(255 * (1.055 * 0.2 ** (1 / 2.4) - 0.055)) and ocio == srgb, srgb
