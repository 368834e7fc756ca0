"""The render plan subdivides each Catmull-Clark mesh by its size on screen (docs/render_plan.md, "Subdivision
meshes"), says so in its JSON, and eyerecord's --complexity defaults to usdrecord's low."""
import pytest

pytest.importorskip("pxr")
from pxr import Gf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender import RenderSession  # noqa: E402
from eyerender.cli.eyerecord import build_parser  # noqa: E402
from eyerender.plan import make_overrides, plan_dict  # noqa: E402


def cube(stage, path, size, at):
    """A cube mesh (unauthored subdivisionScheme: catmullClark, UsdGeom's fallback)."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    h = size / 2
    mesh.CreatePointsAttr([(x, y, z) for z in (-h, h) for y in (-h, h) for x in (-h, h)])
    mesh.CreateFaceVertexCountsAttr([4] * 6)
    mesh.CreateFaceVertexIndicesAttr([0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 1, 3, 7, 5, 0, 4, 6, 2])
    mesh.AddTranslateOp().Set(Gf.Vec3d(*at))
    return mesh


def test_small_meshes_render_unrefined_and_large_ones_refined_with_the_reason_in_the_plan():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    UsdLux.DomeLight.Define(stage, "/World/dome")
    cube(stage, "/World/pebble", 0.1, (2, 1, 0))  # about 5 px of 128
    cube(stage, "/World/boulder", 5.0, (0, 0, 0))  # fills most of the frame
    s = RenderSession(stage, width=128, height=96, refine_level=2,
                      plan_overrides=make_overrides(refine_level_ceiling=2))
    s.render(spp=1)
    meshes = {m["prim"]: m for m in plan_dict(s.last_plan)["meshes"]}
    assert meshes["/World/pebble"]["refineLevel"] == 0 and meshes["/World/pebble"]["pixels"] < 10, meshes
    assert "level 0" in meshes["/World/pebble"]["why"]
    assert meshes["/World/boulder"]["refineLevel"] == 2 and meshes["/World/boulder"]["sceneLevel"] == 2, meshes
    assert s.index.mesh_stats("/World/pebble")["refine_level"] == 0
    assert s.index.mesh_stats("/World/pebble")["refinements"] == 0  # waited at level 0, never refined
    assert s.index.mesh_stats("/World/boulder")["refine_level"] == 2
    assert any(line.startswith("plan meshes: 2 subdivision meshes") for line in s.last_plan.summary_lines())


def test_eyerecord_complexity_defaults_to_usdrecords_low():
    assert build_parser().parse_args(["in.usda", "out.exr"]).complexity == "low"
