"""The front end never crashes: every case that once ended in a traceback or a signal, run as a user runs it (in a
subprocess, so a crash fails the test instead of killing pytest), ends in exit 0 with one warning naming the
skipped prim, or in one short error line and exit 1. Then a short seeded pass of scripts/fuzz_stages.py."""
import importlib.util
import os
import subprocess
import sys

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender.output_files import partial_failure, stale_temp_files  # noqa: E402
from eyerender.usd_diagnostics import one_line, summarise_tf_error  # noqa: E402
from eyerender.validation import check_transform  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def eyerecord(*args, cwd=None):
    """(exit status, stdout lines, stderr lines) of eyerecord run in its own process."""
    proc = subprocess.run([sys.executable, "-m", "eyerender.cli.eyerecord", *map(str, args)], capture_output=True,
                          timeout=120, cwd=cwd)
    return proc.returncode, proc.stdout.decode(errors="replace").splitlines(), \
        proc.stderr.decode(errors="replace").splitlines()


def assert_no_crash(rc, out, err):
    assert rc in (0, 1), (rc, err[-5:])
    assert not any("Traceback" in line for line in err), err
    assert all(len(line) < 200 for line in out + err), [line for line in out + err if len(line) >= 200]


def shot(tmp_path, name="shot.usda"):
    """A camera, a key light and a card in front of it; returns (stage, path)."""
    path = tmp_path / name
    stage = Usd.Stage.CreateNew(str(path))
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateIntensityAttr(500.0)
    light.AddTranslateOp().Set(Gf.Vec3d(0, 10, 30))
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-20, -20, -5), (20, -20, -5), (20, 20, -5), (-20, 20, -5)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    return stage, path


def render(stage, path, *flags):
    stage.GetRootLayer().Save()
    out = path.parent / "out.exr"
    rc, stdout, stderr = eyerecord(path, out, "-w", 16, "--spp", 1, "-q", *flags)
    assert_no_crash(rc, stdout, stderr)
    return rc, stdout, stderr, out


def author_raw(stage, prim_path, name, kind, value):
    """Authors attribute `name` of type `kind` on the root layer directly: USD's API refuses a type other than
    the schema's, a .usda file does not."""
    prim = stage.GetPrimAtPath(prim_path)
    if prim.GetAttribute(name) and prim.GetAttribute(name).IsAuthored():
        prim.RemoveProperty(name)
    spec = Sdf.AttributeSpec(stage.GetRootLayer().GetPrimAtPath(prim_path), name, kind)
    spec.default = value


def warning_about(stderr, prim):
    lines = [line for line in stderr if line.startswith(f"eyerecord: warning: {prim}: ")]
    assert len(lines) == 1, stderr
    return lines[0]


@pytest.mark.parametrize("matrix", [
    Gf.Matrix4d(0), Gf.Matrix4d(1).SetScale(Gf.Vec3d(1, 0, 1)), Gf.Matrix4d(float("nan")),
    Gf.Matrix4d(1).SetTranslate(Gf.Vec3d(0, 0, 1e30)),
], ids=["zero", "scale 0", "NaN", "1e30 translate"])
def test_a_degenerate_camera_transform_skips_the_camera_and_never_reaches_embree(tmp_path, matrix):
    stage, path = shot(tmp_path)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/main_cam")).ClearXformOpOrder()
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/main_cam")).AddTransformOp().Set(matrix)
    rc, _, err, out = render(stage, path)
    assert "transform" in warning_about(err, "/World/main_cam")
    assert rc == 0 and out.exists()  # the default camera frames the stage instead
    rc, _, err, _ = render(stage, path, "--camera", "/World/main_cam")
    assert rc == 1 and err[-1].startswith("eyerecord: error: ")


@pytest.mark.parametrize("what", ["projective", "singular"])
def test_a_projective_or_singular_mesh_transform_skips_the_mesh(tmp_path, what):
    stage, path = shot(tmp_path)
    # usd-wg's weird_matrix_transform.usda: both at once (its rows are linearly dependent).
    matrix = Gf.Matrix4d(1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 1) if what == "projective" else \
        Gf.Matrix4d(1).SetScale(Gf.Vec3d(0, 1, 1))
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/card")).AddTransformOp().Set(matrix)
    rc, _, err, out = render(stage, path)
    assert rc == 0 and what in warning_about(err, "/World/card") and out.exists()


def test_normals_of_the_wrong_type_are_ignored_with_a_warning(tmp_path):
    stage, path = shot(tmp_path)
    author_raw(stage, "/World/card", "normals", Sdf.ValueTypeNames.Int, 3)  # usd-wg's normalsTypes.usda /World/int
    rc, _, err, _ = render(stage, path)
    assert rc == 0 and "primvars:normals" in warning_about(err, "/World/card")


@pytest.mark.parametrize("case", ["bad op token", "string translate"])
def test_a_bad_xform_op_skips_the_prim_with_usds_reason(tmp_path, case):
    stage, path = shot(tmp_path)
    card = stage.GetPrimAtPath("/World/card")
    order = card.CreateAttribute("xformOpOrder", Sdf.ValueTypeNames.TokenArray, variability=Sdf.VariabilityUniform)
    if case == "bad op token":
        order.Set(["xformOp:bogus"])
    else:
        card.CreateAttribute("xformOp:translate", Sdf.ValueTypeNames.String).Set("abc")
        order.Set(["xformOp:translate"])
    rc, _, err, _ = render(stage, path)
    warning = warning_about(err, "/World/card")
    assert rc == 0 and ("bogus" in warning if case == "bad op token" else "opVal" in warning), warning
    assert "pxrInternal" not in warning and "line" not in warning.split(": ", 2)[-1][:6]


@pytest.mark.parametrize("attribute,kind,value,message", [
    ("eye:scleraMeanFreePath", Sdf.ValueTypeNames.Float3, Gf.Vec3f(1e20, 1, 1), "valid range (0, 1000] mm"),
    ("eye:corneaIor", Sdf.ValueTypeNames.String, "1.4", "is a str, not a number"),
    ("eye:limbalArc", Sdf.ValueTypeNames.Int, 3, "not a bool"),
    ("eye:irisColor", Sdf.ValueTypeNames.Float, 0.5, "not a 3-vector"),
    ("eye:modelTransform", Sdf.ValueTypeNames.Double, 1.0, "not a matrix4d"),
])
def test_an_eye_attribute_out_of_range_or_of_the_wrong_type_fails_the_render(tmp_path, attribute, kind, value,
                                                                             message):
    stage, path = shot(tmp_path)
    eye = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
    eye.AddAppliedSchema("EyeAPI")
    author_raw(stage, "/World/Eye", attribute, kind, value)
    rc, _, err, out = render(stage, path)
    assert rc == 1 and err[-1].startswith(f"eyerecord: error: /World/Eye: {attribute}") and message in err[-1], err
    assert not out.exists()


@pytest.mark.parametrize("case", ["NaN position", "singular transform", "string intensity", "float color"])
def test_a_light_that_cannot_be_rendered_is_named_in_a_warning(tmp_path, case):
    stage, path = shot(tmp_path)
    light = stage.GetPrimAtPath("/World/key")
    if case == "NaN position":
        UsdGeom.Xformable(light).GetOrderedXformOps()[0].Set(Gf.Vec3d(float("nan"), 0, 0))
    elif case == "singular transform":
        UsdGeom.Xformable(light).AddScaleOp().Set(Gf.Vec3f(0, 0, 0))
    else:
        name, kind, value = ("inputs:intensity", Sdf.ValueTypeNames.String, "bright") if case == "string intensity" \
            else ("inputs:color", Sdf.ValueTypeNames.Float, 0.5)
        author_raw(stage, "/World/key", name, kind, value)
    rc, _, err, _ = render(stage, path)
    assert rc == 0 and warning_about(err, "/World/key")


def test_a_tiny_aperture_is_an_error_on_the_image_size_not_a_203877_pixel_tall_image(tmp_path):
    stage, path = shot(tmp_path)
    UsdGeom.Camera(stage.GetPrimAtPath("/World/main_cam")).GetHorizontalApertureAttr().Set(0.0024)
    stage.GetRootLayer().Save()
    rc, _, err = eyerecord(path, tmp_path / "out.exr", "-w", 32, "--spp", 1, "-q")
    assert rc == 1 and "image size 32x" in err[-1] and "apertures" in err[-1], err


def test_a_non_utf8_byte_in_a_usda_is_a_one_line_error(tmp_path):
    path = tmp_path / "bad.usda"
    path.write_bytes(b'#usda 1.0\ndef Xform "a\xff\xfe" {\n    float x = \xff\n}\n')  # USD's error quotes the bytes
    rc, out, err = eyerecord(path, tmp_path / "out.exr")
    assert_no_crash(rc, out, err)
    assert rc == 1 and len(err) == 1 and "cannot open stage" in err[0] and "UnicodeDecodeError" not in err[0], err


def test_usds_error_text_is_summarised_to_its_commentary():
    from pxr import Tf, UsdUtils

    with pytest.raises(Tf.ErrorException) as error:
        UsdUtils.TimeCodeRange.CreateFromFrameSpec("x:y")
    assert summarise_tf_error(error.value) == 'Invalid FrameSpec: "x:y"'
    assert one_line("pxrInternal_v0_1__pxrReserved__::A::B failed\nsecond line") == "A::B failed"
    assert len(one_line("x" * 500)) == 150


def test_check_transform_accepts_a_rotation_and_rejects_what_rays_cannot_use():
    rotation = Gf.Matrix4d(1).SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), 30)).SetTranslateOnly(Gf.Vec3d(1e6, 0, 0))
    assert check_transform("/a", rotation) == rotation
    for bad, why in ((Gf.Matrix4d(0), "projective"), (Gf.Matrix4d(1).SetScale(Gf.Vec3d(1, 1, 1e-13)), "singular"),
                     (Gf.Matrix4d(1).SetTranslate(Gf.Vec3d(0, 2e15, 0)), "beyond")):
        with pytest.raises(eyerender.EyeRenderError, match=why):
            check_transform("/a", bad)
    tiny = Gf.Matrix4d(1).SetScale(1e-9)  # a small scale is not a singular one: it is uniform
    assert check_transform("/a", tiny) == tiny


def test_stale_temp_files_of_dead_writers_are_removed_before_writing(tmp_path):
    stage, path = shot(tmp_path)
    stage.GetRootLayer().Save()
    dead, live = tmp_path / ".out.exr.tmp.999999999.0", tmp_path / f".out.exr.tmp.{os.getppid()}.0"
    other = tmp_path / ".other.exr.tmp.999999999.0"
    for f in (dead, live, other):
        f.write_bytes(b"partial")
    assert stale_temp_files(tmp_path / "out.exr") == [str(dead)]
    rc, _, _ = eyerecord(path, tmp_path / "out.exr", "-w", 8, "--spp", 1, "-q")
    assert rc == 0 and not dead.exists() and live.exists() and other.exists()


def test_an_error_at_frame_2_names_frame_1s_files_which_stay_written(tmp_path):
    stage, path = shot(tmp_path)
    aperture = UsdGeom.Camera(stage.GetPrimAtPath("/World/main_cam")).GetHorizontalApertureAttr()
    aperture.Set(24.0, 1)
    aperture.Set(-1.0, 2)
    stage.GetRootLayer().Save()
    rc, out, err = eyerecord(path, tmp_path / "f.#.exr", "-f", "1:2", "--png", "-w", 8, "--spp", 1, "-q")
    assert_no_crash(rc, out, err)
    assert rc == 1 and err[-1].startswith("eyerecord: error: wrote ") and "frame 2" in err[-1], err
    assert "f.1.exr" in err[-1] and "f.1.png" in err[-1]
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("f.")) == ["f.1.exr", "f.1.png"]


def test_a_failed_png_after_its_exr_names_the_exr(tmp_path, monkeypatch, capsys):
    from eyerender import render_session
    from eyerender.cli.eyerecord import main

    stage, path = shot(tmp_path)
    stage.GetRootLayer().Save()

    def failing_png(*args):
        raise RuntimeError("write out.png: disk full")

    monkeypatch.setattr(render_session, "write_png_preview", failing_png)
    assert main([str(path), str(tmp_path / "out.exr"), "--png", "-w", "8", "--spp", "1", "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == f"eyerecord: error: wrote {tmp_path / 'out.exr'}, then: write out.png: disk full", err
    assert (tmp_path / "out.exr").exists() and not (tmp_path / "out.png").exists()
    assert partial_failure("boom", []) == "boom"


def _load_fuzzer():
    spec = importlib.util.spec_from_file_location("fuzz_stages", os.path.join(REPO, "scripts", "fuzz_stages.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_short_seeded_fuzz_pass_finds_no_crash_traceback_long_line_or_leftover_file():
    fuzzer = _load_fuzzer()
    outcomes, problems = fuzzer.fuzz(seed=2026, count=40, timeout=60)
    assert sum(outcomes.values()) == 40 and not problems, problems
    assert outcomes["rendered"] > 0 and outcomes["one-line error"] > 0  # the mutants reach both ends


def test_the_delegates_own_api_rejects_what_would_crash_it():
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    UsdLux.SphereLight.Define(stage, "/World/key").AddTranslateOp().Set(Gf.Vec3d(0, 10, 30))
    UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim().AddAppliedSchema("EyeAPI")
    session = eyerender.RenderSession(stage, width=8, height=8)
    import numpy as np

    for bad in (np.full((4, 4), np.nan), np.zeros((4, 4)), np.diag([1.0, 1.0, 0.0, 1.0])):
        for prim in ("/World/main_cam", "/World/key", "/World/Eye"):
            with pytest.raises(ValueError, match="transform"):
                session.store.set_transform(prim, bad)
    rounded = np.eye(4)
    rounded[3, 3] = 1.0000000000000002  # a composed look-at matrix's: affine, within rounding
    session.store.set_transform("/World/main_cam", rounded)
    projective = np.eye(4)
    projective[0, 3] = 1e-6
    with pytest.raises(ValueError, match="projective"):
        session.store.set_transform("/World/main_cam", projective)
    eye = eyerender.eyes.read_eye_params(stage.GetPrimAtPath("/World/Eye"))
    eye.sclera_mean_free_path = (1e20, 1.0, 1.0)
    session.store.set_eye_params("/World/Eye", eye)
    with pytest.raises(eyerender.EyeRenderError, match="sclera mean free path.r = 1e\\+20 mm"):
        session.render(spp=1)


def test_a_point_instancer_leaves_out_its_singular_instance_and_draws_the_rest():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    instancer = UsdGeom.PointInstancer.Define(stage, "/World/scatter")
    tile = UsdGeom.Mesh.Define(stage, "/World/scatter/protos/tile")
    tile.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    tile.CreateFaceVertexCountsAttr([3])
    tile.CreateFaceVertexIndicesAttr([0, 1, 2])
    instancer.CreatePrototypesRel().SetTargets([tile.GetPath()])
    instancer.CreatePositionsAttr([(0, 0, 0), (3, 0, 0)])
    instancer.CreateScalesAttr([(1, 1, 1), (0, 0, 0)])  # the second instance is squashed flat: singular
    instancer.CreateProtoIndicesAttr([0, 0])
    # A zero scale is how instances are hidden: that instance draws nothing, the prototype is drawn once.
    session = eyerender.RenderSession(stage, width=8, height=8)
    drawn = [i for i in session.index.rprim_ids() if i.startswith("/World/scatter")]
    assert drawn == ["/World/scatter/__prototype0/tile"]
    session.render(spp=1)
    assert np.isfinite(session.image("color")).all()


@pytest.mark.parametrize("kind", ["curves", "points"])
def test_curves_and_points_with_a_singular_transform_or_a_string_width_are_skipped(kind, tmp_path):
    stage, path = shot(tmp_path)
    for name, broken in (("squashed", "transform"), ("stringy", "widths")):
        prim_path = f"/World/{name}"
        if kind == "curves":
            gprim = UsdGeom.BasisCurves.Define(stage, prim_path)
            gprim.CreateCurveVertexCountsAttr([2])
            gprim.CreateTypeAttr(UsdGeom.Tokens.linear)
        else:
            gprim = UsdGeom.Points.Define(stage, prim_path)
        gprim.CreatePointsAttr([(0, 0, 0), (1, 0, 0)])
        if broken == "transform":
            gprim.AddScaleOp().Set(Gf.Vec3f(1, 0, 1))
        else:
            author_raw(stage, prim_path, "widths", Sdf.ValueTypeNames.String, "thick")
    rc, _, err, out = render(stage, path)
    assert rc == 0 and out.exists()
    assert "singular" in warning_about(err, "/World/squashed") and warning_about(err, "/World/squashed").endswith(
        "(skipped)")
    assert warning_about(err, "/World/stringy").endswith("(skipped)")


def test_an_eye_whose_cornea_shell_target_and_model_transform_are_unreadable_is_one_error_line():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    eye = UsdGeom.Xform.Define(stage, "/World/eye").GetPrim()
    eye.ApplyAPI("EyeAPI")
    eye.CreateRelationship("eye:corneaShell").SetTargets(["/World/nowhere"])
    author_raw(stage, "/World/eye", "eye:modelTransform", Sdf.ValueTypeNames.String, "tilted")
    UsdGeom.Mesh.Define(stage, "/World/cornea")  # named like a shell: the look-alike check reads the eye
    # The look-alike check reads the eye's model transform too: the eye's own error is what is raised.
    with pytest.raises(eyerender.EyeRenderError) as error:
        eyerender.RenderSession(stage, width=8, height=8)
    assert str(error.value) == "/World/eye: eye:modelTransform is a str, not a matrix4d"


def test_an_edit_that_makes_a_mesh_transform_singular_skips_it_at_the_next_frame():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    tile = UsdGeom.Mesh.Define(stage, "/World/tile")
    tile.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    tile.CreateFaceVertexCountsAttr([3])
    tile.CreateFaceVertexIndicesAttr([0, 1, 2])
    scale = tile.AddScaleOp()
    scale.Set(Gf.Vec3f(1, 1, 1))
    session = eyerender.RenderSession(stage, width=8, height=8)
    assert "/World/tile" in session.index.rprim_ids()
    scale.Set(Gf.Vec3f(1, 1, 0))
    session.render(spp=1)
    assert "/World/tile" not in session.index.rprim_ids()
    assert [w for w in session.scene.warnings if w.startswith("/World/tile: ") and w.endswith("(skipped)")], \
        session.scene.warnings
    scale.Set(Gf.Vec3f(1, 1, 1))  # fixed again: a resync brings it back
    session.render(spp=1)
    assert "/World/tile" in session.index.rprim_ids(), session.scene.warnings


def test_one_missing_asset_referenced_by_many_prims_is_one_warning(tmp_path):
    # usd-wg's intent-vfx teapotScene: one missing layer referenced by 548 prims printed 548 lines.
    stage, path = shot(tmp_path)
    for k in range(6):
        stage.DefinePrim(f"/World/copy{k}").GetReferences().AddReference("./missing_asset.usda")
    stage.Save()
    rc, out, err = eyerecord(path, tmp_path / "out.exr", "--imageWidth", 16, "--spp", 1, "--quiet")
    assert_no_crash(rc, out, err)
    usd = [line for line in err if "USD:" in line]
    assert len(usd) == 1 and "missing_asset.usda" in usd[0] and "and 5 more prims" in usd[0], err
    assert rc == 0
