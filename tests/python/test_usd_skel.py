"""UsdSkel through the scene delegate: skinned points and transforms as usd-core's UsdSkel computes them (and as
UsdSkel.BakeSkinning bakes them), blend shapes, rigid bindings, eyes on a head joint, what a skinning-only frame
re-syncs, and bad skeleton data (one warning, the prim unskinned)."""
import math

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdSkel  # noqa: E402

import skel_stages as ss  # noqa: E402
from eyerender import RenderSession  # noqa: E402
from eyerender.skinning import transform_points  # noqa: E402
from eyerender.usd_scene_delegate import UsdSceneDelegate  # noqa: E402

DIRTY_POINTS, DIRTY_TRANSFORM = 1 << 1, 1 << 3  # delegate/hdeye/changeTracker.h


class RecordingStore:
    """A SceneStore that also keeps the last points, transform and primvars sent per prim."""

    def __init__(self):
        self.index = eyerender.RenderIndex(eyerender.RenderDelegate())
        self.store = eyerender.SceneStore(self.index)
        self.points, self.transforms, self.primvars = {}, {}, {}

    def __getattr__(self, name):
        return getattr(self.store, name)

    def add_mesh(self, prim_id, counts, indices, points, transform, *args, **kwargs):
        self.points[prim_id], self.transforms[prim_id] = np.array(points), np.array(transform)
        return self.store.add_mesh(prim_id, counts, indices, points, transform, *args, **kwargs)

    def add_eye_mesh(self, prim_id, counts, indices, points, eye, transform, *args):
        self.points[prim_id], self.transforms[prim_id] = np.array(points), np.array(transform)
        return self.store.add_eye_mesh(prim_id, counts, indices, points, eye, transform, *args)

    def add_analytic_eye(self, prim_id, eye, transform):
        self.transforms[prim_id] = np.array(transform)
        return self.store.add_analytic_eye(prim_id, eye, transform)

    def add_camera(self, prim_id, params, transform):
        self.transforms[prim_id] = np.array(transform)
        return self.store.add_camera(prim_id, params, transform)

    def set_points(self, prim_id, points):
        self.points[prim_id] = np.array(points)
        return self.store.set_points(prim_id, points)

    def set_transform(self, prim_id, transform):
        self.transforms[prim_id] = np.array(transform)
        return self.store.set_transform(prim_id, transform)

    def set_primvar(self, prim_id, name, interpolation, values):
        self.primvars[(prim_id, name)] = np.array(values)
        return self.store.set_primvar(prim_id, name, interpolation, values)


def delegate(stage, time=1):
    store = RecordingStore()
    scene = UsdSceneDelegate(stage, store, time=time)
    scene.populate()
    return scene, store


def render(stage, time, width=48, height=32, spp=4):
    session = RenderSession(stage, width=width, height=height, time=time)
    session.render(spp=spp)
    return session.image("color")


def points_at(stage, path, time):
    return np.array(UsdGeom.Mesh(stage.GetPrimAtPath(path)).GetPointsAttr().Get(time), dtype=np.float32)


def matrix(m):
    return np.array(m, dtype=np.float64).reshape(4, 4)


def test_transform_points_rounds_as_gf_matrix4d_transform():
    m = Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(1, 2, 3), 37)) * Gf.Matrix4d().SetTranslate(Gf.Vec3d(0.1, 2, -3))
    points = np.random.default_rng(1).normal(size=(200, 3)).astype(np.float32)
    ours = transform_points(points, m)
    gf = np.array([m.Transform(Gf.Vec3f(*map(float, p))) for p in points], dtype=np.float32)
    assert np.array_equal(ours, gf), np.abs(ours - gf).max()


def test_two_joint_strip_points_are_the_baked_points_at_every_frame():
    stage = ss.two_joint_strip()
    baked = ss.baked_copy(stage)
    scene, store = delegate(stage)
    for t in (1, 2, 3):
        scene.set_time(t)
        expected = points_at(baked, "/World/Rig/Strip", t)
        got = store.points["/World/Rig/Strip"]
        assert np.array_equal(got, expected), f"frame {t}: worst {np.abs(got - expected).max()}"
    # The tip column moved: frame 3 bends the tip joint by 60 degrees about (1, 0, 0).
    tip = store.points["/World/Rig/Strip"][-2]
    assert np.allclose(tip, [1 + math.cos(math.radians(60)), math.sin(math.radians(60)), 0], atol=1e-6), tip


def test_two_joint_strip_renders_pixel_identical_to_its_baked_copy():
    stage = ss.two_joint_strip()
    baked = ss.baked_copy(stage)
    session = RenderSession(stage, width=48, height=32, time=1)
    images = []
    for t in (1, 3):
        session.render(time=t, spp=4)
        ours, theirs = session.image("color"), render(baked, t)
        assert np.array_equal(ours, theirs), f"frame {t}: worst pixel difference {np.abs(ours - theirs).max()}"
        images.append(ours)
    assert np.abs(images[0] - images[1]).max() > 0.05  # the bend shows


def test_dual_quaternion_skinning_blends_rotations_not_positions():
    lbs_scene, lbs = delegate(ss.two_joint_strip("classicLinear"), time=3)
    dq_stage = ss.two_joint_strip("dualQuaternion")
    dq_scene, dq = delegate(dq_stage, time=3)
    assert np.array_equal(dq.points["/World/Rig/Strip"], points_at(ss.baked_copy(dq_stage), "/World/Rig/Strip", 3))
    # The top point over the tip joint (x = 1, y = 0.4) carries weights 0.5 / 0.5: dual quaternions turn it by
    # half the 60 degree bend about the joint; linear blending averages the two rigid positions (it shrinks).
    top = 9
    half = math.radians(30)
    assert np.allclose(dq.points["/World/Rig/Strip"][top], [1 - 0.4 * math.sin(half), 0.4 * math.cos(half), 0],
                       atol=1e-6), dq.points["/World/Rig/Strip"][top]
    full = math.radians(60)
    assert np.allclose(lbs.points["/World/Rig/Strip"][top],
                       [(1 + 1 - 0.4 * math.sin(full)) / 2, (0.4 + 0.4 * math.cos(full)) / 2, 0], atol=1e-6)


@pytest.mark.parametrize("joints", [True, False], ids=["with joints", "a skeleton of no joints"])
def test_blend_shapes_and_inbetweens_move_points_as_usdskel_says(joints):
    stage = ss.blend_shape_strip(joints)
    baked = ss.baked_copy(stage)
    scene, store = delegate(stage)
    rest = points_at(stage, "/World/Rig/Strip", 1)
    for t, lift in ((1, (0, 0, 0)), (2, (0, 0, 0.4)), (3, (0, 0, 0.5))):  # frame 2: weight 0.5 is the in-between
        scene.set_time(t)
        got = store.points["/World/Rig/Strip"]
        assert np.allclose(got[-1] - rest[-1], lift, atol=1e-7), (t, got[-1])
        assert np.array_equal(got[:-2], rest[:-2])
        assert np.array_equal(got, points_at(baked, "/World/Rig/Strip", t))


def test_rigidly_bound_eye_follows_the_head_joint_by_transform_alone():
    stage = ss.eye_on_head(rigid=True)
    scene, store = delegate(stage)
    eye = "/World/Rig/Eye"
    authored = points_at(stage, eye, 1)
    cache = UsdSkel.Cache()
    cache.Populate(UsdSkel.Root(stage.GetPrimAtPath("/World/Rig")), Usd.PrimDefaultPredicate)
    skel_query = cache.GetSkelQuery(UsdSkel.Skeleton(stage.GetPrimAtPath("/World/Rig/Skel")))
    geom_bind = UsdSkel.BindingAPI(stage.GetPrimAtPath(eye)).GetGeomBindTransformAttr().Get()
    bind_head = skel_query.GetJointWorldBindTransforms()[1]
    for t in (2, 3):
        store.index.sync_all()
        counts = scene.set_time(t)
        assert dict(counts) == {"skinned transform": 1}, counts
        head_world = skel_query.ComputeJointWorldTransforms(UsdGeom.XformCache(t))[1]
        expected = matrix(geom_bind * bind_head.GetInverse() * head_world)
        assert np.allclose(store.transforms[eye], expected, atol=1e-12), (store.transforms[eye], expected)
        assert np.array_equal(store.points[eye], authored)  # rigid: the points (and the iris projection) stay
        assert store.index.dirty_bits(eye) == DIRTY_TRANSFORM
    # The head turned 40 degrees about y: the eye's gaze (+z) turned with it.
    gaze = Gf.Vec3d(*store.transforms[eye][2, :3]).GetNormalized()
    assert abs(math.degrees(math.acos(gaze[2])) - 40) < 1e-5, gaze  # quatf rotations


def test_rigidly_bound_eye_renders_pixel_identical_to_its_baked_copy():
    stage = ss.eye_on_head(rigid=True)
    baked = ss.baked_copy(stage)
    ours, theirs = render(stage, 3), render(baked, 3)
    assert np.array_equal(ours, theirs), np.abs(ours - theirs).max()
    assert np.abs(ours - render(stage, 1)).max() > 0.02  # the eye moved


def test_eye_skinned_per_vertex_keeps_its_frame_on_the_joint_and_rests_in_bind_pose():
    stage = ss.eye_on_head(rigid=False)
    scene, store = delegate(stage)
    eye = "/World/Rig/Eye"
    authored = points_at(stage, eye, 1)
    assert np.array_equal(store.primvars[(eye, "rest")], authored)  # rest pose = bind pose
    rigid_scene, rigid = delegate(ss.eye_on_head(rigid=True))
    for t in (2, 3):
        counts = scene.set_time(t)
        rigid_scene.set_time(t)
        assert dict(counts) == {"skinned points": 1, "skinned transform": 1}, counts
        # All weight on the head joint: the frame is the rigid binding's, and the points stay the bind points.
        assert np.allclose(store.transforms[eye], rigid.transforms[eye], atol=1e-12)
        assert np.abs(store.points[eye] - authored).max() < 1e-6


def test_eye_rest_time_picks_the_skinned_pose_at_that_time():
    stage = ss.eye_on_head(rigid=False)
    eye = stage.GetPrimAtPath("/World/Rig/Eye")
    count = len(UsdGeom.Mesh(eye).GetPointsAttr().Get())
    # Half of the weight on the root joint: turning the head shears the eye, so the skinned pose differs from bind.
    api = UsdSkel.BindingAPI(eye)
    api.CreateJointIndicesPrimvar(False, 2).Set([0, 1] * count)
    api.CreateJointWeightsPrimvar(False, 2).Set([0.5, 0.5] * count)
    eye.CreateAttribute("eye:restTime", Sdf.ValueTypeNames.Double).Set(3.0)
    scene, store = delegate(stage, time=3)
    rest, points = store.primvars[("/World/Rig/Eye", "rest")], store.points["/World/Rig/Eye"]
    assert np.array_equal(rest, points)  # at eye:restTime the eye is undeformed relative to its rest pose
    assert np.abs(rest - points_at(stage, "/World/Rig/Eye", 1)).max() > 1e-3


def test_analytic_eye_xform_bound_to_a_joint_moves_with_it_and_so_do_its_children():
    stage, skel = ss.head_rig()
    xform = UsdGeom.Xform.Define(stage, "/World/Rig/EyeL")
    xform.GetPrim().AddAppliedSchema("EyeAPI")
    geom_bind = ss.translate(0.3, 1.2, 0.4)
    xform.AddTransformOp().Set(geom_bind)
    ss.bind(xform.GetPrim(), skel, [1], [1.0], 1, constant=True, geom_bind=geom_bind)
    # A gprim (or light: boundable too) below inherits the constant joint influences and UsdSkel skins it with its
    # own geomBindTransform; a camera below is not skinnable and follows the Xform.
    lid = ss.strip_mesh(stage, "/World/Rig/EyeL/lid", segments=2, length=0.2, height=0.1)
    lid.AddTranslateOp().Set(Gf.Vec3d(0, 0.2, 0))
    UsdSkel.BindingAPI.Apply(lid.GetPrim()).CreateGeomBindTransformAttr(ss.translate(0, 0.2, 0) * geom_bind)
    UsdGeom.Camera.Define(stage, "/World/Rig/EyeL/eyeCam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 0.5))
    scene, store = delegate(stage)
    counts = scene.set_time(3)
    assert counts == {"skinned transform": 3}, counts
    turn = Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), 40))
    expected = geom_bind * ss.translate(0, -1, 0) * turn * ss.translate(0, 1, 0)
    assert np.allclose(store.transforms["/World/Rig/EyeL"], matrix(expected), atol=1e-6)
    assert np.allclose(store.transforms["/World/Rig/EyeL/lid"], matrix(ss.translate(0, 0.2, 0) * expected), atol=1e-6)
    assert np.allclose(store.transforms["/World/Rig/EyeL/eyeCam"], matrix(ss.translate(0, 0, 0.5) * expected),
                       atol=1e-6)


def test_skinning_only_frame_is_a_points_only_sync():
    stage = ss.two_joint_strip()
    session = RenderSession(stage, width=32, height=24, time=1)
    session.render(spp=1)
    strip = "/World/Rig/Strip"
    before = session.index.mesh_stats(strip)
    counts = session.scene.set_time(2)
    assert dict(counts) == {"skinned points": 1}, counts
    assert session.index.dirty_bits(strip) == DIRTY_POINTS
    session.render(spp=1)
    after = session.index.mesh_stats(strip)
    delta = {k: after[k] - before[k] for k in before}
    assert delta["point_uploads"] == 1 and delta["topology_builds"] == 0 and delta["refinements"] == 0, delta
    assert delta["transform_updates"] == 0, delta


def test_static_skinned_stage_resyncs_nothing_when_time_moves():
    stage = ss.two_joint_strip(bend=0.0)
    UsdSkel.Animation(stage.GetPrimAtPath("/World/Rig/Skel/Anim")).GetRotationsAttr().Clear()
    UsdSkel.Animation(stage.GetPrimAtPath("/World/Rig/Skel/Anim")).GetRotationsAttr().Set([Gf.Quatf(1)] * 2)
    scene, _ = delegate(stage)
    assert dict(scene.set_time(2)) == {}


def _break_joint_counts(stage):
    UsdSkel.Skeleton(stage.GetPrimAtPath("/World/Rig/Skel")).GetBindTransformsAttr().Set([Gf.Matrix4d(1)])


def _nan_weights(stage):
    api = UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip"))
    weights = list(api.GetJointWeightsPrimvar().Get())
    weights[3] = float("nan")
    api.GetJointWeightsPrimvar().Set(weights)


def _singular_geom_bind(stage):
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip")).GetGeomBindTransformAttr().Set(
        Gf.Matrix4d().SetScale(Gf.Vec3d(1, 0, 1)))


def _nan_geom_bind(stage):
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip")).GetGeomBindTransformAttr().Set(
        Gf.Matrix4d(float("nan")))


def _joint_index_out_of_range(stage):
    api = UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip"))
    indices = list(api.GetJointIndicesPrimvar().Get())
    indices[5] = 7
    api.GetJointIndicesPrimvar().Set(indices)


def _too_few_influences(stage):
    api = UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip"))
    api.GetJointIndicesPrimvar().Set(list(api.GetJointIndicesPrimvar().Get())[:-2])
    api.GetJointWeightsPrimvar().Set(list(api.GetJointWeightsPrimvar().Get())[:-2])


def _unknown_joint_name(stage):
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip")).CreateJointsAttr(["root", "root/nose"])


def _few_translations(stage):
    UsdSkel.Animation(stage.GetPrimAtPath("/World/Rig/Skel/Anim")).GetTranslationsAttr().Set([Gf.Vec3f(0)])


def _element_sizes_differ(stage):
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip")).GetJointIndicesPrimvar().SetElementSize(3)


def _unknown_method(stage):
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip")).GetSkinningMethodAttr().Set("bogus")


def _skeleton_is_a_mesh(stage):
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Strip")).GetSkeletonRel().SetTargets(["/World/Rig/Strip"])


@pytest.mark.parametrize("corrupt,message", [
    (_few_translations, "animation /World/Rig/Skel/Anim has 1 translations for 2 joints"),
    (_element_sizes_differ, "jointIndices / jointWeights are not usable by UsdSkel (elementSize 3 / 2"),
    (_unknown_method, "skel:skinningMethod 'bogus' is not classicLinear or dualQuaternion"),
    (_skeleton_is_a_mesh, "has joint influences but skel:skeleton /World/Rig/Strip is not a Skeleton"),
    (_break_joint_counts, "1 bindTransforms for 2 joints"),
    (_nan_weights, "jointWeights hold NaN"),
    (_singular_geom_bind, "geomBindTransform is singular"),
    (_nan_geom_bind, "geomBindTransform is singular or not finite"),
    (_joint_index_out_of_range, "jointIndices refer to joints outside [0, 2)"),
    (_too_few_influences, "34 jointIndices for 18 points x 2 influences"),
    (_unknown_joint_name, "skel:joints names 'root/nose'"),
])
def test_bad_skel_data_warns_once_and_renders_unskinned(corrupt, message):
    stage = ss.two_joint_strip()
    corrupt(stage)
    session = RenderSession(stage, width=16, height=12, time=3)
    session.render(spp=1)
    warnings = [w for w in session.scene.warnings if "Strip" in w or "Skel" in w]
    assert len(warnings) == 1 and warnings[0].startswith("/World/Rig/Strip: ") and message in warnings[0], warnings
    assert warnings[0].endswith("(rendered unskinned)")
    scene, store = delegate(stage, time=3)
    assert np.array_equal(store.points["/World/Rig/Strip"], points_at(stage, "/World/Rig/Strip", 3))
    assert dict(scene.set_time(2)) == {}


def _shape(stage):
    return UsdSkel.BlendShape(stage.GetPrimAtPath("/World/Rig/Strip/lift"))


@pytest.mark.parametrize("corrupt,message", [
    (lambda st: _shape(st).GetPointIndicesAttr().Set([0, 999]), "has point indices outside [0, 18)"),
    (lambda st: _shape(st).GetOffsetsAttr().Set([(0, 0, 1)]), "has 1 offsets for 2 point indices"),
    (lambda st: UsdSkel.BindingAPI(st.GetPrimAtPath("/World/Rig/Strip")).GetBlendShapeTargetsRel().SetTargets(
        ["/World/Nothing"]), "skel:blendShapeTargets /World/Nothing is not a BlendShape"),
    (lambda st: UsdSkel.Animation(st.GetPrimAtPath("/World/Rig/Skel/Anim")).GetBlendShapeWeightsAttr().Set(
        [1.0, 2.0], 2), "has 2 blendShapeWeights for 1 blendShapes at time 2"),
], ids=["indices", "offsets", "target", "weights"])
def test_bad_blend_shapes_warn_once_and_render_unskinned(corrupt, message):
    stage = ss.blend_shape_strip()
    corrupt(stage)
    scene, store = delegate(stage, time=1)
    for t in (2, 3):
        scene.set_time(t)
    assert len(scene.warnings) == 1 and scene.warnings[0].startswith("/World/Rig/Strip: ") and \
        message in scene.warnings[0], scene.warnings
    assert np.array_equal(store.points["/World/Rig/Strip"], points_at(stage, "/World/Rig/Strip", 3))


def test_missing_animation_source_leaves_the_skeleton_in_rest_pose_with_one_warning():
    stage = ss.two_joint_strip()
    UsdSkel.BindingAPI(stage.GetPrimAtPath("/World/Rig/Skel")).GetAnimationSourceRel().SetTargets(["/World/Nothing"])
    session = RenderSession(stage, width=16, height=12, time=3)
    session.render(spp=1)
    assert session.scene.warnings == ["/World/Rig/Skel: skel:animationSource /World/Nothing is not a SkelAnimation "
                                      "(the skeleton stays in its rest pose)"], session.scene.warnings
    scene, store = delegate(stage, time=3)
    assert np.allclose(store.points["/World/Rig/Strip"], points_at(stage, "/World/Rig/Strip", 3), atol=1e-6)


def test_non_finite_animation_at_a_later_frame_warns_and_falls_back_to_the_bind_pose():
    stage = ss.two_joint_strip()
    anim = UsdSkel.Animation(stage.GetPrimAtPath("/World/Rig/Skel/Anim"))
    anim.GetRotationsAttr().Set([Gf.Quatf(1), Gf.Quatf(float("nan"), 0, 0, 0)], 3)
    scene, store = delegate(stage, time=2)
    assert scene.warnings == []
    scene.set_time(3)
    assert len(scene.warnings) == 1 and scene.warnings[0].startswith("/World/Rig/Strip: "), scene.warnings
    assert np.array_equal(store.points["/World/Rig/Strip"], points_at(stage, "/World/Rig/Strip", 3))
    scene.set_time(2)  # dropped for good: no second warning, still unskinned
    assert len(scene.warnings) == 1


def test_skinned_polygon_mesh_normals_are_skinned_as_bake_skinning_does():
    stage = ss.two_joint_strip()
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Rig/Strip"))
    count = len(mesh.GetPointsAttr().Get())
    mesh.CreateNormalsAttr([Gf.Vec3f(0.3, 0.1, 1).GetNormalized()] * count)
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    baked = ss.baked_copy(stage)
    scene, store = delegate(stage)
    assert scene.warnings == []
    for t in (1, 3):
        scene.set_time(t)
        ours = store.primvars[("/World/Rig/Strip", "normals")]
        theirs = np.array(UsdGeom.Mesh(baked.GetPrimAtPath("/World/Rig/Strip")).GetNormalsAttr().Get(t), np.float32)
        assert np.array_equal(ours, theirs), (t, np.abs(ours - theirs).max())
    tip = store.primvars[("/World/Rig/Strip", "normals")][-1]  # turned 60 degrees about z with the tip joint
    turned = Gf.Rotation(Gf.Vec3d(0, 0, 1), 60).TransformDir(Gf.Vec3d(0.3, 0.1, 1).GetNormalized())
    assert np.allclose(tip, turned, atol=1e-6), (tip, turned)
    ours, theirs = render(stage, 3), render(baked, 3)
    assert np.array_equal(ours, theirs), np.abs(ours - theirs).max()


def test_face_varying_and_primvar_normals_follow_their_points_joints():
    normal = Gf.Vec3f(0.3, 0.1, 1).GetNormalized()
    vertex_stage = ss.two_joint_strip()
    mesh = UsdGeom.Mesh(vertex_stage.GetPrimAtPath("/World/Rig/Strip"))
    mesh.CreateNormalsAttr([normal] * len(mesh.GetPointsAttr().Get()))
    corner_stage = ss.two_joint_strip()
    corners = UsdGeom.Mesh(corner_stage.GetPrimAtPath("/World/Rig/Strip")).GetFaceVertexIndicesAttr().Get()
    primvar = UsdGeom.PrimvarsAPI(corner_stage.GetPrimAtPath("/World/Rig/Strip")).CreatePrimvar(
        "normals", Sdf.ValueTypeNames.Normal3fArray, UsdGeom.Tokens.faceVarying)
    primvar.Set([normal] * len(corners))
    (vertex_scene, by_vertex), (corner_scene, by_corner) = delegate(vertex_stage, 3), delegate(corner_stage, 3)
    assert vertex_scene.warnings == corner_scene.warnings == []
    per_point = by_vertex.primvars[("/World/Rig/Strip", "normals")]
    per_corner = by_corner.primvars[("/World/Rig/Strip", "normals")]
    assert np.array_equal(per_corner, per_point[np.asarray(corners)])


@pytest.mark.parametrize("scheme,warned", [("none", True), ("catmullClark", False)])
def test_uniform_normals_of_a_skinned_polygon_mesh_give_way_to_smooth_normals_with_one_warning(scheme, warned):
    stage = ss.two_joint_strip()
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Rig/Strip"))
    mesh.CreateSubdivisionSchemeAttr(scheme)
    mesh.CreateNormalsAttr([(0, 0, 1)] * len(mesh.GetFaceVertexCountsAttr().Get()))
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.uniform)
    scene, store = delegate(stage, time=3)
    expected = ["/World/Rig/Strip: uniform normals cannot follow per-vertex skinning (rendered with smooth "
                "normals)"] if warned else []
    assert scene.warnings == expected
    # Stale normals never reach a polygon mesh; a refined mesh gets them as before (the delegate ignores them).
    assert (("/World/Rig/Strip", "normals") in store.primvars) == (scheme != "none")


def test_point_instanced_copies_of_a_skinned_mesh_render_unskinned_with_one_warning():
    stage = ss.two_joint_strip()
    instancer = UsdGeom.PointInstancer.Define(stage, "/World/Crowd")
    instancer.CreatePrototypesRel().SetTargets(["/World/Rig"])
    instancer.CreatePositionsAttr([(0, 0, 0), (0, 1, 0)])
    instancer.CreateProtoIndicesAttr([0, 0])
    scene, store = delegate(stage, time=3)
    assert scene.warnings == ["/World/Rig/Strip: instanced copies of a skinned mesh render unskinned"]
    copy = "/World/Crowd/__prototype0/Rig/Strip"  # the shared prototype prim both instances draw
    assert np.array_equal(store.points[copy], points_at(stage, "/World/Rig/Strip", 3))
    assert not np.array_equal(store.points["/World/Rig/Strip"], store.points[copy])
