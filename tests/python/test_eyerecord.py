"""eyerecord, the usdrecord-like command: flags, frame ranges, outputs, and one-line errors with a non-zero exit."""
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Usd, UsdGeom, UsdLux, UsdRender  # noqa: E402

from eyerender.cli.eyerecord import main  # noqa: E402
from eyerender.frames import output_path, parse_frames  # noqa: E402


@pytest.fixture
def stage_file(tmp_path):
    """A small stage: an analytic eye looking at the camera, a key light, an animated card, frames 1-3."""
    path = tmp_path / "scene.usda"
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)  # millimetres: the eye's canonical frame is the stage's
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(3)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(50.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    side = UsdGeom.Camera.Define(stage, "/World/side_cam")
    side.AddTranslateOp().Set(Gf.Vec3d(0, 0, 60))
    eye = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
    eye.AddAppliedSchema("EyeAPI")
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateRadiusAttr(1.0)
    light.CreateIntensityAttr(2000.0)
    light.AddTranslateOp().Set(Gf.Vec3d(10, 10, 30))
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-30, -30, -20), (30, -30, -20), (30, 30, -20), (-30, 30, -20)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    op = card.AddTranslateOp()
    op.Set(Gf.Vec3d(0, 0, 0), 1)
    op.Set(Gf.Vec3d(0, 0, -5), 3)
    settings = UsdRender.Settings.Define(stage, "/Render/settings")
    settings.CreateResolutionAttr(Gf.Vec2i(20, 10))
    settings.CreateCameraRel().SetTargets(["/World/side_cam"])
    product = UsdRender.Product.Define(stage, "/Render/product")
    var = UsdRender.Var.Define(stage, "/Render/vars/depth")
    var.CreateSourceNameAttr("depth")
    product.CreateOrderedVarsRel().SetTargets([var.GetPath()])
    settings.CreateProductsRel().SetTargets([product.GetPath()])
    stage.GetRootLayer().Save()
    return path


def run(*args):
    return main([str(a) for a in args])


def one_line_error(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("eyerecord: error: "), err
    return err[0]


def test_renders_exr_with_aovs_and_png(stage_file, tmp_path, capsys):
    out = tmp_path / "eye.exr"
    assert run(stage_file, out, "-w", 24, "--spp", 2, "--aov", "irisMnee", "--aov", "depth", "--png", "-q") == 0
    channels = eyerender.read_exr(str(out))
    assert {"R", "G", "B", "A", "irisMnee.R", "depth.Z"} <= set(channels)
    assert channels["R"].shape == (24, 24)  # square apertures: height follows the camera
    assert np.isfinite(channels["R"]).all() and channels["R"].max() > 0
    assert channels["irisMnee.R"].max() > 0  # the iris got light through MNEE
    assert (tmp_path / "eye.png").stat().st_size > 0
    summary = capsys.readouterr().out.strip().splitlines()[-1]
    assert "1 frame(s) 24x24, 2 spp" in summary and "Mrays/s" in summary


def test_eye_aovs_sum_to_the_beauty(stage_file, tmp_path):
    # The analytic eye under the key (made large, so that its reflection covers pixels) before the card: the glint, the
    # refracted iris and the card (nonEye) are each lit, and the five eye AOVs add up to the colour per pixel (the
    # analytic eye has no sclera volume: no limbal arc).
    stage = Usd.Stage.Open(str(stage_file))
    UsdLux.SphereLight(stage.GetPrimAtPath("/World/key")).GetRadiusAttr().Set(8.0)
    stage.GetRootLayer().Save()
    out = tmp_path / "parts.exr"
    parts = ("nonEye", "glint", "iris", "sclera", "limbalArc")
    flags = [a for part in parts for a in ("--aov", part)]
    assert run(stage_file, out, "--camera", "main_cam", "-w", 32, "--spp", 4, *flags, "-q") == 0
    channels = eyerender.read_exr(str(out))
    for c in "RGB":
        total = sum(channels[f"{part}.{c}"].astype(np.float64) for part in parts)
        beauty = channels[c].astype(np.float64)
        assert np.allclose(total, beauty, rtol=1e-5, atol=1e-6), np.abs(total - beauty).max()
    for part in ("nonEye", "glint", "iris"):
        assert channels[f"{part}.R"].max() > 0, part
    assert channels["limbalArc.R"].max() == 0


def test_frame_range_writes_one_file_per_frame(stage_file, tmp_path):
    assert run(stage_file, tmp_path / "f.###.png", "-f", "1:3", "-w", 8, "--spp", 1, "-q") == 0
    assert sorted(os.listdir(tmp_path)) == ["f.001.png", "f.002.png", "f.003.png", "scene.usda"]


def test_a_log_gets_one_line_per_frame_and_the_summary_the_time_to_first_pixel(stage_file, tmp_path, capsys):
    assert run(stage_file, tmp_path / "f.###.exr", "-f", "1:3", "-w", 8, "--spp", 2) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    frames = [line for line in lines if line.startswith("eyerecord: frame ")]
    assert len(frames) == 3 and all("2 spp" in f and "first pixel" in f and "Msamples/s" in f for f in frames), lines
    assert "3 frame(s) 8x8, 2 spp" in lines[-1] and "first pixel" in lines[-1] and "Msamples/s" in lines[-1]


def test_the_progress_bar_on_a_terminal_shows_samples_time_and_time_left(monkeypatch, capsys):
    from eyerender.console import ProgressBar

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    bar = ProgressBar(True)
    bar.label = "render"
    bar(8, 32, 2.0)
    drawn = capsys.readouterr().err
    assert drawn.startswith("\rrender [#######") and "8/32 spp" in drawn and "eta   6.0 s" in drawn, drawn
    limited = ProgressBar(True, time_limit=10.0)
    limited(8, 1 << 20, 2.0)  # under a time limit the time left is the limit's, and the sample count is open
    drawn = capsys.readouterr().err
    assert "8 spp" in drawn and "eta   8.0 s" in drawn, drawn


def test_frame_syntax_and_placeholders():
    assert parse_frames("1:5x2,8") == [1, 3, 5, 8]
    assert parse_frames("1.5") == [1.5]
    assert output_path("a.####.exr", 12) == "a.0012.exr"
    assert output_path("a.###.##.exr", 1.5) == "a.001.50.exr"
    assert parse_frames("5:1") == [5, 4, 3, 2, 1]  # usdrecord counts down
    assert parse_frames("1:2x0.5") == [1, 1.5, 2]
    for bad in ("1:", "a", "1:5x0", "5:1x1", "1:5x-1", "1:2:3", "nan"):
        with pytest.raises(eyerender.EyeRenderError):
            parse_frames(bad)


def test_render_settings_prim_gives_resolution_camera_and_aovs(stage_file, tmp_path):
    out = tmp_path / "rs.exr"
    assert run(stage_file, out, "-rs", "/Render/settings", "--spp", 1, "-q") == 0
    channels = eyerender.read_exr(str(out))
    assert channels["R"].shape == (10, 20) and "depth.Z" in channels


def test_camera_by_name_and_time_limit(stage_file, tmp_path, capsys):
    out = tmp_path / "side.exr"
    assert run(stage_file, out, "-cam", "side_cam", "-w", 16, "--spp", 100000, "--time-limit", 0.05, "-q") == 0
    summary = capsys.readouterr().out
    spp = int(summary.split(" spp")[0].rsplit(" ", 1)[-1])
    assert 1 <= spp < 100000  # stopped by the time limit, after whole samples


def test_no_mnee_and_paraboloid_switches_change_the_iris(stage_file, tmp_path):
    images = {}
    for name, flags in (("mnee", []), ("nomnee", ["--no-mnee"]), ("parab", ["--cornea-model", "paraboloid"])):
        out = tmp_path / f"{name}.exr"
        assert run(stage_file, out, "-w", 16, "--spp", 2, "--aov", "irisMnee", "-q", *flags) == 0
        images[name] = eyerender.read_exr(str(out))
    assert images["mnee"]["irisMnee.R"].max() > 0
    assert images["nomnee"]["irisMnee.R"].max() == 0  # nothing came through MNEE
    assert not np.array_equal(images["mnee"]["R"], images["parab"]["R"])


def test_chamber_estimators_light_the_iris_alike_and_unknown_names_are_refused(stage_file, tmp_path, capsys):
    means = {}
    for name in ("path", "cache", "controlVariate"):
        out = tmp_path / f"{name}.exr"
        assert run(stage_file, out, "-w", 16, "--spp", 16, "--aov", "irisMnee", "-q", "--chamber-estimator", name) == 0
        iris = eyerender.read_exr(str(out))["irisMnee.R"]
        assert np.isfinite(iris).all()
        means[name] = float(iris.mean())
    print(means)
    assert means["path"] > 0
    for name in ("cache", "controlVariate"):  # 16 pixels wide, 16 samples: the means agree to a few per cent
        assert abs(means[name] / means["path"] - 1) < 0.1, means
    settings = eyerender.RenderSettings()
    assert settings.chamber_estimator == "cache"  # the default (docs/iris_benchmark.md)
    settings.chamber_estimator = "cache"
    assert settings.chamber_estimator == "cache"
    with pytest.raises(ValueError, match="guided"):
        settings.chamber_estimator = "guided"
    capsys.readouterr()
    with pytest.raises(SystemExit):  # argparse: one usage line and exit status 2
        run(stage_file, tmp_path / "bad.exr", "--chamber-estimator", "guided")


def test_the_catchlights_edge_pixels_are_counted_in_the_header_and_the_option_is_checked(stage_file, tmp_path,
                                                                                           capsys):
    import OpenEXR

    stage = Usd.Stage.Open(str(stage_file))
    UsdLux.SphereLight(stage.GetPrimAtPath("/World/key")).GetRadiusAttr().Set(8.0)  # a glint pixels across
    stage.GetRootLayer().Save()
    counts = {}
    for n in (16, 1):
        out = tmp_path / f"catchlight{n}.exr"
        assert run(stage_file, out, "--camera", "main_cam", "-w", 48, "--spp", 2, "--catchlight-samples", n, "-q") == 0
        value = OpenEXR.InputFile(str(out)).header()["eyerender:catchlightPixels"]
        counts[n] = int(value.decode() if isinstance(value, bytes) else value)
    assert 0 < counts[16] < 48 * 48 // 4 and counts[1] == 0, counts
    capsys.readouterr()
    assert run(stage_file, tmp_path / "bad.exr", "--catchlight-samples", 0, "-q") == 1
    assert "--catchlight-samples 0: must be 1 to 256" in one_line_error(capsys)


@pytest.mark.parametrize("case", ["missing file", "malformed", "bad camera", "not a camera", "unwritable",
                                  "bad extension", "frames without placeholder", "bad frames"])
def test_bad_input_is_one_line_and_nonzero(case, stage_file, tmp_path, capsys):
    out = tmp_path / "out.exr"
    args = {
        "missing file": [tmp_path / "nope.usda", out],
        "malformed": [tmp_path / "bad.usda", out],
        "bad camera": [stage_file, out, "--camera", "/World/nope"],
        "not a camera": [stage_file, out, "--camera", "/World/Eye"],
        "unwritable": [stage_file, tmp_path / "no_dir" / "out.exr"],
        "bad extension": [stage_file, tmp_path / "out.jpg"],
        "frames without placeholder": [stage_file, out, "-f", "1:3"],
        "bad frames": [stage_file, tmp_path / "f.#.exr", "-f", "x:y"],
    }[case]
    (tmp_path / "bad.usda").write_text("#usda 1.0\ndef Xform \"broken\" {\n")
    assert run(*args, "-w", 8, "--spp", 1, "-q") == 1
    message = one_line_error(capsys)
    expected = {"missing file": "no such file", "malformed": "cannot open stage", "bad camera": "no camera",
                "not a camera": "is a Xform, not a Camera", "unwritable": "does not exist",
                "bad extension": "must be .exr or .png", "frames without placeholder": "placeholder",
                "bad frames": "--frames"}[case]
    assert expected in message
    assert not out.exists()  # nothing half-written


def test_console_script_is_installed(stage_file, tmp_path):
    exe = shutil.which("eyerecord") or os.path.join(os.path.dirname(sys.executable), "eyerecord")
    result = subprocess.run([exe, str(stage_file), str(tmp_path / "x.png"), "-w", "8", "--spp", "1", "-q"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    result = subprocess.run([exe, str(tmp_path / "missing.usda"), str(tmp_path / "x.png")], capture_output=True,
                            text=True)
    assert result.returncode == 1 and result.stderr.strip().count("\n") == 0
