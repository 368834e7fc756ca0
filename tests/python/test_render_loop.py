"""RenderSession.render runs the delegate's progressive loop: one call gathers the stage's edits, the plan, the
materials and lights, then renders passes with the GIL released; callbacks run between passes (never per sample),
a stop request from another thread ends it after a pass, resume keeps the samples, and the image is the same for
any pass split. Time to first pixel and samples per second are reported and written in the EXR header."""
import threading

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, UsdGeom  # noqa: E402

import skel_stages as ss  # noqa: E402
from eyerender import RenderSession  # noqa: E402


def card_stage():
    stage = ss.base_stage()
    ss.strip_mesh(stage, "/World/card", segments=2, length=1.5, height=1.0)
    return stage


def session(stage=None, **kwargs):
    return RenderSession(stage or card_stage(), width=48, height=36, settings={"threads": 2}, **kwargs)


def test_passes_of_any_size_give_the_image_of_one_sample_per_pass_with_one_callback_per_pass():
    one_per_pass, calls = session(), []
    one_per_pass.render(spp=24, pass_seconds=0, progress=lambda done, total, s: calls.append(done))
    assert calls == list(range(1, 25))  # pass_seconds 0: a pass per sample
    grown, grown_calls = session(), []
    grown.render(spp=24, pass_seconds=10.0, progress=lambda done, total, s: grown_calls.append(done))
    assert grown_calls[0] == 1 and grown_calls[-1] == 24
    assert len(grown_calls) <= 6, grown_calls  # 1, 2, 4, 8, 9: far fewer Python calls than samples
    assert np.array_equal(one_per_pass.image("color"), grown.image("color"))


def test_a_callback_returning_false_stops_after_that_pass_and_resume_continues_to_the_same_image():
    whole = session()
    whole.render(spp=12)
    paused = session()
    stats = paused.render(spp=12, pass_seconds=0, progress=lambda done, total, s: done < 5)
    assert stats["samples_per_pixel"] == 5 and stats["stopped"]
    stats = paused.render(spp=7, resume=True)
    assert stats["samples_per_pixel"] == 12 and stats["first_sample"] == 0
    assert np.array_equal(whole.image("color"), paused.image("color"))


def test_a_stage_edit_between_pause_and_resume_restarts_the_render():
    stage = card_stage()
    s = session(stage)
    s.render(spp=4)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/key")).GetOrderedXformOps()[0].Set(Gf.Vec3d(-3, -1, 2))
    stats = s.render(spp=3, resume=True)
    assert stats["samples_per_pixel"] == 3 and stats["stage_changes"] == {"transform": 1}
    fresh = session(stage)
    fresh.render(spp=3)
    assert np.array_equal(s.image("color"), fresh.image("color"))


def test_a_stop_requested_from_another_thread_ends_the_render_while_python_threads_run():
    s = session()
    ticks = []

    def worker():  # runs only if the render released the GIL
        while len(ticks) < 3:
            ticks.append(1)
            threading.Event().wait(0.01)
        s.request_stop()

    def first_pass(p):
        if p.samples_done == 1:
            threading.Thread(target=worker).start()

    stats = s.render(spp=1 << 20, on_pass=first_pass, pass_seconds=0.02)
    assert stats["stopped"] and len(ticks) == 3
    assert 1 <= stats["samples_per_pixel"] < 1 << 20
    counts = s.buffer_state("color")[1]
    assert counts.min() == counts.max() == stats["samples_per_pixel"]  # whole passes only
    assert not s.stop_flag.requested  # cleared: the next render runs
    assert s.render(spp=2)["samples_per_pixel"] == 2


def test_an_exception_in_the_callback_ends_the_render_and_is_raised_to_the_caller():
    s = session()

    def fail(p):
        raise ValueError("from the callback")

    with pytest.raises(ValueError, match="from the callback"):
        s.render(spp=8, on_pass=fail)
    assert s.render(spp=2)["samples_per_pixel"] == 2


def test_time_to_first_pixel_and_samples_per_second_are_reported_and_in_the_exr_header(tmp_path):
    import OpenEXR

    s = session()
    stats = s.render(spp=8, progress=lambda *a: None)
    assert 0 < stats["time_to_first_pixel"] <= stats["seconds"]
    assert stats["samples_per_second"] > 0
    s.write(str(tmp_path / "loop.exr"))
    header = OpenEXR.InputFile(str(tmp_path / "loop.exr")).header()
    value = header["eyerender:timeToFirstPixel"]
    value = value.decode() if isinstance(value, bytes) else value
    assert value.endswith(" s") and float(value.split()[0]) == pytest.approx(stats["time_to_first_pixel"], abs=1e-4)
    assert float(header["eyerender:samplesPerSecond"]) > 0


def test_a_time_limit_stops_between_passes_after_the_first():
    s = session()
    stats = s.render(spp=1 << 20, time_limit=0.3)
    assert stats["time_limit_reached"] and not stats["stopped"]
    assert stats["samples_per_pixel"] >= 1
    assert stats["seconds"] < 0.3 + 0.5  # a pass aims at no more than the time left


def test_a_first_pass_in_stages_shows_the_coarse_grid_first_and_gives_the_same_image():
    from eyerender.viewer import block_fill

    plain, staged, strides = session(), session(), []

    def on_pass(p):
        if p.stride > 1:
            counts = staged.buffer_state("color")[1]
            on_grid = np.zeros_like(counts, dtype=bool)
            on_grid[::p.stride, ::p.stride] = True
            strides.append((p.stride, bool((counts[on_grid] == 1).all() and (counts[~on_grid] == 0).all())))
            shown = block_fill(staged.image("color"), p.stride)
            assert shown.shape == staged.image("color").shape and (shown[:p.stride, :p.stride] == shown[0, 0]).all()

    plain.render(spp=6)
    stats = staged.render(spp=6, on_pass=on_pass, first_pass_stride=4)
    assert strides == [(4, True), (2, True)]  # each stage: its grid's pixels have the sample, the others not yet
    assert 0 < stats["time_to_preview"] <= stats["time_to_first_pixel"]
    assert np.array_equal(plain.image("color"), staged.image("color"))


def test_a_planned_render_reports_the_stage_edits_it_applied():
    # The plan syncs the stage again before rendering; the summary still counts the edits this render took in.
    import eyerender.plan

    stage = card_stage()
    s = session(stage, plan_overrides=eyerender.plan.make_overrides())
    s.render(spp=1)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/key")).GetOrderedXformOps()[0].Set(Gf.Vec3d(-3, -1, 2))
    assert s.render(spp=1)["stage_changes"] == {"transform": 1}
