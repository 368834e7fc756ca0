"""Binding properties an Xform inherits, as UsdSkel resolves them for a gprim in its place: jointIndices,
jointWeights, geomBindTransform, skel:joints and skinningMethod come from the nearest ancestor-or-self that authors
them (up to the SkelRoot). An eye Xform beside a Sphere probe with the same binding must land where
UsdSkel.BakeSkinning puts the probe. The structure is the one found on a real rig (an eye on usd-wg's RiggedFigure
neck joint, a head group holding the shared binding properties)."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, UsdGeom, UsdSkel  # noqa: E402

import skel_stages as ss  # noqa: E402
from test_usd_skel import delegate, matrix  # noqa: E402

GEOM_BIND = ss.translate(*(ss.HEAD_EYE_OFFSET + Gf.Vec3d(0, 1, 0)))  # the eye's bind placement in skeleton space


def _head_group(stage, skel, path, local=None, **properties):
    """An Xform under the SkelRoot bound to skel, authoring the given binding properties (joint_indices: constant
    indices with weight 1, geom_bind, joints), with an EyeAPI Xform "Eye" and a Sphere "Probe" below it."""
    group = UsdGeom.Xform.Define(stage, path)
    if local is not None:
        group.AddTransformOp().Set(local)
    api = UsdSkel.BindingAPI.Apply(group.GetPrim())
    api.CreateSkeletonRel().SetTargets([skel.GetPath()])
    _author(group.GetPrim(), **properties)
    children = []
    for name, kind in (("Eye", UsdGeom.Xform), ("Probe", UsdGeom.Sphere)):
        child = kind.Define(stage, f"{path}/{name}")
        children.append(child.GetPrim())
    children[0].AddAppliedSchema("EyeAPI")
    UsdGeom.Sphere(children[1]).CreateRadiusAttr(0.1)
    return children


def _author(prim, joint_indices=None, geom_bind=None, joints=None):
    api = UsdSkel.BindingAPI.Apply(prim)
    if joint_indices is not None:
        api.CreateJointIndicesPrimvar(True, 1).Set(joint_indices)
        api.CreateJointWeightsPrimvar(True, 1).Set([1.0])
    if geom_bind is not None:
        api.CreateGeomBindTransformAttr(geom_bind)
    if joints is not None:
        api.CreateJointsAttr(joints)


def _assert_eye_on_baked_probe(stage, eye, probe):
    baked = ss.baked_copy(stage)
    scene, store = delegate(stage)
    assert not scene.warnings, scene.warnings
    moved = []
    for t in (1, 2, 3):
        scene.set_time(t)
        expected = matrix(UsdGeom.XformCache(t).GetLocalToWorldTransform(baked.GetPrimAtPath(probe)))
        got = store.transforms[eye]
        assert np.allclose(got, expected, atol=1e-9), f"frame {t}: worst {np.abs(got - expected).max()}"
        moved.append(expected)
    assert np.abs(moved[2] - moved[0]).max() > 0.1  # the head turned: the comparison is not at the bind pose


def test_eye_xform_takes_geom_bind_and_joint_order_its_head_group_authors():
    # The group authors geomBindTransform and skel:joints (index 0 names the head, the skeleton's 0 is the root);
    # the eye and the probe author their own constant jointIndices only.
    stage, skel = ss.head_rig()
    eye, probe = _head_group(stage, skel, "/World/Rig/Head", geom_bind=GEOM_BIND, joints=["root/head"])
    for prim in (eye, probe):
        _author(prim, joint_indices=[0])
    _assert_eye_on_baked_probe(stage, str(eye.GetPath()), str(probe.GetPath()))


def test_eye_xform_with_its_own_geom_bind_is_bound_itself_not_through_its_group():
    # The group (moved by its own transform) authors the joint influences; the eye and the probe author their own
    # geomBindTransform and sit at it. UsdSkel skins the probe with its own geomBindTransform: so must the eye be.
    stage, skel = ss.head_rig()
    group_local = ss.translate(0.0, 0.5, -0.2)
    eye, probe = _head_group(stage, skel, "/World/Rig/Head", local=group_local, joint_indices=[1])
    for prim in (eye, probe):
        _author(prim, geom_bind=GEOM_BIND)
        UsdGeom.Xformable(prim).AddTransformOp().Set(GEOM_BIND * group_local.GetInverse())
    _assert_eye_on_baked_probe(stage, str(eye.GetPath()), str(probe.GetPath()))


def test_eye_xform_authoring_no_binding_follows_its_bound_group_with_its_own_offset():
    # Unlike a gprim (which UsdSkel would move to the group's geomBindTransform), an Xform authoring no binding
    # property follows its nearest bound ancestor and keeps its local offset: two eyes under one head stay apart.
    stage, skel = ss.head_rig()
    eye, _ = _head_group(stage, skel, "/World/Rig/Head", joint_indices=[1], geom_bind=GEOM_BIND)
    offset = ss.translate(0.1, 0, 0)
    UsdGeom.Xformable(eye).AddTransformOp().Set(offset)
    scene, store = delegate(stage)
    scene.set_time(3)
    head = scene.skinning.get(stage.GetPrimAtPath("/World/Rig/Head")).world(3, UsdGeom.XformCache(3))
    assert np.allclose(store.transforms[str(eye.GetPath())], matrix(offset * head), atol=1e-12)
