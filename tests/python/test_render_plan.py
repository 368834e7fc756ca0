"""The render plan from Python and the command line: the JSON contract, the synthetic cases, overrides winning,
`eyerecord --plan` (prints JSON, renders and writes nothing), the one line per eye at render start, and the
`eyerender:plan` EXR header attribute."""
import csv
import json
import math
import os

import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux  # noqa: E402

from eyerender.cli.eyerecord import main  # noqa: E402
from eyerender.plan import PLAN_ATTRIBUTE, check_contract, make_overrides, plan_dict  # noqa: E402
from eyerender.render_session import RenderSession  # noqa: E402

IRIS_Z = -3.735  # mm


def make_stage(path=None, *, camera_distance=40.0, lights=(("sphere", 2.0, 45.0),), camera_turned=False,
               limbal_arc=None):
    """A millimetre stage: an analytic eye at the origin gazing +z, a 50 mm camera (24 mm square film) on the axis,
    and lights: ("sphere", radius mm, degrees off the gaze at 200 mm) or ("dome",)."""
    stage = Usd.Stage.CreateNew(str(path)) if path else Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(50.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.1, 1e6))
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, camera_distance))
    if camera_turned:
        cam.AddRotateYOp().Set(180.0)  # looks down +z: the eye is behind it
    eye = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
    eye.AddAppliedSchema("EyeAPI")
    if limbal_arc is not None:
        eye.CreateAttribute("eye:limbalArc", Sdf.ValueTypeNames.Bool).Set(limbal_arc)
    for n, light in enumerate(lights):
        if light[0] == "dome":
            UsdLux.DomeLight.Define(stage, "/World/dome").CreateIntensityAttr(1.0)
        else:
            _, radius, angle = light
            sphere = UsdLux.SphereLight.Define(stage, f"/World/key{n}")
            sphere.CreateRadiusAttr(radius)
            sphere.CreateIntensityAttr(3000.0)
            a = math.radians(angle)
            sphere.AddTranslateOp().Set(Gf.Vec3d(200 * math.sin(a), 0, IRIS_Z + 200 * math.cos(a)))
    if path:
        stage.GetRootLayer().Save()
    return stage


def plan_of(stage, width=64, **overrides):
    session = RenderSession(stage, width=width)
    return plan_dict(session.plan(make_overrides(**overrides)))


def test_json_contract_holds_for_a_small_key_light():
    plan = check_contract(plan_of(make_stage()))
    (eye,) = plan["eyes"]
    assert eye["prim"] == "/World/Eye"
    # 64 px over a 24 mm film, 50 mm lens, iris circle 43.735 mm away: the pinhole formula.
    assert eye["pixels"] == pytest.approx(64 / 24 * 50 * 15.08 / (40 - IRIS_Z), rel=0.005)
    assert eye["mnee"] is True and plan["applied"]["mnee"] is True
    assert set(eye["why"]) >= {"mnee", "mneeAllSolutions", "sss", "limbalArc", "chamberEvents"}
    assert eye["lights"][0]["strategy"] == "mnee"


def test_dome_only_turns_mnee_off():
    plan = plan_of(make_stage(lights=(("dome",),)))
    (eye,) = plan["eyes"]
    assert eye["mnee"] is False and plan["applied"]["mnee"] is False
    assert eye["lights"][0]["strategy"] == "bsdf"


def test_eye_behind_the_camera_gets_no_mnee():
    plan = plan_of(make_stage(camera_turned=True))
    (eye,) = plan["eyes"]
    assert eye["behindCamera"] is True and eye["pixels"] == 0 and eye["mnee"] is False


def test_a_few_pixels_wide_eye_is_measured_and_planned():
    plan = plan_of(make_stage(camera_distance=2000.0), width=64)
    (eye,) = plan["eyes"]
    assert eye["pixels"] < 2
    assert eye["limbalArc"] is False


def test_flags_win_over_the_planner():
    plan = plan_of(make_stage(lights=(("dome",),)), mnee=True, mnee_all_solutions=True)
    (eye,) = plan["eyes"]
    assert eye["mnee"] is True and eye["mneeAllSolutions"] is True
    assert eye["why"]["mneeAllSolutions"].startswith("flag")
    plan = plan_of(make_stage(), mnee=False)
    assert plan["eyes"][0]["mnee"] is False and plan["applied"]["mnee"] is False


def test_session_applies_the_plan_to_its_settings():
    session = RenderSession(make_stage(lights=(("dome",),)), width=16, plan_overrides=make_overrides())
    assert session.delegate.settings.mnee is True  # the renderer's default until a frame is planned
    session.render(spp=1)
    assert session.delegate.settings.mnee is False
    assert check_contract(plan_dict(session.last_plan))["eyes"][0]["mnee"] is False


def test_a_dome_and_a_key_are_applied_per_light_and_the_json_says_so():
    plan = check_contract(plan_of(make_stage(lights=(("dome",), ("sphere", 2.0, 30.0)))))
    assert plan["application"] == "perEye"
    assert "pending" not in json.dumps(plan)
    (eye,) = plan["eyes"]
    assert {light["light"]: light["strategy"] for light in eye["lights"]} == {"/World/dome": "bsdf",
                                                                             "/World/key1": "mnee"}
    assert eye["applied"] == {"mnee": True, "mneeLights": ["/World/key1"], "mneeAllSolutions": False,
                              "maxChamberEvents": 64, "chamberCacheRings": eye["chamberCacheRings"],
                              "scleraScattering": False, "limbalArc": eye["limbalArc"],
                              "refineLevel": eye["refineLevel"]}
    assert eye["chamberCacheRings"] in (12, 16, 20, 24, 28, 32)


def test_session_renders_each_eye_with_its_plan_and_clears_it_without_one():
    # A dome alone: the plan gives it to BSDF sampling, so no MNEE runs on the eye (irisMnee stays 0); without a
    # plan the eye's planned switches are cleared and the global switch (on) rules again.
    stage = make_stage(lights=(("dome",),))
    session = RenderSession(stage, width=16, aovs=("color", "irisMnee"), plan_overrides=make_overrides())
    session.render(spp=2)
    assert float(session.image("irisMnee").max()) == 0.0
    session.plan_overrides = None
    session.delegate.settings.mnee = True
    session.render(spp=2)
    assert session.last_plan is None
    assert float(session.image("irisMnee").max()) > 0.0


def test_authored_limbal_arc_is_read_from_the_stage():
    from eyerender.plan import authored_eye_values

    assert authored_eye_values(make_stage(limbal_arc=False)) == {"/World/Eye": {"limbalArc": False}}
    assert authored_eye_values(make_stage()) == {}  # the schema's fallback is not an authored value
    plan = plan_of(make_stage(limbal_arc=False), authored=authored_eye_values(make_stage(limbal_arc=False)))
    assert plan["eyes"][0]["why"]["limbalArc"].startswith("authored")


def test_eyerecord_plan_prints_json_and_writes_nothing(tmp_path, capsys):
    stage_file = tmp_path / "scene.usda"
    make_stage(stage_file)
    out = tmp_path / "out.exr"
    assert main([str(stage_file), str(out), "--plan", "-w", "32"]) == 0
    plan = check_contract(json.loads(capsys.readouterr().out))
    assert plan["width"] == 32 and len(plan["eyes"]) == 1
    assert sorted(os.listdir(tmp_path)) == ["scene.usda"]  # no image, no temporary file
    assert main([str(stage_file), str(out), "--plan", "--no-mnee", "-w", "32"]) == 0
    assert json.loads(capsys.readouterr().out)["eyes"][0]["mnee"] is False


def test_eyerecord_prints_one_line_per_eye_and_stores_the_plan_in_the_exr(tmp_path, capsys):
    stage_file = tmp_path / "scene.usda"
    make_stage(stage_file, lights=(("dome",), ("sphere", 2.0, 30.0)))
    out = tmp_path / "eye.exr"
    assert main([str(stage_file), str(out), "-w", "16", "--spp", "1", "-q"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    plan_lines = [line for line in lines if line.startswith("eyerecord: plan /World/Eye:")]
    assert len(plan_lines) == 1 and "mnee on [key1]" in plan_lines[0], lines
    header = eyerender._hdeye.read_exr_attributes(str(out))
    plan = check_contract(header[PLAN_ATTRIBUTE])
    assert plan["eyes"][0]["prim"] == "/World/Eye"
    assert [light["strategy"] for light in plan["eyes"][0]["lights"]] == ["bsdf", "mnee"]  # dome, key


def test_no_auto_plan_leaves_the_header_without_a_plan(tmp_path):
    stage_file = tmp_path / "scene.usda"
    make_stage(stage_file)
    out = tmp_path / "eye.exr"
    assert main([str(stage_file), str(out), "-w", "8", "--spp", "1", "-q", "--no-auto-plan"]) == 0
    assert PLAN_ATTRIBUTE not in eyerender._hdeye.read_exr_attributes(str(out))


def test_check_contract_rejects_a_broken_plan():
    with pytest.raises(ValueError):
        check_contract({"eyes": [{"prim": "/e", "pixels": True, "mnee": True, "sss": "none", "limbalArc": False,
                                  "why": {}}]})
    with pytest.raises(ValueError):
        check_contract({"eyes": {}})


def test_eyestudy_writes_table_reference_and_image_and_reuses_the_reference(tmp_path, capsys):
    from eyerender.cli.eyestudy import main as study

    stage_file = tmp_path / "scene.usda"
    make_stage(stage_file)
    out = tmp_path / "shot.exr"
    args = [str(stage_file), str(out), "-w", "8", "--budgets", "0.02,0.05", "--reference-spp", "4", "-q"]
    assert study(args) == 0
    for name in ("shot.exr", "shot.reference.exr", "shot.study.csv", "shot.study.png"):
        assert (tmp_path / name).exists(), name
    rows = list(csv.DictReader((tmp_path / "shot.study.csv").open()))
    assert list(rows[0])[:7] == ["mode", "budget_s", "spp", "seconds", "eye_rel_rmse", "eye_noise", "eye_bias"]
    assert len(rows) == 2 * 2  # two modes x two budgets
    for r in rows:  # two seeds per budget: a noisy 8 px render has noise, and noise and bias make up the RMSE
        rmse, noise, bias = (float(r[f"frame_{k}"]) for k in ("rel_rmse", "noise", "bias"))
        assert noise > 0 and (math.isclose(rmse**2, noise**2 + bias**2, rel_tol=1e-9) or bias == 0 <= noise - rmse), r
    assert PLAN_ATTRIBUTE in eyerender._hdeye.read_exr_attributes(str(out))
    capsys.readouterr()
    stamp = (tmp_path / "shot.reference.exr").stat().st_mtime_ns
    assert study(args) == 0
    assert (tmp_path / "shot.reference.exr").stat().st_mtime_ns == stamp  # reused, not re-rendered
    (tmp_path / "shot.study.png").unlink()
    assert study(args + ["--no-plot"]) == 0
    assert not (tmp_path / "shot.study.png").exists()


def test_session_renders_a_tiny_eye_mesh_at_the_planned_level_and_restores_it_without_a_plan():
    """Sweep refine's rule, applied: a ~6 px eye mesh renders at level 0 under a --complexity high (2) populate,
    re-refined once; a session without a plan renders it at the populate level."""
    import os
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench"))
    import bench_plan
    from eyerender.plan import make_overrides
    from eyerender.render_session import RenderSession

    stage = bench_plan.make_mesh_stage(pixels=6, width=32, angle_deg=70)
    planned = RenderSession(stage, width=32, aovs=("color", "primId"), refine_level=2, settings={"threads": 1},
                            plan_overrides=make_overrides(refine_level_ceiling=2))
    planned.render(spp=1)
    eye = plan_dict(planned.last_plan)["eyes"][0]
    assert eye["refineLevel"] == 0 and eye["applied"]["refineLevel"] == 0
    stats = planned.index.mesh_stats("/World/Eye/Eyeball")
    assert stats["refine_level"] == 0 and stats["refine_level_changes"] == 1, stats
    plain = RenderSession(stage, width=32, refine_level=2, settings={"threads": 1})
    plain.render(spp=1)
    assert plain.index.mesh_stats("/World/Eye/Eyeball")["refine_level"] == 2


def test_the_chamber_walk_is_the_full_64_events_unless_set_and_the_bound_reaches_the_eye():
    # Sweep chamber: the plan keeps the whole walk; chamber_events (what bench_plan.py's chamber sweep drives) wins
    # and is what the eye renders with.
    (eye,) = plan_of(make_stage(lights=(("sphere", 2.0, 75.0),)))["eyes"]
    assert eye["chamberEvents"] == 64 and eye["applied"]["maxChamberEvents"] == 64
    assert "provisional" not in eye["why"]["chamberEvents"], eye["why"]["chamberEvents"]
    (cut,) = plan_of(make_stage(lights=(("sphere", 2.0, 75.0),)), chamber_events=2)["eyes"]
    assert cut["chamberEvents"] == 2 and cut["applied"]["maxChamberEvents"] == 2
    assert cut["why"]["chamberEvents"].startswith("flag")


def test_the_measured_thresholds_are_the_defaults_and_a_large_light_at_60_deg_keeps_mnee():
    # Sweep 2 at 60-75 deg: MNEE still pays for a 0.84 sr light at 60 deg (x1.20) and loses at 70 deg (x0.83), so
    # the grazing bound starts at 65 deg; sweep refine: level 3 never differed from level 2, the cap; sweep sclera
    # at 2.5 and 3 px: the walk's equal-time MSE beats Lambert's in both lights, the cut is 2.5 px.
    rules = eyerender._hdeye.PlanRules()
    assert rules.grazing_angle_deg == 65 and rules.refine_max_level == 2 and rules.sss_min_pixels == 2.5
    (eye,) = plan_of(make_stage(lights=(("sphere", 100.0, 60.0), ("sphere", 100.0, 70.0))))["eyes"]
    strategies = {light["light"]: light["strategy"] for light in eye["lights"]}
    assert strategies == {"/World/key0": "mnee", "/World/key1": "bsdf"}, eye["lights"]
