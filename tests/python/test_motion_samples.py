"""Motion samples over a shutter (eyerender.motion) and the shutter's precedence (eyerender.shutter), on stages
authored here: which time codes each moving prim is sampled at, the values USD gives there, static prims kept to
one sample, the sample cap, and bad shutters as one warning and a sharp render."""
import math

import numpy as np
import pytest

pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Usd, UsdGeom, UsdRender  # noqa: E402

import skel_stages  # noqa: E402
from eyerender import motion  # noqa: E402
from eyerender.errors import EyeRenderError  # noqa: E402
from eyerender.instancing import point_instancer_groups  # noqa: E402
from eyerender.shutter import (  # noqa: E402
    SHARP,
    Shutter,
    ShutterOverride,
    parse_shutter_arguments,
    resolve_shutter,
    settings_override,
)
from eyerender.skinning import StageSkinning  # noqa: E402
from eyerender.usd_values import to_float_array  # noqa: E402


def sampler(frame, open_, close, warnings=None):
    return motion.MotionSampler(Usd.TimeCode(frame), Shutter(open_, close, "test"), warnings)


def world(prim):
    return lambda t, cache: cache.GetLocalToWorldTransform(prim)


def translating_cube():
    """A cube translated along x by 0 at frame 1 and 4 at frame 2 (two samples)."""
    stage = Usd.Stage.CreateInMemory()
    cube = UsdGeom.Cube.Define(stage, "/Cube")
    op = cube.AddTranslateOp()
    op.Set(Gf.Vec3d(0, 0, 0), 1)
    op.Set(Gf.Vec3d(4, 0, 0), 2)
    return stage, cube.GetPrim()


def test_translating_cube_is_sampled_at_the_shutter_ends_with_usd_interpolation():
    stage, cube = translating_cube()
    s = motion.transform_samples(sampler(1.5, -0.25, 0.25), cube, world(cube))
    assert s.times.tolist() == [-0.25, 0.25]
    xs = [m[3][0] for m in s.values]
    assert xs == pytest.approx([1.0, 3.0], abs=1e-12), xs


def test_shutter_over_an_authored_sample_includes_it():
    stage, cube = translating_cube()
    # frame 1, shutter [-0.5, 0.5]: [0.5, 1.5] holds the sample at 1; before it USD holds the first value.
    s = motion.transform_samples(sampler(1, -0.5, 0.5), cube, world(cube))
    assert s.times.tolist() == [-0.5, 0.0, 0.5]
    assert [m[3][0] for m in s.values] == pytest.approx([0.0, 0.0, 2.0], abs=1e-12)


def test_rotating_xform_with_three_samples_keeps_each_sample():
    stage = Usd.Stage.CreateInMemory()
    xf = UsdGeom.Xform.Define(stage, "/Turn")
    op = xf.AddRotateYOp()
    for t, angle in ((1, 0.0), (1.5, 30.0), (2, 90.0)):
        op.Set(angle, t)
    child = UsdGeom.Xform.Define(stage, "/Turn/Child").GetPrim()  # the ancestor's samples move the child
    s = motion.transform_samples(sampler(1, 0, 1), child, world(child))
    assert s.times.tolist() == [0.0, 0.5, 1.0]
    angles = [math.degrees(math.atan2(m[0][2], m[0][0])) for m in s.values]  # row 0 is the rotated x axis
    assert [-a for a in angles] == pytest.approx([0.0, 30.0, 90.0], abs=1e-9), angles


def test_a_static_prim_under_a_shutter_is_one_sample():
    stage = Usd.Stage.CreateInMemory()
    xf = UsdGeom.Xform.Define(stage, "/Still")
    xf.AddTranslateOp().Set(Gf.Vec3d(1, 2, 3))
    s = motion.transform_samples(sampler(1, -0.25, 0.25), xf.GetPrim(), world(xf.GetPrim()))
    assert s.static and s.times.tolist() == [-0.25]
    assert s.values[0][3][:3].tolist() == [1, 2, 3]


def test_held_keys_within_the_shutter_are_one_sample():
    stage = Usd.Stage.CreateInMemory()
    xf = UsdGeom.Xform.Define(stage, "/Held")
    op = xf.AddTranslateOp()
    for t in (1, 1.1, 1.2, 5):
        op.Set(Gf.Vec3d(1, 0, 0) if t < 5 else Gf.Vec3d(9, 0, 0), t)
    assert motion.transform_samples(sampler(1.1, -0.1, 0.1), xf.GetPrim(), world(xf.GetPrim())).static


def test_more_samples_than_the_cap_are_resampled_evenly_with_one_warning():
    stage = Usd.Stage.CreateInMemory()
    xf = UsdGeom.Xform.Define(stage, "/Busy")
    op = xf.AddTranslateOp()
    for k in range(41):
        op.Set(Gf.Vec3d(math.sin(k), 0, 0), 1 + k / 40)
    warnings = []
    s = sampler(1, 0, 1, warnings)
    for _ in range(3):  # every frame asks again: one warning
        samples = motion.transform_samples(s, xf.GetPrim(), world(xf.GetPrim()))
    assert len(samples.times) == motion.MAX_SAMPLES_PER_PRIM
    assert np.allclose(np.diff(samples.times), 1 / (motion.MAX_SAMPLES_PER_PRIM - 1))
    assert len(warnings) == 1 and "/Busy" in warnings[0], warnings


def quad_mesh(stage, path="/Quad"):
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    return mesh


def to_points(values, what):
    return to_float_array(values, 3, what)


def test_velocities_only_move_points_linearly_over_the_shutter():
    stage = Usd.Stage.CreateInMemory()
    stage.SetTimeCodesPerSecond(24)
    mesh = quad_mesh(stage)
    # USD applies velocities to time-sampled points (a cache's per-frame samples), about the frame's sample.
    mesh.GetPointsAttr().Set(mesh.GetPointsAttr().Get(), 1)
    mesh.GetVelocitiesAttr().Set([(48, 0, 0)] * 4, 1)  # units per second: 2 units per frame along x
    s = motion.points_samples(sampler(1, -0.25, 0.25), mesh.GetPrim(), 4, to_points)
    assert s.times.tolist() == [-0.25, 0.25]
    offsets = [v[:, 0] - np.array([0, 1, 1, 0]) for v in s.values]
    assert np.allclose(offsets[0], -0.5) and np.allclose(offsets[1], 0.5), offsets


def test_accelerations_bend_the_motion_and_take_uniform_samples():
    stage = Usd.Stage.CreateInMemory()
    stage.SetTimeCodesPerSecond(24)
    mesh = quad_mesh(stage)
    mesh.GetPointsAttr().Set(mesh.GetPointsAttr().Get(), 1)
    mesh.GetVelocitiesAttr().Set([(0, 0, 0)] * 4, 1)
    mesh.GetAccelerationsAttr().Set([(0, 0, 24 * 24 * 2.0)] * 4, 1)  # z = a t^2 / 2 = t_frames^2 units
    s = motion.points_samples(sampler(1, 0, 1), mesh.GetPrim(), 4, to_points)
    # CURVED_MOTION_SAMPLES even times, halved while a chord misses the parabola by more than 1 % of its path: a
    # segment h frames long misses it by h^2 / 4 units halfway, the path is 1 unit, so h = 0.25 (0.0156) is halved.
    assert s.times.tolist() == [i / 8 for i in range(9)]
    z = [float(v[0, 2]) for v in s.values]
    assert z == pytest.approx([t * t for t in s.times], rel=1e-5), z


def test_animated_points_are_sampled_at_their_authored_times():
    stage = Usd.Stage.CreateInMemory()
    mesh = quad_mesh(stage)
    base = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], np.float32)
    for t, dz in ((1, 0.0), (1.25, 1.0), (2, 1.0)):
        mesh.GetPointsAttr().Set([tuple(p + (0, 0, dz)) for p in base], t)
    s = motion.points_samples(sampler(1, 0, 0.5), mesh.GetPrim(), 4, to_points)
    assert s.times.tolist() == [0.0, 0.25, 0.5]
    assert [float(v[0, 2]) for v in s.values] == pytest.approx([0.0, 1.0, 1.0])


def test_a_point_count_that_changes_within_the_shutter_holds_the_frames_points():
    stage = Usd.Stage.CreateInMemory()
    mesh = quad_mesh(stage)
    mesh.GetPointsAttr().Set([(0, 0, 0)] * 4, 1)
    mesh.GetPointsAttr().Set([(1, 0, 0)] * 5, 1.5)
    s = motion.points_samples(sampler(1, 0, 1), mesh.GetPrim(), 4, to_points)  # USD holds the base sample
    assert s.static and np.array_equal(s.values[0], np.zeros((4, 3), np.float32))
    with pytest.raises(EyeRenderError, match="4 points at time 1"):  # a mesh built for another count
        motion.points_samples(sampler(1, 0, 1), mesh.GetPrim(), 5, to_points)


def test_a_nan_point_sample_inside_the_shutter_is_an_error_naming_the_prim():
    stage = Usd.Stage.CreateInMemory()
    mesh = quad_mesh(stage)
    mesh.GetPointsAttr().Set([(0, 0, 0)] * 4, 1)
    mesh.GetPointsAttr().Set([(math.nan, 0, 0)] * 4, 1.2)
    with pytest.raises(EyeRenderError, match="/Quad: points at time 1.2"):
        motion.points_samples(sampler(1, 0, 0.5), mesh.GetPrim(), 4, to_points)


def test_skinned_strip_is_skinned_at_each_animation_sample_in_the_shutter():
    stage = skel_stages.two_joint_strip(bend=60.0)  # the tip turns 0 / 30 / 60 degrees at frames 1 / 2 / 3
    skinning = StageSkinning([])
    skinning.add_root(stage.GetPrimAtPath("/World/Rig"))
    skinned = skinning.get(stage.GetPrimAtPath("/World/Rig/Strip"))
    s = sampler(2, -0.5, 1.0)
    samples = motion.skinned_points_samples(s, skinned, lambda t, cache: skinned.points(Usd.TimeCode(t), cache))
    # The animation's samples (frames 2 and 3) and the shutter's open, then halfway times where the tip's arc leaves
    # the straight line between samples (refined: 15 degrees over the first half frame, 30 over the next frame).
    assert samples.times.tolist() == [-0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 1.0]
    tip = [v[-2] for v in samples.values]  # the strip's end point, (2, 0, 0) at the bind pose
    for t, p in zip(2 + samples.times, tip):
        angle = math.radians(60.0 * (t - 1) / 2)  # UsdSkel slerps the joint rotation between samples
        expected = (1 + math.cos(angle), math.sin(angle))
        assert (p[0], p[1]) == pytest.approx(expected, abs=1e-5), (t, p)


def test_point_instancer_with_animated_positions_gives_instance_samples():
    stage = Usd.Stage.CreateInMemory()
    pi = UsdGeom.PointInstancer.Define(stage, "/Instancer")
    UsdGeom.Cube.Define(stage, "/Instancer/Protos/Box")
    pi.CreatePrototypesRel().SetTargets(["/Instancer/Protos/Box"])
    pi.CreateProtoIndicesAttr([0, 0])
    pi.GetPositionsAttr().Set([(0, 0, 0), (0, 5, 0)], 1)
    pi.GetPositionsAttr().Set([(2, 0, 0), (2, 5, 0)], 2)
    prim = pi.GetPrim()
    s = sampler(1.5, -0.5, 0.5)
    authored, curved = motion.instancer_times([prim], s.interval())
    times = s.times(authored, prim.GetPath(), uniform=curved)

    def groups_at(t, cache):
        return {g.instancer_id: np.array([np.array(m).reshape(4, 4) for m in g.worlds]) for g in
                point_instancer_groups(prim, [cache.GetLocalToWorldTransform(prim)], Usd.TimeCode(t), cache,
                                       base_time=Usd.TimeCode(1.5))}

    samples = motion.instance_samples(s, prim.GetPath(), times, groups_at)
    (group,) = samples.values()
    assert group.times.tolist() == [-0.5, 0.5] and group.values[0].shape == (2, 4, 4)
    assert [float(v[1, 3, 0]) for v in group.values] == pytest.approx([0.0, 2.0])
    assert [float(v[1, 3, 1]) for v in group.values] == pytest.approx([5.0, 5.0])


def test_point_instancer_velocities_extrapolate_from_the_frame():
    stage = Usd.Stage.CreateInMemory()
    stage.SetTimeCodesPerSecond(24)
    pi = UsdGeom.PointInstancer.Define(stage, "/Instancer")
    UsdGeom.Cube.Define(stage, "/Instancer/Protos/Box")
    pi.CreatePrototypesRel().SetTargets(["/Instancer/Protos/Box"])
    pi.CreateProtoIndicesAttr([0])
    pi.GetPositionsAttr().Set([(1, 0, 0)], 3)
    pi.GetVelocitiesAttr().Set([(0, 24, 0)], 3)  # 1 unit per frame along y
    prim = pi.GetPrim()
    s = sampler(3, -0.25, 0.25)
    authored, curved = motion.instancer_times([prim], s.interval())
    assert not curved
    worlds = [list(point_instancer_groups(prim, [Gf.Matrix4d(1)], Usd.TimeCode(t), s.cache(t),
                                          base_time=Usd.TimeCode(3)))[0].worlds[0] for t in s.times(authored, "/I")]
    assert [w[3][1] for w in worlds] == pytest.approx([-0.25, 0.25])


# -- the shutter ---------------------------------------------------------------------------------------------

def camera_stage(open_=-0.25, close=0.25):
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/Cam")
    cam.CreateShutterOpenAttr(open_)
    cam.CreateShutterCloseAttr(close)
    return stage, cam.GetPrim()


def render_settings(stage, disable=None, instantaneous=None, product_disable=None):
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    if disable is not None:
        settings.CreateDisableMotionBlurAttr(disable)
    if instantaneous is not None:
        settings.CreateInstantaneousShutterAttr(instantaneous)
    product = UsdRender.Product.Define(stage, "/Render/Product")
    settings.CreateProductsRel().SetTargets([product.GetPath()])
    if product_disable is not None:
        product.CreateDisableMotionBlurAttr(product_disable)
    return "/Render/Settings"


def test_the_camera_authors_the_shutter():
    stage, cam = camera_stage()
    shutter = resolve_shutter(cam, Usd.TimeCode(1))
    assert (shutter.open, shutter.close, shutter.blurred) == (-0.25, 0.25, True)
    assert "camera /Cam" in shutter.describe()


def test_an_unauthored_shutter_is_sharp():
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/Cam").GetPrim()
    assert not resolve_shutter(cam, Usd.TimeCode(1)).blurred


def test_render_settings_disable_motion_blur_wins_over_the_camera():
    stage, cam = camera_stage()
    override = settings_override(stage, render_settings(stage, disable=True))
    shutter = resolve_shutter(cam, Usd.TimeCode(1), override)
    assert (shutter.open, shutter.close) == (0.0, 0.0) and "disableMotionBlur" in shutter.source


def test_instantaneous_shutter_closes_at_the_open():
    stage, cam = camera_stage(0.1, 0.5)
    shutter = resolve_shutter(cam, Usd.TimeCode(1), settings_override(stage, render_settings(stage,
                                                                                          instantaneous=True)))
    assert (shutter.open, shutter.close, shutter.blurred) == (0.1, 0.1, False)


def test_a_products_authored_value_wins_over_its_settings():
    stage, cam = camera_stage()
    override = settings_override(stage, render_settings(stage, disable=True, product_disable=False))
    assert resolve_shutter(cam, Usd.TimeCode(1), override).blurred


def test_the_command_line_shutter_wins_over_settings_and_camera():
    stage, cam = camera_stage()
    override = settings_override(stage, render_settings(stage, disable=True), interval=(-0.5, 0.0))
    shutter = resolve_shutter(cam, Usd.TimeCode(1), override)
    assert (shutter.open, shutter.close, shutter.source) == (-0.5, 0.0, "--shutter")
    assert not resolve_shutter(cam, Usd.TimeCode(1), ShutterOverride(interval=(0.0, 0.0))).blurred


def test_the_default_time_is_sharp_whatever_the_shutter():
    stage, cam = camera_stage()
    assert resolve_shutter(cam, Usd.TimeCode.Default(), ShutterOverride(interval=(-1.0, 1.0))) == SHARP


@pytest.mark.parametrize("open_, close", [(math.nan, 0.25), (0.5, -0.5), (0.0, math.inf), (-50.0, 0.0)])
def test_a_bad_camera_shutter_is_one_warning_and_sharp(open_, close):
    stage, cam = camera_stage(open_, close)
    warnings = []
    shutter = resolve_shutter(cam, Usd.TimeCode(1), None, warnings)
    assert shutter == SHARP and len(warnings) == 1 and warnings[0].startswith("/Cam: shutter"), warnings


def test_shutter_arguments():
    assert parse_shutter_arguments(None) is None
    assert parse_shutter_arguments([0.0]) == (0.0, 0.0)
    assert parse_shutter_arguments([-0.25, 0.25]) == (-0.25, 0.25)
    assert parse_shutter_arguments(None, disable_motion_blur=True) == (0.0, 0.0)
    for bad in ([0.5], [1.0, 0.0], [math.nan, 0.0], [0.0, 20.0], [0.0, 0.1, 0.2]):
        with pytest.raises(EyeRenderError, match="--shutter"):
            parse_shutter_arguments(bad)
    with pytest.raises(EyeRenderError, match="contradict"):
        parse_shutter_arguments([0.0, 0.5], disable_motion_blur=True)
