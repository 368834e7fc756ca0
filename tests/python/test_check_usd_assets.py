"""bench/check_usd_assets.py, the comparison of the scene delegate with usd-core's own answers (UsdSkel.BakeSkinning,
UsdShade's subset bindings) that docs/usd_support.md's table comes from, run on stages the tests author: it must
find each stage's rows, agree where the delegate is right and exit 1 where an answer differs."""
import re
import sys
from pathlib import Path

import pytest

pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, UsdGeom, UsdShade  # noqa: E402

import skel_stages  # noqa: E402
from shading_stages import preview_material  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import check_usd_assets  # noqa: E402

QUADS = [(0, 1, 4, 3), (1, 2, 5, 4)]  # two quads side by side, 6 points


def subset_stage():
    """Two quads: the mesh bound to blue, face 1 in a subset bound to red (the same material file a real asset's
    subsets would have, authored inline)."""
    stage = skel_stages.base_stage()
    mesh = UsdGeom.Mesh.Define(stage, "/World/quads")
    mesh.CreatePointsAttr([(x, y, 0) for y in (0, 1) for x in (0, 1, 2)])
    mesh.CreateFaceVertexCountsAttr([4, 4])
    mesh.CreateFaceVertexIndicesAttr([i for f in QUADS for i in f])
    binding = UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim())
    binding.Bind(preview_material(stage, "/World/blue", (0.1, 0.2, 0.9)))
    subset = binding.CreateMaterialBindSubset("right", [1])
    UsdShade.MaterialBindingAPI.Apply(subset.GetPrim()).Bind(preview_material(stage, "/World/red", (0.8, 0.1, 0.1)))
    return stage


def run(tmp_path, capsys, *extra):
    for name, stage in (("strip", skel_stages.two_joint_strip(bend=80.0)), ("head", skel_stages.eye_on_head()),
                        ("quads", subset_stage())):
        stage.GetRootLayer().Export(str(tmp_path / f"{name}.usda"))  # the stage held: its layer lives with it
    status = check_usd_assets.main([str(tmp_path), "--frames", "3", "--relative-to", str(tmp_path), *extra])
    return status, capsys.readouterr().out


def skel_rows(out, asset):
    """(frame, complexity, max point deviation) of each UsdSkel row of `asset`."""
    rows = [line.split(" | ") for line in out.splitlines() if line.startswith(asset + " | ")]
    return [(float(r[1]), r[2], float(r[3])) for r in rows if re.fullmatch(r"[0-9.e+-]+", r[3])]


def test_skinned_and_subset_stages_match_usd_and_exit_zero(tmp_path, capsys):
    status, out = run(tmp_path, capsys)
    for asset in ("strip.usda", "head.usda"):
        rows = skel_rows(out, asset)
        # Three frames over 1-3, at both complexities: the bent frames are where skinning can go wrong.
        assert {frame for frame, _, _ in rows} == {1.0, 2.0, 3.0}, out
        assert {c for _, c, _ in rows} == {"low", "high"}, out
        assert max(d for _, _, d in rows) < 1e-5, out
    subset = [line for line in out.splitlines() if line.startswith("quads.usda | ")]
    assert len(subset) == 1 and subset[0].split(" | ")[3:6] == ["1/1 meshes", "2", "0"], out
    assert status == 0, out


def test_a_bake_that_differs_is_reported_by_its_size_and_exits_one(tmp_path, capsys, monkeypatch):
    # The baked strip's points moved 0.01 up at frame 3 only: the check must see exactly that, there, and fail.
    bake = check_usd_assets.baked_stage

    def moved_bake(path, frames):
        stage = bake(path, frames)
        if path.endswith("strip.usda"):
            points = stage.GetPrimAtPath("/World/Rig/Strip").GetAttribute("points")
            points.Set([p + Gf.Vec3f(0, 0.01, 0) for p in points.Get(3)], 3)
        return stage

    monkeypatch.setattr(check_usd_assets, "baked_stage", moved_bake)
    status, out = run(tmp_path, capsys)
    deviation = {(frame, c): d for frame, c, d in skel_rows(out, "strip.usda")}
    assert deviation[(3.0, "low")] == pytest.approx(0.01, rel=1e-3), out
    assert max(deviation[(f, c)] for f in (1.0, 2.0) for c in ("low", "high")) < 1e-5, out
    assert max(d for _, _, d in skel_rows(out, "head.usda")) < 1e-5, out
    assert status == 1
