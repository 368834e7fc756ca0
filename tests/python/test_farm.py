"""Rendering on a Dask farm (eyerender.farm, eyerecord --workers/--scheduler), with real processes on 127.0.0.1:
a farm's frames and split frames are bit-identical to the single-machine render, lost workers lose no frame, a bad
frame fails alone, re-runs skip written frames, --strict fails frames on an unreadable texture, and unreachable
schedulers or stages give one-line errors.

Two clusters serve the module: a LocalCluster of 2 worker processes (eyerender.farm.Farm(workers=2)), and a
scheduler plus 2 workers started as `python -m distributed.cli.dask_*` subprocesses, driven through --scheduler.
"""
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
distributed = pytest.importorskip("distributed", reason="the farm extra is not installed (pip install .[farm])")
from pxr import Sdf, Usd, UsdGeom, UsdShade, Vt  # noqa: E402

from eyerender._hdeye import read_exr_attributes  # noqa: E402
from eyerender.cli.eyerecord import main  # noqa: E402
from eyerender.farm import Farm, RenderJob  # noqa: E402
from eyerender.farm.merge import RangeAccumulator, certify, merge  # noqa: E402
from eyerender.farm.tasks import PROGRESS_TOPIC  # noqa: E402

SAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "usd_samples", "squash_stretch.usda")
SAMPLE = os.path.abspath(SAMPLE)
FRAMES = [1.0, 2.0, 3.0, 4.0]
WIDTH, SPP = 24, 2
SCHEDULER_TIMEOUT = 2.0  # s, for the unreachable-scheduler test; the error must come within this plus start-up


def render_local(tmp, frames, spp=SPP, width=WIDTH, name="local"):
    """The single-machine reference: plain eyerecord, one session over the frames."""
    pattern = str(tmp / f"{name}_####.exr")
    spec = ",".join(f"{f:g}" for f in frames)
    assert main([SAMPLE, pattern, "-w", str(width), "--spp", str(spp), "--frames", spec, "-q"]) == 0
    return {f: eyerender.read_exr(pattern.replace("####", f"{int(f):04d}")) for f in frames}


def assert_same_bits(expected, path, what):
    actual = eyerender.read_exr(str(path))
    assert set(actual) == set(expected), what
    for channel, pixels in expected.items():
        differ = np.count_nonzero(pixels.view(np.uint32) != actual[channel].view(np.uint32))
        assert differ == 0, f"{what}: channel {channel}: {differ} of {pixels.size} values differ from the local render"


def subprocess_env():
    """This process's environment (PXR_PLUGINPATH_NAME from conftest), plus the source tree on PYTHONPATH only if
    the workers could not import eyerender otherwise (CI installs the package; developers run from python/)."""
    env = dict(os.environ)
    probe = subprocess.run([sys.executable, "-c", "import eyerender"], env=env, capture_output=True)
    if probe.returncode:
        source = os.path.dirname(os.path.dirname(eyerender.__file__))
        env["PYTHONPATH"] = os.pathsep.join([source] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_worker(address, env):
    # No nanny: a SIGKILLed worker stays dead instead of being restarted, as a lost machine would.
    return subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                             "--no-nanny", "--no-dashboard", "--host", "127.0.0.1"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    return render_local(tmp_path_factory.mktemp("reference"), FRAMES)


@pytest.fixture(scope="module")
def local_farm():
    with Farm(workers=2) as farm:
        yield farm


@pytest.fixture(scope="module")
def scheduler():
    """`dask scheduler` and two `dask worker`s as subprocesses; yields the scheduler address."""
    env = subprocess_env()
    address = f"tcp://127.0.0.1:{free_port()}"
    processes = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                   "--port", address.rsplit(":", 1)[1], "--no-dashboard"],
                                  env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    processes += [start_worker(address, env) for _ in range(2)]
    try:
        # Connecting retries until the scheduler listens; then wait for the workers to register (events, no sleeps).
        with distributed.Client(address, timeout=30, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=30)
        yield address
    finally:
        for p in processes[1:]:
            p.kill()  # workers are disposable; a graceful close would wait for their scheduler connection
        processes[0].terminate()
        for p in processes:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def job_for(tmp, name, spp=SPP, width=WIDTH, stage=SAMPLE):
    return RenderJob(stage, [str(tmp / f"{name}_####.exr")], spp=spp, width=width)


def test_local_cluster_of_two_workers_renders_frames_bit_identical_to_the_local_render(local_farm, reference,
                                                                                       tmp_path):
    report = local_farm.render(job_for(tmp_path, "farm"), FRAMES, split=1)
    assert report.ok, report.errors
    assert sorted(report.stats) == FRAMES and report.workers == 2
    for f in FRAMES:
        assert_same_bits(reference[f], tmp_path / f"farm_{int(f):04d}.exr", f"frame {f}")
        assert report.stats[f]["samples_per_pixel"] == SPP
    assert "4 frame(s) 24x24, 2 spp on 2 worker(s)" in report.summary()


def test_a_frame_split_into_sample_ranges_is_bit_identical_to_the_unsplit_frame(local_farm, tmp_path):
    spp, frame = 7, 9.0  # 7 samples in 3 ranges: 3 + 2 + 2
    expected = render_local(tmp_path, [frame], spp=spp, width=32)[frame]
    # exact=False keeps the merged sums whatever the certificates say: this checks the merge itself. Certified values
    # must be bit-identical; the few a certificate cannot vouch for (a sum near a float32 rounding boundary) must
    # still be within one float32 step.
    stats = local_farm.submit_frame(job_for(tmp_path, "merged", spp=spp, width=32), frame, split=3,
                                    exact=False).result()
    assert stats["tasks"] == 4 and stats["samples_per_pixel"] == spp and not stats["rerendered_unsplit"]
    merged = eyerender.read_exr(str(tmp_path / "merged_0009.exr"))
    total = sum(p.size for p in expected.values())
    assert stats["uncertified_values"] <= total // 1000, f"{stats['uncertified_values']} of {total} uncertified"
    differ = 0
    for channel, pixels in expected.items():
        got = merged[channel]
        differ += np.count_nonzero(pixels.view(np.uint32) != got.view(np.uint32))
        assert np.all(np.abs(got - pixels) <= np.spacing(np.abs(pixels).astype(np.float32))), channel
    assert differ <= stats["uncertified_values"]
    # exact=True (the default): bit for bit, re-rendering unsplit if any value was not certified.
    stats = local_farm.submit_frame(job_for(tmp_path, "split", spp=spp, width=32), frame, split=3).result()
    assert stats["rerendered_unsplit"] == (stats["uncertified_values"] > 0)
    assert_same_bits(expected, tmp_path / "split_0009.exr", "split frame")


def products_stage(tmp):
    """SAMPLE under render settings with two products: the beauty, depth and a cryptomatte of objects; albedo
    (half), normal and the iris light in a multi-part file."""
    from pxr import Gf, UsdRender

    path = tmp / "products.usda"
    stage = Usd.Stage.CreateNew(str(path))
    stage.GetRootLayer().subLayerPaths.append(SAMPLE)
    names = {}
    for name, source, data_type in (("beauty", "color", "color4f"), ("depth", "depth", "float"),
                                    ("albedo", "albedo", "color3h"), ("N", "normal", "normal3f"),
                                    ("iris", "irisMnee", "color3f"), ("objects", "CryptoObject", "float")):
        var = UsdRender.Var.Define(stage, f"/Render/Vars/{name}")
        var.CreateSourceNameAttr(source)
        var.CreateDataTypeAttr(data_type)
        names[name] = var.GetPath()
    products = []
    for name, variables in (("main", ("beauty", "depth", "objects")), ("aovs", ("albedo", "N", "iris"))):
        product = UsdRender.Product.Define(stage, f"/Render/Products/{name}")
        product.CreateProductNameAttr(str(tmp / "local" / f"{name}.####.exr"))
        product.CreateOrderedVarsRel().SetTargets([names[v] for v in variables])
        products.append(product.GetPath())
    stage.GetPrimAtPath(products[1]).CreateAttribute("eyerender:multiPart", Sdf.ValueTypeNames.Bool).Set(True)
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    settings.CreateResolutionAttr(Gf.Vec2i(WIDTH, WIDTH))
    settings.CreateProductsRel().SetTargets(products)
    stage.SetMetadata("renderSettingsPrimPath", "/Render/Settings")
    stage.GetRootLayer().Save()
    (tmp / "local").mkdir()
    return path


def exr_parts_bits(path):
    """{(part, channel): uint32 or uint16 bits} of every channel of every part of an EXR (part None: single)."""
    import OpenEXR

    parts = OpenEXR.File(str(path), separate_channels=True).parts
    return {(part.name(), name): channel.pixels.view(np.uint16 if channel.pixels.dtype == np.float16 else np.uint32)
            for part in parts for name, channel in part.channels.items()}


def test_a_split_frame_of_render_products_merges_every_var_bit_identical_to_the_local_render(local_farm, tmp_path):
    import dataclasses

    from eyerender.cli.eyerecord import build_parser
    from eyerender.job import open_stage, product_sessions, session_options

    pytest.importorskip("OpenEXR", reason="the openexr Python package reads multi-part files")
    stage_path, frame, spp = products_stage(tmp_path), 2.0, 5
    assert main([str(stage_path), "--spp", str(spp), "--frames", "2", "-q"]) == 0
    args = build_parser().parse_args([str(stage_path)])
    ((options, products),) = product_sessions(open_stage(str(stage_path)), session_options(args), print)
    farm_products = tuple(dataclasses.replace(p, name=p.name.replace("/local/", "/")) for p in products)
    job = RenderJob.from_options(str(stage_path), (), options, spp=spp, products=farm_products)
    stats = local_farm.submit_frame(job, frame, split=3).result()
    assert stats["tasks"] >= 4 and stats["samples_per_pixel"] == spp
    for name in ("main.0002.exr", "aovs.0002.exr"):
        expected, merged = exr_parts_bits(tmp_path / "local" / name), exr_parts_bits(tmp_path / name)
        assert set(merged) == set(expected), name
        for key, bits in expected.items():
            assert np.count_nonzero(bits != merged[key]) == 0, f"{name} {key}: differs from the local render"
    assert {c for _, c in exr_parts_bits(tmp_path / "main.0002.exr")} >= {"objects00.R", "objects02.A", "depth"}
    # Merged whatever the float certificates say: the cryptomatte's coverage is integer counts, exact in any split.
    merged_job = dataclasses.replace(job, products=tuple(
        dataclasses.replace(p, name=p.name.replace("/local/", "/merged_")) for p in products))
    stats = local_farm.submit_frame(merged_job, frame, split=3, exact=False).result()
    assert not stats["rerendered_unsplit"]
    expected = exr_parts_bits(tmp_path / "local" / "main.0002.exr")
    merged = exr_parts_bits(tmp_path / "merged_main.0002.exr")
    crypto = [key for key in expected if key[1].startswith("objects")]
    assert len(crypto) == 12 and all(np.array_equal(expected[k], merged[k]) for k in crypto)
    headers = [read_exr_attributes(str(d / "main.0002.exr")) for d in (tmp_path / "local", tmp_path)]
    manifests = [{k: v for k, v in h.items() if k.startswith("cryptomatte/")} for h in headers]
    assert manifests[0] == manifests[1] and len(json.loads(next(v for k, v in manifests[0].items()
                                                                 if k.endswith("manifest")))) >= 2
    assert sorted(part for part, _ in exr_parts_bits(tmp_path / "aovs.0002.exr")) == \
        ["N"] * 3 + ["albedo"] * 3 + ["iris"] * 3


def test_merge_certificates_flag_a_value_on_a_float32_rounding_boundary():
    # Two ranges of one sample each: 1.0 and 2^-30, whose ulp is 2^-53: sum|s| > 2^52 ulp, certificate 1 fails.
    parts = []
    for value in (1.0, 2.0 ** -30):
        acc = RangeAccumulator(1, 1, 1)
        acc.add(np.full((1, 1, 1), value), np.ones((1, 1)))
        parts.append(acc)
    sums, counts, abs_sums, grain = merge(parts)
    assert not (abs_sums < np.ldexp(grain, 52)).any()
    # Far from a float32 boundary: certificate 2 holds.
    assert certify(sums, counts, abs_sums, grain, 2).all()
    # A sum exactly on the midpoint between two float32s (1 + 2^-24, over one sample) cannot be certified.
    midpoint = np.full((1, 1, 1), 1.0 + 2.0 ** -24)
    assert not certify(midpoint, np.ones((1, 1)), midpoint, np.full((1, 1, 1), 2.0 ** -60), 2).any()
    # Exactly summable samples certify even on a boundary; pixels without samples always do.
    assert certify(midpoint, np.ones((1, 1)), midpoint, np.full((1, 1, 1), 2.0 ** -24), 2).all()
    assert certify(midpoint, np.zeros((1, 1)), midpoint, np.full((1, 1, 1), 2.0 ** -60), 2).all()


def test_a_resumed_job_skips_finished_frames_unless_overwrite(local_farm, reference, tmp_path):
    job = job_for(tmp_path, "resume")
    first = local_farm.render(job, FRAMES[:2], split=1)
    assert first.ok and sorted(first.stats) == FRAMES[:2]
    written = {f: os.stat(tmp_path / f"resume_{int(f):04d}.exr").st_mtime_ns for f in FRAMES[:2]}
    again = local_farm.render(job, FRAMES, split=1)
    assert again.skipped == FRAMES[:2] and sorted(again.stats) == FRAMES[2:]
    for f in FRAMES[:2]:
        assert os.stat(tmp_path / f"resume_{int(f):04d}.exr").st_mtime_ns == written[f], f"frame {f} was rewritten"
    for f in FRAMES:
        assert_same_bits(reference[f], tmp_path / f"resume_{int(f):04d}.exr", f"frame {f}")
    forced = local_farm.render(job, FRAMES[:1], split=1, overwrite=True)
    assert forced.skipped == [] and list(forced.stats) == FRAMES[:1]


def sample_with_triangle(path, prim_path):
    """A new stage at `path` over the animated sample, with a triangle mesh (points unset) at prim_path."""
    stage = Usd.Stage.CreateNew(str(path))
    stage.GetRootLayer().subLayerPaths.append(SAMPLE)
    mesh = UsdGeom.Mesh.Define(stage, prim_path)
    mesh.CreateFaceVertexCountsAttr([3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2])
    return stage, mesh


def bad_prim_stage(tmp):
    """The animated sample plus a triangle whose points are NaN at time code 3 only."""
    path = tmp / "bad_frame.usda"
    stage, mesh = sample_with_triangle(path, "/World/Bad")
    points = mesh.CreatePointsAttr()
    good = Vt.Vec3fArray([(0, 0, -50), (1, 0, -50), (0, 1, -50)])
    for frame in FRAMES:
        points.Set(Vt.Vec3fArray([(float("nan"), 0, -50), (1, 0, -50), (0, 1, -50)]) if frame == 3 else good, frame)
    stage.GetRootLayer().Save()
    return path


def test_cli_reports_a_deterministically_failing_frame_once_and_completes_the_others(scheduler, tmp_path, capsys):
    stage = bad_prim_stage(tmp_path)
    out = tmp_path / "bad_####.exr"
    status = main([str(stage), str(out), "-w", str(WIDTH), "--spp", str(SPP), "--frames", "1:4", "--split", "1",
                   "--scheduler", scheduler, "-q"])
    captured = capsys.readouterr()
    errors = [line for line in captured.err.splitlines() if line.startswith("eyerecord: error:")]
    assert status == 1
    assert errors == ["eyerecord: error: frame 3: /World/Bad: points holds NaN or infinite values"], captured.err
    assert [f for f in FRAMES if (tmp_path / f"bad_{int(f):04d}.exr").exists()] == [1.0, 2.0, 4.0]
    assert not [n for n in os.listdir(tmp_path) if n.startswith(".")], "a temporary output was left behind"
    assert "3 frame(s)" in captured.out and "1 failed" in captured.out


def missing_texture_stage(tmp):
    """The animated sample plus a material whose diffuseColor reads a file that does not exist."""
    path = tmp / "missing_texture.usda"
    stage, mesh = sample_with_triangle(path, "/World/Card")
    mesh.CreatePointsAttr(Vt.Vec3fArray([(0, 0, -50), (1, 0, -50), (0, 1, -50)]))
    material = UsdShade.Material.Define(stage, "/World/Looks/card")
    surface = UsdShade.Shader.Define(stage, "/World/Looks/card/surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    texture = UsdShade.Shader.Define(stage, "/World/Looks/card/texture")
    texture.CreateIdAttr("UsdUVTexture")
    texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("missing.png")
    rgb = texture.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(rgb)
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()
    return path


def test_strict_on_the_farm_fails_every_frame_on_an_unreadable_texture_and_writes_nothing(scheduler, tmp_path,
                                                                                           capsys):
    stage = missing_texture_stage(tmp_path)
    args = [str(stage), str(tmp_path / "t_####.exr"), "-w", "8", "--spp", "1", "--frames", "1:2", "--split", "1",
            "--scheduler", scheduler, "-q"]
    assert main(args + ["--strict"]) == 1
    errors = [line for line in capsys.readouterr().err.splitlines() if line.startswith("eyerecord: error:")]
    assert len(errors) == 2 and all("missing.png" in e and len(e) < 200 for e in errors), errors
    assert not [n for n in os.listdir(tmp_path) if n.endswith(".exr")]
    # Without --strict the same job renders, warning once about the texture.
    assert main(args) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "missing.png" in line]
    assert len(warnings) == 1, warnings
    assert sorted(n for n in os.listdir(tmp_path) if n.endswith(".exr")) == ["t_0001.exr", "t_0002.exr"]


def test_cli_on_a_running_scheduler_renders_frames_bit_identical_and_reruns_skip_them(scheduler, reference,
                                                                                       tmp_path, capsys):
    args = [SAMPLE, str(tmp_path / "cli_####.exr"), "-w", str(WIDTH), "--spp", str(SPP), "--frames", "1:4",
            "--scheduler", scheduler, "-q"]
    assert main(args) == 0
    assert "4 frame(s) 24x24, 2 spp on 2 worker(s)" in capsys.readouterr().out
    for f in FRAMES:
        assert_same_bits(reference[f], tmp_path / f"cli_{int(f):04d}.exr", f"frame {f}")
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "0 frame(s) on 2 worker(s)" in out and "4 skipped" in out, out


def test_a_worker_killed_mid_task_loses_no_frame_and_changes_no_pixel(scheduler, tmp_path):
    """A third worker joins the running cluster; the first time it reports a frame half rendered, it is SIGKILLed.
    Its frame must be rerun elsewhere: every frame arrives, once, bit-identical to the local render."""
    frames, spp, width = [5.0, 6.0, 7.0, 8.0, 9.0, 10.0], 48, 32  # ~0.3 s a frame: a kill lands mid-task
    expected = render_local(tmp_path, frames, spp=spp, width=width, name="ref")
    victim = start_worker(scheduler, subprocess_env())
    killed = {}
    caught = threading.Event()
    try:
        with distributed.Client(scheduler, timeout=30, set_as_default=False) as client, \
                distributed.Client(scheduler, timeout=30, set_as_default=False) as watcher:
            client.wait_for_workers(3, timeout=30)

            def on_progress(event):
                message = event[1]
                if message["pid"] == victim.pid and 0 < message["samples"] < spp and not caught.is_set():
                    killed.update(message)
                    os.kill(victim.pid, signal.SIGKILL)
                    caught.set()

            # A second client watches the progress events (Farm.render subscribes its own client's handler).
            watcher.subscribe_topic(PROGRESS_TOPIC, on_progress)
            job = RenderJob(SAMPLE, [str(tmp_path / "kill_####.exr")], spp=spp, width=width)
            report = Farm(client=client).render(job, frames, split=1)
    finally:
        victim.kill()
        victim.wait()
    assert caught.is_set(), "the extra worker was never seen mid-frame"
    assert report.ok, report.errors
    assert sorted(report.stats) == frames
    assert report.stats[killed["frame"]]["pid"] != victim.pid, "the killed worker's frame was not rerun elsewhere"
    for f in frames:
        assert_same_bits(expected[f], tmp_path / f"kill_{int(f):04d}.exr", f"frame {f}")
    assert not [n for n in os.listdir(tmp_path) if n.startswith(".")], "a temporary output was left behind"


def test_a_stage_workers_cannot_reach_is_a_one_line_error(scheduler, tmp_path, capsys):
    missing = tmp_path / "elsewhere" / "shot.usda"
    assert main([str(missing), str(tmp_path / "x.exr"), "--scheduler", scheduler, "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and \
        err[0].startswith(f"eyerecord: error: stage {missing} is not reachable from worker tcp://"), err


def test_an_unreachable_scheduler_is_a_one_line_error_within_the_timeout(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
    start = time.monotonic()
    status = main([SAMPLE, str(tmp_path / "x.exr"), "--scheduler", address, "--scheduler-timeout",
                   str(SCHEDULER_TIMEOUT), "-q"])
    seconds = time.monotonic() - start
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 1
    assert len(err) == 1 and err[0].startswith(f"eyerecord: error: cannot reach the Dask scheduler at {address} "
                                               f"within {SCHEDULER_TIMEOUT:g} s"), err
    assert seconds < SCHEDULER_TIMEOUT + 3, f"gave up after {seconds:.1f} s"
