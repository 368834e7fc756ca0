"""eyeview's server and render loop over plain HTTP: the page, the state and the frames are served while the render
converges; an edit goes through the session layer (the image changes, "save" writes a .usda that reproduces it
sublayered over the stage); bad edits and clients that go away never end the render or reach the stage."""
import json
import socket
import time
import urllib.error
import urllib.request

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Sdf, Usd, UsdGeom  # noqa: E402

from eyerender.cli import eyeview  # noqa: E402
from eyeview_fixture import RunningView, eye_stage  # noqa: E402


@pytest.fixture
def view(tmp_path):
    running = RunningView(eye_stage(tmp_path / "eye.usda"), tmp_path / "look.usda")
    yield running
    running.close()


def get(view, path):
    with urllib.request.urlopen(view.url + path.lstrip("/"), timeout=10) as reply:
        return reply.status, reply.read()


def post(view, path, body):
    data = body if isinstance(body, bytes) else json.dumps(body).encode()
    request = urllib.request.Request(view.url + path.lstrip("/"), data=data, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=10) as reply:
            return reply.status, json.loads(reply.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def state(view):
    return json.loads(get(view, "/state")[1])


def wait_for(condition, timeout=20.0, what="the condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"{what} did not happen within {timeout} s")


def frame_after(view, samples):
    """The snapshot's pixels once the render holds `samples` samples after the last edit."""
    wait_for(lambda: state(view)["samples"] >= samples, what=f"{samples} samples")
    return view.viewer.snapshot.pixels.copy()


def test_the_page_state_and_a_png_frame_are_served_while_samples_grow(view):
    status, page = get(view, "/")
    assert status == 200 and b"EventSource" in page
    first = wait_for(lambda: state(view)["samples"], what="a first pass")
    status, png = get(view, "/frame.png?exposure=1")
    assert status == 200 and png[:8] == b"\x89PNG\r\n\x1a\n"
    later = wait_for(lambda: state(view)["samples"] > first and state(view)["samples"], what="more samples")
    now = state(view)  # while converging, the page has this render's times and rate
    assert 0 < now["time_to_preview"] <= now["time_to_first_pixel"] < 10 and now["samples_per_second"] > 0, now
    names = [c["name"] for c in state(view)["controls"]]
    assert {"keyAzimuth", "keyIntensity", "cameraAzimuth", "pupil", "limbusInner", "irisDepth", "gazeYaw"} <= \
        set(names), names
    assert later > first


def test_an_edit_changes_the_image_and_save_writes_a_layer_that_reproduces_it(view, tmp_path):
    before = frame_after(view, 4)
    assert post(view, "/edit", {"name": "pupil", "value": 9.0}) == (200, {"ok": True, "message": ""})
    after = frame_after(view, 4)
    assert np.abs(after - before).mean() > 0.01  # a 9 mm pupil: much more of the iris is black
    status, answer = post(view, "/save", {})
    assert status == 200 and "look.usda" in answer["message"]
    layer = Sdf.Layer.FindOrOpen(str(tmp_path / "look.usda"))
    assert layer.GetAttributeAtPath("/World/Eye.eye:pupilDiameter").default == 9.0
    over = Usd.Stage.Open(Sdf.Layer.CreateAnonymous())
    over.GetRootLayer().subLayerPaths = [str(tmp_path / "look.usda"), str(tmp_path / "eye.usda")]
    assert over.GetPrimAtPath("/World/Eye").GetAttribute("eye:pupilDiameter").Get() == 9.0
    assert Sdf.Layer.FindOrOpen(str(tmp_path / "eye.usda")).GetAttributeAtPath(
        "/World/Eye.eye:pupilDiameter") is None  # the stage's own layer is untouched


def test_a_light_move_is_authored_in_the_session_layer_and_moves_the_light(view, tmp_path):
    frame_after(view, 2)
    assert post(view, "/edit", {"name": "keyAzimuth", "value": -120})[0] == 200
    wait_for(lambda: state(view)["samples"] >= 2, what="a render after the edit")
    post(view, "/save", {})
    over = Usd.Stage.Open(Sdf.Layer.CreateAnonymous())
    over.GetRootLayer().subLayerPaths = [str(tmp_path / "look.usda"), str(tmp_path / "eye.usda")]
    moved = UsdGeom.Xformable(over.GetPrimAtPath("/World/key")).ComputeLocalToWorldTransform(0).ExtractTranslation()
    assert moved[0] < 0 and abs(moved.GetLength() - (20 ** 2 + 10 ** 2 + 30 ** 2) ** 0.5) < 1e-6  # same distance


@pytest.mark.parametrize("name, value, says", [
    ("pupil", "nan", "not a finite number"),
    ("pupil", 20, "outside"),
    ("pupil", "wide", "not a number"),
    ("limbusInner", 0.95, "outside its valid range (0, eye:limbusOuterRatio"),
    ("noSuchControl", 1, "no control"),
])
def test_a_bad_edit_is_one_message_and_neither_reaches_the_stage_nor_stops_the_render(view, name, value, says):
    frame_after(view, 2)
    status, answer = post(view, "/edit", {"name": name, "value": value})
    assert status == 400 and says in answer["message"], answer
    assert says in state(view)["message"]
    assert view.viewer.editor.layer.GetAttributeAtPath("/World/Eye.eye:pupilDiameter") is None
    assert view.viewer.editor.layer.GetAttributeAtPath("/World/Eye.eye:limbusInnerRatio") is None
    samples = state(view)["samples"]
    wait_for(lambda: state(view)["samples"] > samples, what="the render going on")
    assert view.loop.is_alive()


def test_a_malformed_request_is_a_400_with_one_line(view):
    status, answer = post(view, "/edit", b"{not json")
    assert status == 400 and answer["message"].startswith("bad request")
    assert post(view, "/aov", {"aov": "nope"})[0] == 400
    assert post(view, "/aov", {"aov": "irisMnee"})[0] == 200
    assert wait_for(lambda: state(view)["aov"] == "irisMnee")


def test_a_client_that_drops_the_event_stream_does_not_end_the_render(view):
    host, port = view.server.server_address
    for _ in range(3):
        with socket.create_connection((host, port), timeout=5) as s:
            s.sendall(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
            received = b""
            while b"data: " not in received:  # the headers, then the first event
                chunk = s.recv(4096)
                assert chunk, received
                received += chunk
    samples = wait_for(lambda: state(view)["samples"], what="a pass")
    wait_for(lambda: state(view)["samples"] > samples, what="the render going on")


def test_pause_keeps_the_samples_and_resume_continues_from_them(view):
    frame_after(view, 3)
    assert post(view, "/pause", {"paused": True})[0] == 200
    paused = wait_for(lambda: state(view)["paused"] and state(view)["samples"], what="the pause")
    time.sleep(0.5)
    assert state(view)["samples"] == paused
    post(view, "/pause", {"paused": False})
    wait_for(lambda: state(view)["samples"] > paused, what="the render resuming")
    counts = view.viewer.session.buffer_state("color")[1]
    assert counts.min() >= paused  # the samples before the pause are still in the buffers


def test_the_command_line_says_what_is_wrong_in_one_line(tmp_path, capsys):
    assert eyeview.main([str(tmp_path / "missing.usda"), "--port", "0"]) == 1
    assert eyeview.main([eye_stage(tmp_path / "eye.usda"), "--port", "70000"]) == 1
    assert eyeview.main([str(tmp_path / "eye.usda"), "--save", "out.exr"]) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 3 and all(line.startswith("eyeview: error: ") for line in lines), lines
