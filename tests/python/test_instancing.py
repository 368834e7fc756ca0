"""Instancing through the USD scene delegate: PointInstancers (gprim, Xform and nested-instancer prototypes,
invisibleIds, inactive ids, per-instance colours) and native instances share one prototype per prim, render as the
flattened reference does, and a moving instancer re-syncs its instances only."""
import numpy as np
import pytest

pytest.importorskip("pxr")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdSkel  # noqa: E402

from eyerender import RenderSession  # noqa: E402

GRID = (40, 25)  # 1000 instances


def square(stage, path, half):
    """A square mesh of half-width `half` in the xy plane, centred at the origin."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    return mesh


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
    quad = square(stage, "/World/crowd/protos/nest/protos/quad", 0.02)
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


# -- stage edits (stage_notices.py) ---------------------------------------------------------------------------------

def assert_renders_as_fresh(s, stage):
    """s, after the stage was edited, renders what a session built on the edited stage renders; returns the image."""
    s.render(spp=2)
    fresh = session(stage)
    fresh.render(spp=2)
    ours, theirs = s.image("color"), fresh.image("color")
    assert sorted(s.index.rprim_ids()) == sorted(fresh.index.rprim_ids())
    assert np.array_equal(ours, theirs), f"worst pixel difference {np.abs(ours - theirs).max()}"
    return ours


def test_point_instancer_positions_edited_after_the_session_was_built_move_its_instances():
    stage = crowd_stage()
    s = session(stage)
    s.render(spp=2)
    before = s.image("color")
    pi = UsdGeom.PointInstancer(stage.GetPrimAtPath("/World/crowd"))
    pi.GetPositionsAttr().Set([Gf.Vec3f(p) + Gf.Vec3f(0.4, 0.3, 0) for p in pi.GetPositionsAttr().Get()])
    after = assert_renders_as_fresh(s, stage)
    assert not np.array_equal(before, after)
    assert len(s.index.rprim_ids()) == 5  # re-populated in place of the old prototypes, not beside them
    assert s.stats["stage_changes"]["removed prims"] == s.stats["stage_changes"]["added prims"]


def test_prototype_added_to_a_point_instancer_after_the_session_was_built_is_drawn_by_its_own_instancer():
    stage = crowd_stage()
    s = session(stage)
    s.render(spp=1)
    pi = UsdGeom.PointInstancer(stage.GetPrimAtPath("/World/crowd"))
    disk = UsdGeom.Sphere.Define(stage, "/World/crowd/protos/disk")
    disk.CreateRadiusAttr(0.06)
    disk.AddScaleOp().Set(Gf.Vec3f(1, 1, 0.1))
    pi.GetPrototypesRel().AddTarget(disk.GetPath())
    indices = list(pi.GetProtoIndicesAttr().Get())
    indices[:300] = [3] * 300
    pi.GetProtoIndicesAttr().Set(indices)
    assert_renders_as_fresh(s, stage)
    drawn = instances_drawn(s, "/World/crowd/")
    mask = pi.ComputeMaskAtTime(Usd.TimeCode.Default())
    assert drawn["/World/crowd/__prototype3/disk"] == sum(1 for k in range(300) if mask[k])
    assert drawn["/World/crowd/__prototype0/box"] == sum(1 for k in range(300, len(indices)) if mask[k] and k % 3 == 0)


def test_prototype_mesh_edited_after_the_session_was_built_changes_every_instance():
    stage = crowd_stage()
    s = session(stage)
    s.render(spp=1)
    tri = UsdGeom.Mesh(stage.GetPrimAtPath("/World/crowd/protos/group/tri"))
    tri.GetPointsAttr().Set([(-0.07, -0.07, 0), (0.07, -0.07, 0), (0, 0.09, 0)])
    assert_renders_as_fresh(s, stage)
    assert s.stats["stage_changes"]["instancer"] == 1


def test_native_instance_moved_after_the_session_was_built_moves_within_its_group():
    stage = crowd_stage()
    s = session(stage)
    s.render(spp=1)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/cards/c1")).GetOrderedXformOps()[0].Set(Gf.Vec3d(0.5, 1.8, 0.5))
    assert_renders_as_fresh(s, stage)
    assert instances_drawn(s, "/World/cards/")["/World/cards/c0/__instances/geo"] == 3  # one group, not two


def test_native_instance_added_after_the_session_was_built_joins_the_drawn_instances():
    stage = crowd_stage()
    s = session(stage)
    s.render(spp=1)
    inst = UsdGeom.Xform.Define(stage, "/World/cards/c3")
    inst.AddTranslateOp().Set(Gf.Vec3d(1.0, -2.2, 0.5))
    inst.GetPrim().GetReferences().AddInternalReference("/Library/card")
    inst.GetPrim().SetInstanceable(True)
    assert_renders_as_fresh(s, stage)
    assert sum(instances_drawn(s, "/World/cards/").values()) == 4


def test_skinned_mesh_in_a_native_instance_prototype_renders_unskinned_with_one_warning():
    stage = crowd_stage()
    root = UsdSkel.Root.Define(stage, "/Library/rig")
    skel = UsdSkel.Skeleton.Define(stage, "/Library/rig/skel")
    skel.CreateJointsAttr(["root"])
    skel.CreateBindTransformsAttr([Gf.Matrix4d(1)])
    skel.CreateRestTransformsAttr([Gf.Matrix4d(1)])
    mesh = UsdGeom.Mesh.Define(stage, "/Library/rig/skin")
    mesh.CreatePointsAttr([(-0.2, -0.2, 0), (0.2, -0.2, 0), (0.2, 0.2, 0), (-0.2, 0.2, 0)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skel.GetPath()])
    binding.CreateJointIndicesPrimvar(False, 1).Set([0, 0, 0, 0])
    binding.CreateJointWeightsPrimvar(False, 1).Set([1.0] * 4)
    del root
    for k in range(2):
        inst = stage.DefinePrim(f"/World/rigs/r{k}")  # typeless: a SkelRoot through its reference
        inst.GetReferences().AddInternalReference("/Library/rig")
        UsdGeom.Xformable(inst).AddTranslateOp().Set(Gf.Vec3d(-1.0 + 2.0 * k, -2.0, 0.5))
        inst.SetInstanceable(True)
    assert stage.GetPrimAtPath("/World/rigs/r0").IsA(UsdSkel.Root)
    s = session(stage)
    prototype = stage.GetPrimAtPath("/World/rigs/r0").GetPrototype()
    assert s.scene.warnings == [f"{prototype.GetPath()}/skin: instanced copies of a skinned mesh render unskinned"]
    assert instances_drawn(s, "/World/rigs/") == {"/World/rigs/r0/__instances/skin": 2}


def test_an_unrenderable_prim_in_a_prototype_is_left_out_with_one_warning_and_the_rest_renders():
    # As in OpenUSD's testUsdSkelCache/populate.usda: an empty mesh inside a native instance's prototype (it ended
    # the whole render with an error).
    stage = crowd_stage()
    UsdGeom.Mesh.Define(stage, "/Library/card/empty")
    s = session(stage)
    prototype = stage.GetPrimAtPath("/World/cards/c0").GetPrototype()
    instanced_as = {f"/World/cards/c{k}/empty" for k in range(3)}
    warnings = [w for w in s.scene.warnings if "empty" in w]
    assert len(warnings) == 1, s.scene.warnings
    head, _, instance = warnings[0].removesuffix(")").partition(" (skipped; instanced as ")
    assert head == f"{prototype.GetPath()}/empty: mesh has no points or no faces" and instance in instanced_as
    assert instances_drawn(s, "/World/cards/") == {"/World/cards/c0/__instances/geo": 3}
    s.render(spp=1)
    assert (s.image("color")[:, :, 3] > 0).any()


def test_cornea_shell_in_a_prototype_is_left_out_of_every_instance():
    stage = crowd_stage()
    eye = UsdGeom.Xform.Define(stage, "/World/crowd/protos/group/eye")
    eye.GetPrim().AddAppliedSchema("EyeAPI")
    eye.AddScaleOp().Set(Gf.Vec3f(0.002))
    eye.GetPrim().CreateRelationship("eye:corneaShell").SetTargets(["/World/crowd/protos/group/tri"])
    s = session(stage)
    assert s.scene.cornea_shells == {Sdf.Path("/World/crowd/protos/group/tri"): eye.GetPath()}
    assert "/World/crowd/__prototype1/group/tri" not in s.index.rprim_ids()
    assert "/World/crowd/__prototype1/group/ball" in s.index.rprim_ids()  # the rest of the prototype stays


def test_a_point_instancer_inside_a_native_instance_is_drawn_at_every_instance():
    # OpenUSD's PointInstancer pi stage: native instances of a prim holding a PointInstancer (they drew nothing).
    stage = crowd_stage()
    pi = UsdGeom.PointInstancer.Define(stage, "/Library/scatter/pi")
    pi.AddTranslateOp().Set(Gf.Vec3d(0, 0.3, 0))
    tile = square(stage, "/Library/scatter/pi/protos/tile", 0.1)
    pi.CreatePrototypesRel().SetTargets([tile.GetPath()])
    pi.CreatePositionsAttr([(-0.3, 0, 0), (0.3, 0, 0)])
    pi.CreateProtoIndicesAttr([0, 0])
    for k, x in enumerate((-1.0, 1.0)):
        inst = UsdGeom.Xform.Define(stage, f"/World/scatters/s{k}")
        inst.AddTranslateOp().Set(Gf.Vec3d(x, -0.9, 0.5))  # in view, in front of the crowd
        inst.GetPrim().GetReferences().AddInternalReference("/Library/scatter")
        inst.GetPrim().SetInstanceable(True)
    shared, flat = session(stage), session(stage, flatten_instances=True)
    drawn = instances_drawn(shared, "/World/scatters/")
    assert list(drawn.values()) == [4], drawn  # one prototype rprim, 2 points x 2 native instances
    shared.render(spp=2)
    flat.render(spp=2)
    assert float(np.abs(shared.image("color") - flat.image("color")).max()) == 0.0
    assert shared.scene.warnings == []
    stage.GetPrimAtPath("/World/scatters").SetActive(False)
    without = session(stage)
    without.render(spp=2)
    assert float(np.abs(shared.image("color") - without.image("color")).max()) > 0.1  # the tiles are in view


def test_a_constant_display_color_on_native_instance_roots_colours_each_instance_as_flattened():
    # OpenUSD's InstancePrimvars stage: instance roots carry displayColor, their prototype's sphere has none.
    stage = crowd_stage()
    UsdGeom.Sphere.Define(stage, "/Library/bead/geo").CreateRadiusAttr(0.2)
    for k, (x, color) in enumerate(((-1.0, (0.9, 0.1, 0.1)), (0.0, None), (1.0, (0.1, 0.2, 0.9)))):
        inst = UsdGeom.Xform.Define(stage, f"/World/beads/b{k}")
        inst.AddTranslateOp().Set(Gf.Vec3d(x, -0.9, 0.5))
        inst.GetPrim().GetReferences().AddInternalReference("/Library/bead")
        inst.GetPrim().SetInstanceable(True)
        if color:
            UsdGeom.PrimvarsAPI(inst).CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray,
                                                    UsdGeom.Tokens.constant).Set([color])
    shared, flat = session(stage, aovs=["albedo"]), session(stage, flatten_instances=True, aovs=["albedo"])
    assert list(instances_drawn(shared, "/World/beads/").values()) == [3]
    shared.render(spp=2)
    flat.render(spp=2)
    assert float(np.abs(shared.image("albedo") - flat.image("albedo")).max()) == 0.0
    albedo = shared.image("albedo")[35, :, :3]  # the row through the beads; their centres at columns 15, 32, 49
    for column, color in ((15, (0.9, 0.1, 0.1)), (32, (0.18, 0.18, 0.18)), (49, (0.1, 0.2, 0.9))):
        assert albedo[column] == pytest.approx(color, abs=1e-6), column


def test_curves_and_points_in_a_prototype_are_drawn_at_every_instance():
    # OpenUSD's moreCurves and Instancing stages: curves and points inside native prototypes were "not supported".
    stage = crowd_stage()
    hair = UsdGeom.BasisCurves.Define(stage, "/Library/tuft/hair")
    hair.CreateTypeAttr(UsdGeom.Tokens.linear)
    hair.CreateCurveVertexCountsAttr([2])
    hair.CreatePointsAttr([(-0.3, 0, 0), (0.3, 0, 0)])
    hair.CreateWidthsAttr([0.08])
    dots = UsdGeom.Points.Define(stage, "/Library/tuft/dots")
    dots.CreatePointsAttr([(0, 0.15, 0)])
    dots.CreateWidthsAttr([0.12])
    for k, x in enumerate((-1.0, 1.0)):
        inst = UsdGeom.Xform.Define(stage, f"/World/tufts/t{k}")
        inst.AddTranslateOp().Set(Gf.Vec3d(x, -0.9, 0.5))
        inst.GetPrim().GetReferences().AddInternalReference("/Library/tuft")
        inst.GetPrim().SetInstanceable(True)
    shared, flat = session(stage), session(stage, flatten_instances=True)
    assert shared.scene.warnings == []
    assert len([i for i in shared.index.rprim_ids() if i.startswith("/World/tufts/")]) == 4  # 2 prims x 2 instances
    shared.render(spp=2)
    flat.render(spp=2)
    assert float(np.abs(shared.image("color") - flat.image("color")).max()) == 0.0
    stage.GetPrimAtPath("/World/tufts").SetActive(False)
    without = session(stage)
    without.render(spp=2)
    assert float(np.abs(shared.image("color") - without.image("color")).max()) > 0.1  # in view
