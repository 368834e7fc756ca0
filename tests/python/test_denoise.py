"""eyerecord --denoise: Open Image Denoise's beauty beside the raw one (EXR channels denoised.R/G/B, a .denoised.png),
the raw beauty bit for bit what a render without --denoise writes, and less noise than the raw image."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
pytest.importorskip("pyoidn", reason="pyoidn is not installed (scripts/install_deps.sh)")
from pxr import Gf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender.cli.eyerecord import main  # noqa: E402
from eyerender.denoise import denoise_beauty  # noqa: E402


def card_with_camera(stage):
    """A 16-unit grey card in the xy plane and a camera 10 units in front of it."""
    UsdGeom.Camera.Define(stage, "/cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    card = UsdGeom.Mesh.Define(stage, "/card")
    card.CreatePointsAttr([(-8, -8, 0), (8, -8, 0), (8, 8, 0), (-8, 8, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")


@pytest.fixture
def card_file(tmp_path):
    """The card under a sphere light and a dim dome."""
    path = tmp_path / "card.usda"
    stage = Usd.Stage.CreateNew(str(path))
    card_with_camera(stage)
    key = UsdLux.SphereLight.Define(stage, "/key")
    key.CreateIntensityAttr(30.0)
    key.AddTranslateOp().Set(Gf.Vec3d(2, 2, 4))
    UsdLux.DomeLight.Define(stage, "/sky").CreateIntensityAttr(0.2)
    stage.GetRootLayer().Save()
    return path


def test_denoise_writes_its_own_layer_and_png_and_keeps_the_raw_beauty(card_file, tmp_path):
    raw, both = tmp_path / "raw.exr", tmp_path / "both.exr"
    assert main([str(card_file), str(raw), "-w", "32", "--spp", "2", "-q", "--aov", "albedo", "--aov", "normal"]) == 0
    assert main([str(card_file), str(both), "-w", "32", "--spp", "2", "-q", "--denoise", "--png"]) == 0
    a, b = eyerender.read_exr(str(raw)), eyerender.read_exr(str(both))
    assert {"denoised.R", "denoised.G", "denoised.B", "albedo.R", "N.X"} <= set(b)
    for c in ("R", "G", "B", "A"):
        assert np.array_equal(a[c], b[c])  # never over the raw beauty
    assert not np.array_equal(b["R"], b["denoised.R"])
    assert (tmp_path / "both.png").stat().st_size > 0 and (tmp_path / "both.denoised.png").stat().st_size > 0


def test_denoised_beauty_is_closer_to_a_converged_render_than_the_raw_one():
    from eyerender import RenderSession

    stage = Usd.Stage.CreateInMemory()
    card_with_camera(stage)
    key = UsdLux.RectLight.Define(stage, "/key")
    key.CreateIntensityAttr(5.0)
    key.AddTranslateOp().Set(Gf.Vec3d(1, 1, 3))

    def render(spp, seed):
        s = RenderSession(stage, width=32, height=32, aovs=("albedo", "normal"), settings={"seed": seed})
        s.render(spp=spp)
        return s.image("color")[:, :, :3], s.image("albedo"), s.image("normal")

    ref = render(256, 1)[0]
    noisy, albedo, normal = render(2, 2)
    clean = denoise_beauty(noisy, albedo, normal)
    err_raw = np.sqrt(np.mean((noisy - ref) ** 2)) / ref.mean()
    err_dn = np.sqrt(np.mean((clean - ref) ** 2)) / ref.mean()
    assert err_dn < 0.5 * err_raw, (err_raw, err_dn)


def test_denoise_on_the_farm_is_a_one_line_error(card_file, tmp_path, capsys):
    assert main([str(card_file), str(tmp_path / "x.exr"), "--workers", "1", "--denoise"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--denoise is not available on the farm" in err[0]
