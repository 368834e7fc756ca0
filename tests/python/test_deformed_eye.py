"""Deformed, animated eyes through USD: eye:irisProjection resolved relative to the eye, eye:restTime and
primvars:Pref as rest poses, the squash-and-stretch sample refined once and re-evaluated per frame, and its iris
caustic read back in iris texture space with re-projection on and off (docs/deformed_eyes.md)."""
import pathlib

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom

from eyerender import RenderDelegate, RenderIndex, SceneStore
from eyerender._hdeye import write_exr
from eyerender.errors import EyeRenderError
from eyerender.render_session import RenderSession
from eyerender.usd_scene_delegate import UsdSceneDelegate

SAMPLES = pathlib.Path(__file__).resolve().parents[2] / "usd_samples"


class RecordingStore:
    """A SceneStore that also records the primvars and eye params it is sent."""

    def __init__(self):
        self.index = RenderIndex(RenderDelegate())
        self.store = SceneStore(self.index)
        self.primvars, self.eye_params = {}, {}

    def set_primvar(self, prim_id, name, interpolation, values):
        self.primvars[(prim_id, name)] = (interpolation, np.array(values))
        self.store.set_primvar(prim_id, name, interpolation, values)

    def add_eye_mesh(self, prim_id, *args):
        self.eye_params[prim_id] = args[3]
        self.store.add_eye_mesh(prim_id, *args)

    def set_eye_params(self, prim_id, eye):
        self.eye_params[prim_id] = eye
        self.store.set_eye_params(prim_id, eye)

    def __getattr__(self, name):
        return getattr(self.store, name)


def _cube_points(scale=1.0):
    return [Gf.Vec3f(x * scale, y * scale, z * scale) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]


def _eye_stage(points_by_time=None, rest_time=None):
    """/World/Eye (translated) holding an eye mesh /World/Eye/Ball (a cube cage) and /World/Proj (an Xform)."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Xform.Define(stage, "/World")
    eye_xform = UsdGeom.Xform.Define(stage, "/World/Eye")
    eye_xform.AddTranslateOp().Set(Gf.Vec3d(1, 2, 3))
    mesh = UsdGeom.Mesh.Define(stage, "/World/Eye/Ball")
    mesh.GetFaceVertexCountsAttr().Set([4] * 6)
    mesh.GetFaceVertexIndicesAttr().Set([0, 1, 3, 2, 4, 6, 7, 5, 0, 4, 5, 1, 2, 3, 7, 6, 0, 2, 6, 4, 1, 5, 7, 3])
    mesh.GetSubdivisionSchemeAttr().Set("none")
    if points_by_time:
        for t, pts in points_by_time.items():
            mesh.GetPointsAttr().Set(pts, t)
    else:
        mesh.GetPointsAttr().Set(_cube_points())
    prim = mesh.GetPrim()
    prim.AddAppliedSchema("EyeAPI")
    if rest_time is not None:
        prim.CreateAttribute("eye:restTime", Sdf.ValueTypeNames.Double).Set(rest_time)
    proj = UsdGeom.Xform.Define(stage, "/World/Proj")
    proj.AddTranslateOp().Set(Gf.Vec3d(1, 2, 4))
    proj.AddScaleOp().Set(Gf.Vec3f(0.754, 0.754, 0.754))
    return stage, prim


def _populate(stage, time=Usd.TimeCode.Default()):
    store = RecordingStore()
    scene = UsdSceneDelegate(stage, store, time=time, refine_level=0)
    scene.populate()
    return scene, store


def test_iris_projection_is_the_target_frame_relative_to_the_eye():
    stage, prim = _eye_stage()
    prim.CreateRelationship("eye:irisProjection").SetTargets(["/World/Proj"])
    scene, store = _populate(stage)
    eye = store.eye_params["/World/Eye/Ball"]
    assert eye.has_iris_projection
    # Target to world (translate (1, 2, 4), scale 0.754) times the inverse of the eye's (translate (1, 2, 3)):
    # scale 0.754 and translate (0, 0, 1), in USD's row-vector layout (translation in the last row).
    m = np.array(eye.iris_projection).reshape(4, 4)
    expected = np.diag([0.754, 0.754, 0.754, 1.0])
    expected[3, :3] = (0, 0, 1)
    np.testing.assert_allclose(m, expected, atol=1e-6)
    # No relationship: the default (the model frame along the gaze), flagged off.
    stage2, _ = _eye_stage()
    _, store2 = _populate(stage2)
    assert not store2.eye_params["/World/Eye/Ball"].has_iris_projection


def test_an_animated_iris_projection_target_is_pushed_per_frame():
    stage, prim = _eye_stage()
    prim.CreateRelationship("eye:irisProjection").SetTargets(["/World/Proj"])
    op = UsdGeom.Xformable(stage.GetPrimAtPath("/World/Proj")).GetOrderedXformOps()[0]
    op.Set(Gf.Vec3d(1, 2, 4), 1)
    op.Set(Gf.Vec3d(1, 2, 6), 2)
    scene, store = _populate(stage, time=1)
    assert np.array(store.eye_params["/World/Eye/Ball"].iris_projection).reshape(4, 4)[3, 2] == pytest.approx(1)
    updated = scene.set_time(2)
    assert updated["eye"] == 1
    assert np.array(store.eye_params["/World/Eye/Ball"].iris_projection).reshape(4, 4)[3, 2] == pytest.approx(3)


def _refusal(stage, time=Usd.TimeCode.Default()):
    """The one-line error populating `stage` raises: an eye that cannot be rendered is never skipped."""
    with pytest.raises(EyeRenderError) as error:
        _populate(stage, time)
    assert "\n" not in str(error.value) and len(str(error.value)) < 200
    return str(error.value)


def test_a_missing_or_non_xformable_projection_target_is_a_one_line_error():
    stage, prim = _eye_stage()
    prim.CreateRelationship("eye:irisProjection").SetTargets(["/World/Nowhere"])
    assert _refusal(stage) == "/World/Eye/Ball: eye:irisProjection target /World/Nowhere does not exist"
    stage, prim = _eye_stage()
    stage.DefinePrim("/World/Looks", "Scope")
    prim.CreateRelationship("eye:irisProjection").SetTargets(["/World/Looks"])
    assert _refusal(stage).startswith(
        "/World/Eye/Ball: eye:irisProjection target /World/Looks is a Scope, not an Xform or Camera")


def test_rest_time_points_become_the_rest_primvar_and_pref_is_read_as_rest():
    rest, moved = _cube_points(1.0), _cube_points(1.5)
    stage, prim = _eye_stage({1: rest, 2: moved}, rest_time=1)
    scene, store = _populate(stage, time=2)
    interpolation, values = store.primvars[("/World/Eye/Ball", "rest")]
    assert interpolation == "vertex"
    np.testing.assert_allclose(values, np.array(rest, dtype=np.float32))
    # primvars:Pref wins over eye:restTime (an authored rest pose is the artist's).
    stage, prim = _eye_stage({1: rest, 2: moved}, rest_time=2)
    UsdGeom.PrimvarsAPI(prim).CreatePrimvar("Pref", Sdf.ValueTypeNames.Point3fArray, UsdGeom.Tokens.vertex).Set(rest)
    _, store = _populate(stage, time=2)
    np.testing.assert_allclose(store.primvars[("/World/Eye/Ball", "rest")][1], np.array(rest, dtype=np.float32))
    # A rest time whose points do not match is an error naming the attribute.
    stage, prim = _eye_stage({1: rest, 2: moved}, rest_time=1)
    UsdGeom.Mesh(prim).GetPointsAttr().Set(rest[:4], 1)
    assert _refusal(stage, time=2) == "/World/Eye/Ball: eye:restTime = 1 has 4 points, the mesh has 8"


def _uv_texture(path):
    n = 128
    u = np.tile((np.arange(n, dtype=np.float32) + 0.5) / n, (n, 1))
    v = 1 - np.tile(((np.arange(n, dtype=np.float32) + 0.5) / n)[:, None], (1, n))
    write_exr(str(path), [("R", u), ("G", v), ("B", np.ones((n, n), np.float32))])


def _iris_bins(image, bins=8):
    """The irisMnee image binned by the iris texture position each pixel sees: per bin, the median radiance."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    seen = b > 1e-9
    u, v, w = r[seen] / b[seen], g[seen] / b[seen], b[seen]
    i = np.clip((u * bins).astype(int), 0, bins - 1)
    j = np.clip((v * bins).astype(int), 0, bins - 1)
    out, count = np.zeros((bins, bins)), np.zeros((bins, bins))
    for jj in range(bins):
        for ii in range(bins):
            sel = (i == ii) & (j == jj)
            count[jj, ii] = sel.sum()
            out[jj, ii] = np.median(w[sel]) if sel.any() else 0.0
    centres = ((np.arange(bins) + 0.5) / bins - 0.5) * 15.08
    radius = np.hypot(*np.meshgrid(centres, centres))
    return out, count, radius


def _relative_rms(a, ref, count_a, count_ref, radius, inner=2.6, outer=4.4, min_count=3):
    sel = (count_a >= min_count) & (count_ref >= min_count) & (radius >= inner) & (radius <= outer)
    return float(np.sqrt(((a[sel] - ref[sel]) ** 2).sum() / (ref[sel] ** 2).sum())), int(sel.sum())


def test_squash_stretch_sample_refines_once_and_keeps_its_caustic_with_reprojection(tmp_path):
    """The sample's eye (primvars:rest from the asset, points animated over 24 frames, Catmull-Clark level 1)
    seen along its gaze: frames 1 (rest), 7 (stretch 1.5) and 18 (squash 0.67). The caustic read back in iris
    texture space stays the rest frame's with re-projection; with the affine-frame baseline it departs."""
    texture = tmp_path / "uv.exr"
    _uv_texture(texture)
    stage = Usd.Stage.Open(str(SAMPLES / "squash_stretch.usda"))
    # A camera on the eye's gaze axis (session layer): the sample's own camera looks 60 degrees off the gaze,
    # where each pixel's iris radiance also carries the entry Fresnel, which follows the deformed surface's
    # angles by design; head-on it is flat over the inner iris, and what is left is the caustic.
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        gaze = UsdGeom.Camera.Define(stage, "/World/GazeCamera")
        gaze.GetFocalLengthAttr().Set(100.0)
        gaze.GetHorizontalApertureAttr().Set(24.0)
        gaze.GetVerticalApertureAttr().Set(24.0)
        gaze.AddTranslateOp().Set(Gf.Vec3d(0, 0, 8))
    eye_id = "/World/Eye/Eyeball"
    results = {}
    for reprojection in (True, False):
        session = RenderSession(stage, width=80, height=80, aovs=("irisMnee",), refine_level=1,
                                camera="/World/GazeCamera", settings={"sclera_scattering": False, "max_depth": 2},
                                time=1)
        prim = stage.GetPrimAtPath(eye_id)

        def set_eye(t, session=session, prim=prim, reprojection=reprojection):
            eye = session.scene.adapters.eye.mesh_params(prim, Usd.TimeCode(t))
            eye.iris_texture, eye.iris_color, eye.reprojection = str(texture), (1.0, 1.0, 1.0), reprojection
            session.store.set_eye_params(eye_id, eye)

        for frame, seed in ((1, 0), (1, 1), (7, 0), (18, 0)):
            session.scene.set_time(frame)
            set_eye(frame)
            session.delegate.settings.seed = seed
            stats = session.render(spp=12)
            assert stats["non_finite_samples"] == 0
            results[(reprojection, frame, seed)] = _iris_bins(session.image("irisMnee"))
        mesh_stats = session.index.mesh_stats(eye_id)
        # Topology refined once; one stencil evaluation per new pose (populate at frame 1, frames 7 and 18;
        # frame 1 again re-evaluates since its points are time samples).
        assert mesh_stats["refinements"] == 1
        assert mesh_stats["topology_builds"] == 1
        assert mesh_stats["stencil_evaluations"] >= 3

    ref, ref_count, radius = results[(True, 1, 0)]
    ref1, ref1_count, _ = results[(True, 1, 1)]
    noise, _ = _relative_rms(ref1, ref, ref1_count, ref_count, radius)
    report = [f"seed noise {noise:.3f}"]
    for frame in (7, 18):
        on, on_count, _ = results[(True, frame, 0)]
        off, off_count, _ = results[(False, frame, 0)]
        d_on, n_on = _relative_rms(on, ref, on_count, ref_count, radius)
        d_off, n_off = _relative_rms(off, ref, off_count, ref_count, radius)
        report.append(f"frame {frame}: re-projection {d_on:.3f} ({n_on} bins), baseline {d_off:.3f} ({n_off} bins)")
        assert n_on >= 8
        # Noise-aware: 1.5x the seed-to-seed difference plus 0.03 (view-dependent entry Fresnel, pixel footprint).
        assert d_on < 1.5 * noise + 0.03, report
        assert d_off > 2 * noise, report
    print("squash_stretch caustic in iris space: " + "; ".join(report))
