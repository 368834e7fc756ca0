"""RenderSession follows its stage: edits made from Python after the session was built (Usd.Notice.ObjectsChanged)
are seen by the next render, through the dirty bits they need: added and removed prims re-populate, value
changes update in place. Every case renders exactly as a session built fresh on the edited stage."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, UsdGeom, UsdLux, UsdSkel  # noqa: E402

import skel_stages as ss  # noqa: E402
from eyerender import RenderSession  # noqa: E402

DIRTY_POINTS, DIRTY_TRANSFORM, DIRTY_PARAMS = 1 << 1, 1 << 3, 1 << 6  # delegate/hdeye/changeTracker.h


def card(stage, path, x=0.0, purpose=None):
    mesh = ss.strip_mesh(stage, path, segments=2, length=1.5, height=1.0)
    mesh.AddTranslateOp().Set(Gf.Vec3d(x, 0, 0))
    if purpose:
        mesh.CreatePurposeAttr(purpose)
    return mesh


def session(stage, time=1):
    return RenderSession(stage, width=40, height=30, time=time)


def frame(s, time=None):
    s.render(time=time, spp=2)
    return s.image("color")


def assert_same_as_fresh(s, stage, time=None):
    ours = frame(s, time)
    fresh = frame(session(stage, time if time is not None else 1))
    assert np.array_equal(ours, fresh), f"worst pixel difference {np.abs(ours - fresh).max()}"
    return ours


def test_light_moved_after_the_session_was_built_is_seen_in_the_next_render():
    stage = ss.base_stage()
    card(stage, "/World/card")
    s = session(stage)
    before = frame(s)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/key")).GetOrderedXformOps()[0].Set(Gf.Vec3d(-3, -1, 2))
    after = assert_same_as_fresh(s, stage)
    assert s.stats["stage_changes"] == {"transform": 1}, s.stats["stage_changes"]
    assert np.abs(after - before).max() > 0.02


def test_light_intensity_change_is_a_params_sync():
    stage = ss.base_stage()
    card(stage, "/World/card")
    s = session(stage)
    frame(s)
    UsdLux.SphereLight(stage.GetPrimAtPath("/World/key")).GetIntensityAttr().Set(90.0)
    assert dict(s.scene.apply_stage_changes()) == {"params": 1}
    assert s.index.dirty_bits("/World/key") == DIRTY_PARAMS
    assert_same_as_fresh(s, stage)


def test_added_mesh_appears_and_removed_mesh_disappears():
    stage = ss.base_stage()
    card(stage, "/World/left", x=-1.0)
    s = session(stage)
    frame(s)
    card(stage, "/World/right", x=1.0)
    assert_same_as_fresh(s, stage)
    assert "/World/right" in s.index.rprim_ids()
    assert s.stats["stage_changes"] == {"added prims": 1}, s.stats["stage_changes"]
    stage.RemovePrim("/World/left")
    assert_same_as_fresh(s, stage)
    assert "/World/left" not in s.index.rprim_ids()
    assert s.stats["stage_changes"] == {"removed prims": 1}, s.stats["stage_changes"]


def test_deactivated_prim_disappears_and_reactivated_returns():
    stage = ss.base_stage()
    card(stage, "/World/group/card")
    s = session(stage)
    frame(s)
    stage.GetPrimAtPath("/World/group").SetActive(False)
    assert_same_as_fresh(s, stage)
    assert "/World/group/card" not in s.index.rprim_ids()
    stage.GetPrimAtPath("/World/group").SetActive(True)
    assert_same_as_fresh(s, stage)
    assert "/World/group/card" in s.index.rprim_ids()


def test_changed_eye_attribute_resyncs_the_eye():
    stage = ss.base_stage()
    eye = ss.eye_sphere_mesh(stage, "/World/eye", radius=0.8)
    s = session(stage)
    frame(s)
    # A new attribute (a property resync) and a new value of an existing one both update the eye's parameters.
    eye.GetPrim().CreateAttribute("eye:pupilDiameter", Sdf.ValueTypeNames.Float).Set(7.0)
    assert dict(s.scene.apply_stage_changes()) == {"eye": 1}
    assert s.scene.eyes == ["/World/eye"]
    assert_same_as_fresh(s, stage)
    eye.GetPrim().GetAttribute("eye:pupilDiameter").Set(2.0)
    assert dict(s.scene.apply_stage_changes()) == {"eye": 1}
    assert s.index.dirty_bits("/World/eye") == DIRTY_PARAMS
    assert_same_as_fresh(s, stage)


def test_points_edit_is_a_points_only_sync():
    stage = ss.base_stage()
    mesh = card(stage, "/World/card")
    s = session(stage)
    frame(s)
    mesh.GetPointsAttr().Set([p + Gf.Vec3f(0, 0.3, 0) for p in mesh.GetPointsAttr().Get()])
    assert dict(s.scene.apply_stage_changes()) == {"points": 1}
    assert s.index.dirty_bits("/World/card") == DIRTY_POINTS
    assert_same_as_fresh(s, stage)


def test_parent_xform_edit_moves_every_child_by_transform_alone():
    stage = ss.base_stage()
    card(stage, "/World/group/a", x=-1.0)
    card(stage, "/World/group/b", x=1.0)
    UsdGeom.Xform(stage.GetPrimAtPath("/World/group")).AddTranslateOp()
    s = session(stage)
    frame(s)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/group")).GetOrderedXformOps()[0].Set(Gf.Vec3d(0, 0.5, 0))
    s.scene.apply_stage_changes()
    assert s.index.dirty_bits("/World/group/a") == DIRTY_TRANSFORM == s.index.dirty_bits("/World/group/b")
    assert_same_as_fresh(s, stage)


def test_edit_inside_a_skel_root_reskins():
    stage = ss.two_joint_strip()
    s = session(stage, time=3)
    before = frame(s)
    rotations = UsdSkel.Animation(stage.GetPrimAtPath("/World/Rig/Skel/Anim")).GetRotationsAttr()
    rotations.Set([Gf.Quatf(1), ss.z_rotation(-50)], 3)
    after = assert_same_as_fresh(s, stage, time=3)
    assert np.abs(after - before).max() > 0.02


def test_proxy_only_asset_renders_by_default_from_python_as_from_eyerecord():
    stage = ss.base_stage()
    card(stage, "/World/proxyCard", purpose=UsdGeom.Tokens.proxy)
    card(stage, "/World/renderCard", x=2.0, purpose=UsdGeom.Tokens.render)
    s = session(stage)
    assert s.index.rprim_ids() == ["/World/proxyCard"]


def test_new_point_count_repopulates_the_mesh_instead_of_a_points_sync():
    stage = ss.base_stage()
    mesh = card(stage, "/World/card")
    s = session(stage)
    frame(s)
    mesh.GetPointsAttr().Set(list(mesh.GetPointsAttr().Get()) + [Gf.Vec3f(9, 9, 9)])  # one unused point more
    assert dict(s.scene.apply_stage_changes()) == {"points": 1, "removed prims": 1, "added prims": 1}
    assert_same_as_fresh(s, stage)


def test_parent_visibility_hides_children_and_material_edits_update_params():
    from pxr import UsdShade
    stage = ss.base_stage()
    UsdGeom.Xform.Define(stage, "/World/group")  # imageable: its visibility is inherited
    card(stage, "/World/group/card")
    material = UsdShade.Material.Define(stage, "/World/Looks/red")
    shader = UsdShade.Shader.Define(stage, "/World/Looks/red/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    color = shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f)
    color.Set(Gf.Vec3f(0.8, 0.1, 0.1))
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(stage.GetPrimAtPath("/World/group/card")).Bind(material)
    s = session(stage)
    frame(s)
    color.Set(Gf.Vec3f(0.1, 0.8, 0.1))
    assert dict(s.scene.apply_stage_changes()) == {"params": 1}
    shown = assert_same_as_fresh(s, stage)
    UsdGeom.Imageable(stage.GetPrimAtPath("/World/group")).MakeInvisible()
    assert dict(s.scene.apply_stage_changes()) == {"visibility": 1}
    hidden = assert_same_as_fresh(s, stage)
    assert hidden[..., 3].sum() < shown[..., 3].sum() - 50, (hidden[..., 3].sum(), shown[..., 3].sum())


def test_rebinding_a_material_repopulates_the_prim():
    from pxr import UsdShade
    stage = ss.base_stage()
    card(stage, "/World/card")
    s = session(stage)
    frame(s)
    material = UsdShade.Material.Define(stage, "/World/Looks/blue")
    shader = UsdShade.Shader.Define(stage, "/World/Looks/blue/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.1, 0.1, 0.9))
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(stage.GetPrimAtPath("/World/card")).Bind(material)
    assert_same_as_fresh(s, stage)


def test_mesh_removed_from_a_skel_root_disappears_and_the_rest_stays_skinned():
    stage = ss.eye_on_head(rigid=True)
    strip = ss.strip_mesh(stage, "/World/Rig/Strip", segments=2)
    count = len(strip.GetPointsAttr().Get())
    ss.bind(strip.GetPrim(), UsdSkel.Skeleton(stage.GetPrimAtPath("/World/Rig/Skel")), [1] * count, [1.0] * count, 1)
    s = session(stage, time=3)
    frame(s)
    stage.RemovePrim("/World/Rig/Eye")
    assert_same_as_fresh(s, stage, time=3)
    assert "/World/Rig/Eye" not in s.index.rprim_ids() and s.scene.eyes == []
    assert dict(s.scene.set_time(2)) == {"skinned points": 1}


def test_light_animated_after_the_session_was_built_moves_with_time():
    stage = ss.base_stage()
    card(stage, "/World/card")
    s = session(stage)
    frame(s)
    op = UsdGeom.Xformable(stage.GetPrimAtPath("/World/key")).GetOrderedXformOps()[0]
    op.Set(Gf.Vec3d(2, 3, 4), 1)
    op.Set(Gf.Vec3d(-3, -1, 2), 3)
    assert_same_as_fresh(s, stage, time=1)
    assert s.stats["stage_changes"] == {"removed prims": 1, "added prims": 1}, s.stats["stage_changes"]
    later = frame(s, time=3)
    assert s.stats["updated"] == {"transform": 1, "light": 1}, s.stats["updated"]
    assert np.array_equal(later, frame(session(stage, time=3)))
