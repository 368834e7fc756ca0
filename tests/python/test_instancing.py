"""Instancing through the USD scene delegate: PointInstancers (gprim, Xform and nested-instancer prototypes,
invisibleIds, inactive ids, per-instance colours) and native instances share one prototype per prim, render as the
flattened reference does, and a moving instancer re-syncs its instances only."""
import numpy as np
import pytest

pytest.importorskip("pxr")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender import RenderSession  # noqa: E402

GRID = (40, 25)  # 1000 instances


def crowd_stage():
    """A 1000-instance PointInstancer (prototypes: a Cube gprim, an Xform holding a mesh and a Sphere, a nested
    PointInstancer of three quads) with invisibleIds, inactive ids and per-instance displayColor, and three native
    instances of a card."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 9))
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateIntensityAttr(30.0)
    light.AddTranslateOp().Set(Gf.Vec3d(2, 3, 6))

    pi = UsdGeom.PointInstancer.Define(stage, "/World/crowd")
    pi.AddRotateYOp().Set(10.0)
    cube = UsdGeom.Cube.Define(stage, "/World/crowd/protos/box")
    cube.CreateSizeAttr(0.1)
    cube.AddRotateXOp().Set(30.0)  # the prototype root's own transform counts
    group = UsdGeom.Xform.Define(stage, "/World/crowd/protos/group")
    tri = UsdGeom.Mesh.Define(stage, "/World/crowd/protos/group/tri")
    tri.CreatePointsAttr([(-0.06, -0.06, 0), (0.06, -0.06, 0), (0, 0.07, 0)])
    tri.CreateFaceVertexCountsAttr([3])
    tri.CreateFaceVertexIndicesAttr([0, 1, 2])
    tri.CreateSubdivisionSchemeAttr("none")
    ball = UsdGeom.Sphere.Define(stage, "/World/crowd/protos/group/ball")
    ball.CreateRadiusAttr(0.03)
    ball.AddTranslateOp().Set(Gf.Vec3d(0, 0, 0.05))
    del group
    inner = UsdGeom.PointInstancer.Define(stage, "/World/crowd/protos/nest")
    quad = UsdGeom.Mesh.Define(stage, "/World/crowd/protos/nest/protos/quad")
    quad.CreatePointsAttr([(-0.02, -0.02, 0), (0.02, -0.02, 0), (0.02, 0.02, 0), (-0.02, 0.02, 0)])
    quad.CreateFaceVertexCountsAttr([4])
    quad.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    inner.CreatePrototypesRel().SetTargets([quad.GetPath()])
    inner.CreatePositionsAttr([(-0.05, 0, 0), (0.05, 0, 0), (0, 0.05, 0.01)])
    inner.CreateProtoIndicesAttr([0, 0, 0])
    pi.CreatePrototypesRel().SetTargets([cube.GetPath(), "/World/crowd/protos/group", inner.GetPath()])
    n = GRID[0] * GRID[1]
    positions = [(-3.0 + 0.15 * (k % GRID[0]), -1.9 + 0.15 * (k // GRID[0]), 0.0) for k in range(n)]
    pi.CreatePositionsAttr(positions)
    pi.CreateProtoIndicesAttr([k % 3 for k in range(n)])
    pi.CreateScalesAttr([(1.0 + 0.3 * (k % 5) / 4, 1.0, 1.0) for k in range(n)])
    pi.CreateOrientationsAttr([Gf.Quath(Gf.Rotation(Gf.Vec3d(0, 0, 1), 7.0 * k).GetQuat()) for k in range(n)])
    pi.CreateInvisibleIdsAttr([4, 5, 6, 100])
    pi.DeactivateIds([7, 8, 500])
    color = UsdGeom.PrimvarsAPI(pi.GetPrim()).CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray,
                                                             UsdGeom.Tokens.vertex)
    color.Set([((k % 7) / 7.0, 0.5, 1.0 - (k % 11) / 11.0) for k in range(n)])

    card = UsdGeom.Mesh.Define(stage, "/Library/card/geo")
    card.CreatePointsAttr([(-0.3, -0.2, 0), (0.3, -0.2, 0), (0.3, 0.2, 0), (-0.3, 0.2, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("catmullClark")
    stage.GetPrimAtPath("/Library").SetSpecifier(Sdf.SpecifierClass)
    for k, x in enumerate((-2.0, 0.0, 2.0)):
        inst = UsdGeom.Xform.Define(stage, f"/World/cards/c{k}")
        inst.AddTranslateOp().Set(Gf.Vec3d(x, 2.3, 0.5))
        inst.AddRotateZOp().Set(15.0 * k)
        inst.GetPrim().GetReferences().AddInternalReference("/Library/card")
        inst.GetPrim().SetInstanceable(True)
    return stage


def session(stage, **kwargs):
    return RenderSession(stage, width=64, height=40, settings={"seed": 3}, **kwargs)


def instances_drawn(s, prefix):
    s.index.sync_all()
    return {i: s.index.mesh_stats(i)["instances_drawn"] for i in s.index.rprim_ids() if i.startswith(prefix)}


def test_prototypes_are_added_once_and_drawn_per_unmasked_instance():
    stage = crowd_stage()
    s = session(stage)
    drawn = instances_drawn(s, "/World/")
    # Every prototype prim is one rprim: 4 for the crowd (box, tri, ball, the nested quad) and 1 for the cards.
    assert len(drawn) == 5, sorted(drawn)
    mask = UsdGeom.PointInstancer(stage.GetPrimAtPath("/World/crowd")).ComputeMaskAtTime(Usd.TimeCode.Default())
    visible = [k for k in range(GRID[0] * GRID[1]) if mask[k]]
    assert len(visible) == 1000 - 7
    per_proto = [sum(1 for k in visible if k % 3 == p) for p in range(3)]
    assert drawn["/World/crowd/__prototype0/box"] == per_proto[0]
    assert drawn["/World/crowd/__prototype1/group/tri"] == per_proto[1]
    assert drawn["/World/crowd/__prototype1/group/ball"] == per_proto[1]
    assert drawn["/World/crowd/__prototype2/nest/__prototype0/quad"] == 3 * per_proto[2]  # nested: flattened
    assert drawn["/World/cards/c0/__instances/geo"] == 3
    assert s.scene.warnings == []


def test_instanced_render_matches_the_flattened_reference():
    stage = crowd_stage()
    shared, flat = session(stage), session(stage, flatten_instances=True)
    assert len(flat.index.rprim_ids()) > 1000 and len(shared.index.rprim_ids()) == 5
    shared.render(spp=2)
    flat.render(spp=2)
    a, b = shared.image("color"), flat.image("color")
    assert a[:, :, 3].mean() > 0.1  # the crowd covers the frame
    worst = float(np.abs(a - b).max())
    assert worst == 0.0, f"instanced and flattened differ by up to {worst}"


def test_animated_instancer_resyncs_only_its_instances():
    stage = crowd_stage()
    pi = UsdGeom.PointInstancer(stage.GetPrimAtPath("/World/crowd"))
    positions = list(pi.GetPositionsAttr().Get())
    pi.GetPositionsAttr().Set(positions, 1.0)
    positions[0] = Gf.Vec3f(0, 0, 1)
    pi.GetPositionsAttr().Set(positions, 2.0)
    s = RenderSession(stage, width=32, height=20, time=1.0)
    box = "/World/crowd/__prototype0/box"
    s.render(spp=1)
    before = s.index.mesh_stats(box)
    syncs = s.index.instancer_sync_count("/World/crowd/__prototype0")
    s.scene.set_time(2.0)
    s.index.sync_all()
    after = s.index.mesh_stats(box)
    assert s.index.instancer_sync_count("/World/crowd/__prototype0") == syncs + 1
    assert after["instance_syncs"] == before["instance_syncs"] + 1
    for key in ("topology_builds", "refinements", "point_uploads", "transform_updates"):
        assert after[key] == before[key], key
    assert set(s.scene.last_update) == {"instancer"}


def test_eyes_in_a_prototype_are_flattened_one_per_instance():
    stage = crowd_stage()
    pi = UsdGeom.PointInstancer(stage.GetPrimAtPath("/World/crowd"))
    eye = UsdGeom.Xform.Define(stage, "/World/crowd/protos/group/eye")
    eye.GetPrim().AddAppliedSchema("EyeAPI")
    eye.AddScaleOp().Set(Gf.Vec3f(0.002))  # millimetres of the eye to scene units
    s = session(stage)
    visible = sum(1 for k, keep in enumerate(pi.ComputeMaskAtTime(Usd.TimeCode.Default())) if keep and k % 3 == 1)
    assert len(s.scene.eyes) == visible  # each its own analytic eye prim, with its own frame
    assert all(e.startswith("/World/crowd/__prototype1/instance_") and e.endswith("/group/eye") for e in s.scene.eyes)
    assert "/World/crowd/__prototype1/group/tri" in s.index.rprim_ids()  # the rest of the prototype stays shared
