"""End to end: every sample stage renders through eyerecord's session at a small size, with light where it should
be (eyes get iris light through MNEE), nothing non-finite, and the animated eye re-syncs only its points."""
import pathlib

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Usd  # noqa: E402

SAMPLES = pathlib.Path(__file__).resolve().parents[2] / "usd_samples"
EYE_STAGES = ["closeup", "two_eyes", "squash_stretch", "side_lit", "analytic_anterior", "studio_eye_rig", "saccade",
              "blink", "production_head"]


def render(name, width=40, spp=2, **kwargs):
    stage = Usd.Stage.Open(str(SAMPLES / f"{name}.usda"))
    session = eyerender.RenderSession(stage, width=width, aovs=["irisMnee", "primId"], time=stage.GetStartTimeCode(),
                                      refine_level=1, **kwargs)
    stats = session.render(spp=spp)
    return session, stats


@pytest.mark.parametrize("name", EYE_STAGES + ["glass_sphere_table"])
def test_sample_renders(name):
    session, stats = render(name)
    color = session.image("color")
    assert stats["non_finite_samples"] == 0 and np.isfinite(color).all()
    assert color[:, :, 3].mean() > 0.2  # geometry fills a good part of the frame
    assert color[:, :, :3].mean() > 1e-3  # and is lit
    if name in EYE_STAGES:
        assert session.scene.eyes, "the stage's eyes were not found"
        assert session.image("irisMnee").max() > 0, "no iris light came through MNEE"
    else:
        assert not session.scene.eyes


def test_animated_eye_resyncs_points_only():
    session, _ = render("squash_stretch", width=24, spp=1)
    eye = session.scene.eyes[0]
    before = session.index.mesh_stats(eye)
    counts = session.scene.set_time(12)
    session.render(spp=1)
    after = session.index.mesh_stats(eye)
    assert counts["points"] == 1 and "topology" not in counts and "transform" not in counts
    assert after["stencil_evaluations"] == before["stencil_evaluations"] + 1
    assert after["refinements"] == before["refinements"]  # topology refined once


def test_saccade_blurs_the_frame_whose_shutter_sees_the_eye_turn_and_no_other():
    def image(frame, shutter):
        stage = Usd.Stage.Open(str(SAMPLES / "saccade.usda"))
        session = eyerender.RenderSession(stage, width=32, time=frame, refine_level=1, shutter=shutter)
        session.render(spp=2)
        return session.image("color")

    assert np.array_equal(image(10, None), image(10, (0.0, 0.0)))  # still through frame 10's shutter
    blurred, sharp = image(11, None), image(11, (0.0, 0.0))
    assert np.isfinite(blurred).all()
    assert np.abs(blurred - sharp).mean() > 0.05 * sharp.mean(), (np.abs(blurred - sharp).mean(), sharp.mean())
