"""A studio eye rig (usd_samples/studio_eye_rig.usda: eyeball with EyeAPI, a closed clear cornea shell it targets
with eye:corneaShell, a tear-line strip, an occlusion shell over the corners) renders its cornea once, through the
analytic model, and its tear line and occlusion shell as authored. Variants are edits of the opened sample stage."""
import pathlib

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Sdf, Usd, UsdGeom, UsdShade  # noqa: E402

RIG = pathlib.Path(__file__).resolve().parents[2] / "usd_samples" / "studio_eye_rig.usda"
EYE = "/World/Head/Eye_L"
WIDTH, SPP = 64, 16
OCCLUSION_OPACITY = 0.6  # the sample's (generate_samples.OCCLUSION)


def _rig(edit=None):
    """The sample, with `edit` made in the stage's own session layer (stages opened on one file share its layer)."""
    stage = Usd.Stage.Open(str(RIG))
    stage.SetEditTarget(stage.GetSessionLayer())
    if edit:
        edit(stage)
    return stage


def _render(stage, seed=0):
    session = eyerender.RenderSession(stage, width=WIDTH, aovs=["irisMnee"], refine_level=1, settings={"seed": seed})
    stats = session.render(spp=SPP)
    assert stats["non_finite_samples"] == 0
    return session, session.image("color")[:, :, :3].astype(np.float64), session.image("irisMnee").astype(np.float64)


def _deactivate(path):
    return lambda stage: stage.GetPrimAtPath(path).SetActive(False)


def _untarget_shell(stage):
    """Recognition disabled: the rig as a renderer without eye:corneaShell would see it."""
    stage.GetPrimAtPath(EYE + "/Eyeball").GetRelationship("eye:corneaShell").SetTargets([])


def _rel(a, b):
    return abs(a.mean() - b.mean()) / b.mean()


@pytest.fixture(scope="module")
def rig():
    """The sample as authored, with two seeds: (session, color, irisMnee) each."""
    return _render(_rig()), _render(_rig(), seed=1)


def test_the_targeted_cornea_shell_is_left_out_and_warned_about_nowhere(rig):
    (session, _, _), _ = rig
    assert session.scene.cornea_shells == {Sdf.Path(EYE + "/Cornea"): Sdf.Path(EYE + "/Eyeball")}
    assert EYE + "/Cornea" not in session.index.rprim_ids()
    assert EYE + "/TearLine" in session.index.rprim_ids()
    assert not [w for w in session.scene.warnings if "cornea" in w.lower()], session.scene.warnings


def test_the_cornea_is_refracted_once_the_iris_light_is_the_rig_without_its_shell(rig):
    (_, color, iris), (_, _, iris_seed1) = rig
    noise = _rel(iris_seed1, iris)
    _, color_no_shell, iris_no_shell = _render(_rig(_deactivate(EYE + "/Cornea")))
    print(f"irisMnee mean: rig {iris.mean():.6f}, without the shell {iris_no_shell.mean():.6f}, seed noise {noise:.4f}")
    assert iris.mean() > 0
    assert _rel(iris_no_shell, iris) <= noise
    assert np.allclose(color, color_no_shell, rtol=0, atol=1e-6)  # the same scene: the shell never reaches it


def test_an_untargeted_shell_refracts_a_second_time_shadows_the_iris_and_is_warned_about(rig):
    (_, color, iris), (_, _, iris_seed1) = rig
    noise = _rel(iris_seed1, iris)
    session, naive_color, naive_iris = _render(_rig(_untarget_shell))
    change = _rel(naive_iris, iris)
    print(f"irisMnee mean: recognised {iris.mean():.6f}, shell rendered {naive_iris.mean():.6f} "
          f"(change {change:.3f}, seed noise {noise:.4f}); colour mean {color.mean():.5f} -> {naive_color.mean():.5f}")
    assert change > 10 * noise
    assert naive_iris.mean() < 0.1 * iris.mean()  # a closed glass shell blocks MNEE's shadow rays: its own shadow
    assert any(w.startswith(EYE + "/Cornea: looks like a cornea shell of " + EYE + "/Eyeball")
               for w in session.scene.warnings), session.scene.warnings


def _set_opacity(material_path, opacity):
    def edit(stage):
        shader = UsdShade.Shader(stage.GetPrimAtPath(material_path + "/PreviewSurface"))
        shader.GetInput("opacity").Set(float(opacity))
    return edit


def test_the_occlusion_shell_darkens_the_eye_corners_by_about_its_opacity_and_leaves_the_iris(rig):
    (_, color, iris), (_, color_seed1, iris_seed1) = rig
    _, bare, bare_iris = _render(_rig(_deactivate(EYE + "/Occlusion")))
    _, opaque, _ = _render(_rig(_set_opacity("/World/Looks/Occlusion", 1.0)))
    # Where the shell is: the pixels an opaque black shell blackens.
    corners = (opaque.sum(axis=2) < 0.1 * bare.sum(axis=2)) & (bare.sum(axis=2) > 0)
    ratio = color[corners].mean() / bare[corners].mean()
    # The view crosses the shell once (1 - opacity); most of the light the sclera there receives crossed it too.
    transmit = 1 - OCCLUSION_OPACITY
    print(f"occlusion shell: {corners.sum()} corner pixels, darkened to {ratio:.3f} (view alone {transmit:.2f}, "
          f"view and light {transmit ** 2:.2f}); irisMnee {iris.mean():.6f} vs {bare_iris.mean():.6f} without it")
    assert corners.sum() > 100
    assert 0.8 * transmit ** 2 < ratio < 1.1 * transmit
    assert _rel(bare_iris, iris) <= 2 * _rel(iris_seed1, iris) + 0.01  # the shell is off the cornea


def test_the_tear_line_renders_below_the_iris(rig):
    (_, color, _), (_, color_seed1, _) = rig
    _, bare, _ = _render(_rig(_deactivate(EYE + "/TearLine")))
    diff = np.abs(color - bare).sum(axis=2)
    noise = np.abs(color_seed1 - color).sum(axis=2)
    changed = diff > 0.05
    # The strip runs along the lower lid margin: below the iris's centre in the image (row 0 at the top). Elsewhere
    # only paths that meet it on a later bounce change.
    lower, upper = diff[WIDTH // 2:].sum(), diff[:WIDTH // 2].sum()
    print(f"tear line: {changed.sum()} pixels changed by > 0.05 (seed noise median {np.median(noise):.4f}); "
          f"change in the lower half {lower:.2f}, upper half {upper:.2f}")
    assert changed.sum() > 20
    assert np.median(np.nonzero(changed)[0]) > WIDTH / 2
    assert lower > 3 * upper


def _eye_with_shells(targets):
    """An in-memory stage: an eye mesh (a triangle is enough to populate) whose eye:corneaShell has `targets`, and
    /World/Rig/Shells holding two meshes."""
    stage = Usd.Stage.CreateInMemory()
    for path in ("/World/Eye", "/World/Rig/Shells/A", "/World/Rig/Shells/B"):
        mesh = UsdGeom.Mesh.Define(stage, path)
        mesh.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
        mesh.CreateFaceVertexCountsAttr([3])
        mesh.CreateFaceVertexIndicesAttr([0, 1, 2])
    eye = stage.GetPrimAtPath("/World/Eye")
    eye.ApplyAPI("EyeAPI")
    eye.GetRelationship("eye:corneaShell").SetTargets([Sdf.Path(t) for t in targets])
    return eyerender.RenderSession(stage, width=8)


def test_an_xform_target_leaves_out_every_mesh_under_it():
    session = _eye_with_shells(["/World/Rig/Shells"])
    assert set(session.scene.cornea_shells) == {Sdf.Path("/World/Rig/Shells/A"), Sdf.Path("/World/Rig/Shells/B")}
    assert "/World/Eye" in session.index.rprim_ids()
    assert not any(p.startswith("/World/Rig") for p in session.index.rprim_ids())


def test_a_missing_or_meshless_shell_target_is_one_warning_and_ignored():
    session = _eye_with_shells(["/World/Nowhere", "/World/Eye"])
    assert session.scene.cornea_shells == {}
    assert "/World/Eye" in session.index.rprim_ids()
    assert "/World/Eye: eye:corneaShell target /World/Nowhere does not exist (ignored)" in session.scene.warnings
    assert any("target /World/Eye holds no mesh other than the eye" in w for w in session.scene.warnings)
