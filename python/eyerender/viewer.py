"""eyeview's render loop: a RenderSession rendered progressively on the thread that runs `Viewer.run`, with every
stage edit, save and pause asked for by the web server's threads queued here and carried out between passes on the
render thread (USD is only ever touched there). A snapshot of the chosen AOV is taken between passes for the page;
an edit ends the current render after its pass, and the next render restarts from what the edit dirtied (the
session's stage notices); pause stops after a pass and resume continues with the samples kept.

A bad edit (view_edits refuses it, or the render then fails on it) is one message for the page and is undone; a
failure of the render itself is one message, and the loop waits for the next edit: the loop never ends on its own."""
import collections
import queue
import threading
import time as clock

from .errors import EyeRenderError

SNAPSHOT_INTERVAL = 0.15  # seconds between snapshots for the page (each pass ends within about PASS_SECONDS)
PASS_SECONDS = 0.1  # what a pass aims at: short enough for an edit to be seen within a second
FIRST_PASS_STRIDE = 4  # the first pass after an edit shows every 4th pixel's sample, then every 2nd, then all
VIEW_AOVS = ("color", "irisMnee", "limbalArc", "albedo")


class Snapshot:
    """The latest image of the render for the page, with what the page prints about it."""

    def __init__(self):
        self.lock = threading.Condition()
        self.version = 0
        self.pixels = None  # float32 (h, w, 3) of `aov`
        self.aov = "color"
        self.status = {}
        self.message = ""

    def publish(self, pixels=None, aov=None, **status):
        with self.lock:
            if pixels is not None:
                self.pixels, self.aov = pixels, aov
            self.status.update(status)
            self.version += 1
            self.lock.notify_all()

    def say(self, message):
        with self.lock:
            self.message = message
        self.publish()

    def state(self):
        with self.lock:
            return {"version": self.version, "aov": self.aov, "message": self.message, **self.status}

    def wait(self, version, timeout):
        """Waits until the version passes `version` (or timeout seconds); returns the state."""
        with self.lock:
            self.lock.wait_for(lambda: self.version != version, timeout)
        return self.state()


def block_fill(pixels, stride):
    """An image whose pixels on the stride grid (x and y multiples of `stride`) each fill their stride x stride
    block: a coarse stage of a first pass shown over the whole frame."""
    import numpy as np

    grid = pixels[::stride, ::stride]
    height, width = pixels.shape[:2]
    return np.ascontiguousarray(np.repeat(np.repeat(grid, stride, 0), stride, 1)[:height, :width])


class Viewer:
    """The render side of eyeview: session (a RenderSession), editor (a view_edits.StageEditor)."""

    def __init__(self, session, editor, spp=4096):
        self.session, self.editor, self.spp = session, editor, spp
        self.snapshot = Snapshot()
        self.requests = queue.Queue()  # (kind, payload, reply) from the server's threads
        self.aov = "color"
        self.paused = False
        self.stopping = threading.Event()
        self._taken = 0.0
        self._base = 0
        self._started = clock.perf_counter()
        self._last_edit = collections.deque(maxlen=1)  # (name, previous value) of the last edit applied
        self.plan_lines = session.last_plan.summary_lines() if session.last_plan is not None else []
        self.snapshot.status = {"samples": 0, "target": spp, "paused": False, "plan": [], "width": session.width,
                                "height": session.height}

    # Called from any thread.
    def ask(self, kind, payload=None, timeout=10.0):
        """Queues a request for the render thread and waits for its reply: (ok, message)."""
        reply = queue.Queue(maxsize=1)
        self.requests.put((kind, payload, reply))  # the render ends after its pass and takes it (_on_pass)
        try:
            return reply.get(timeout=timeout)
        except queue.Empty:
            return False, f"{kind}: the renderer did not answer within {timeout:g} s"

    def stop(self):
        self.stopping.set()
        self.session.request_stop()

    # The render thread.
    def run(self):
        """Renders until stop(); between renders takes the queued requests."""
        resume = False
        while not self.stopping.is_set():
            restart = self._take_requests()
            if self.paused or (resume and not restart and self._converged()):
                self._wait_for_request()
                continue
            resume = self._render(resume and not restart)

    def _converged(self):
        stats = self.session.stats
        return stats is not None and stats["samples_per_pixel"] >= self.spp

    def _wait_for_request(self):
        try:
            request = self.requests.get(timeout=0.25)
        except queue.Empty:
            return
        self.requests.put(request)  # taken, in order, by the next _take_requests

    def _render(self, resume):
        """One render call; returns whether the next may resume it (False after a failure: restart)."""
        done = self.session.stats["samples_per_pixel"] if resume and self.session.stats else 0
        self._base = done  # the samples the buffers held before this call
        self._started = clock.perf_counter()
        if not resume:  # the times the page shows are this render's, from its call (sync and plan included)
            self.snapshot.publish(time_to_preview=None, time_to_first_pixel=None)
        try:
            self.session.render(spp=max(1, self.spp - done), resume=resume, on_pass=self._on_pass,
                                pass_seconds=PASS_SECONDS, first_pass_stride=FIRST_PASS_STRIDE)
        except EyeRenderError as e:
            self._undo_last_edit(f"the render failed: {e}")
            return False
        self._publish(final=True)
        return True

    def _on_pass(self, progress):
        now = clock.perf_counter()
        if progress.stride > 1:  # a stage of the first pass: the coarse grid's samples, each over its block
            self._publish(progress=progress)
            return True
        first = progress.samples_done == progress.pass_samples
        if first and self.session.last_plan is not None:  # planned at the start of this render
            self.plan_lines = self.session.last_plan.summary_lines()
        if first or now - self._taken >= SNAPSHOT_INTERVAL:
            self._taken = now
            self._publish(progress=progress)
        return self.requests.empty() and not self.stopping.is_set()

    def _publish(self, progress=None, final=False):
        pixels = self.session.image(self.aov)[:, :, :3]
        if progress is not None and progress.stride > 1:
            pixels = block_fill(pixels, progress.stride)
        else:
            pixels = pixels.copy()
        stats = self.session.stats or {}
        done = self._base + progress.samples_done if progress else stats.get("samples_per_pixel", 0)
        status = {"samples": done, "target": self.spp, "paused": self.paused, "plan": self.plan_lines,
                  "width": self.session.width, "height": self.session.height}
        status.update(self._timing(progress))
        if final and stats:
            status["samples_per_second"] = stats["samples_per_second"]
        self.snapshot.publish(pixels, self.aov, **status)

    def _timing(self, progress):
        """What the page prints of a pass: the preview's stride, the times to the first image (its first stage) and
        to every pixel's first sample, and the samples per second so far."""
        if progress is None:
            return {"preview": ""}
        since = clock.perf_counter() - self._started
        timing = {"preview": f"1/{progress.stride}" if progress.stride > 1 else ""}
        if progress.stride == FIRST_PASS_STRIDE and progress.stride > 1:
            timing["time_to_preview"] = since
        if progress.stride == 1 and progress.samples_done == progress.pass_samples and self._base == 0:
            timing["time_to_first_pixel"] = since
        if progress.stride == 1 and progress.seconds > 0:
            pixels = self.session.width * self.session.height
            timing["samples_per_second"] = pixels * progress.samples_done / progress.seconds
        return timing

    def _take_requests(self):
        """Carries out the queued requests; returns whether one of them changed the stage (a restart)."""
        restart = False
        while True:
            try:
                kind, payload, reply = self.requests.get_nowait()
            except queue.Empty:
                return restart
            ok, message = self._carry_out(kind, payload)
            if ok and kind == "edit":
                restart = True
                self.snapshot.publish(samples=0)  # the samples shown from now on are the edited stage's
            if kind in ("edit", "save") or not ok:
                self.snapshot.say(message)
            reply.put((ok, message))

    def _carry_out(self, kind, payload):
        try:
            if kind == "edit":
                name, value = payload
                previous = self.editor.controls[name].value if name in self.editor.controls else None
                self.editor.apply(name, value)
                self._last_edit.append((name, previous))
                return True, ""
            if kind == "aov":
                if payload not in self.session.aovs:
                    return False, f"no AOV '{payload}' (rendered: {', '.join(self.session.aovs)})"
                self.aov = payload
                self._publish()
                return True, ""
            if kind == "pause":
                self.paused = bool(payload)
                self._publish()
                return True, ""
            if kind == "save":
                return True, f"saved the session layer to {self.editor.save(payload)}"
        except EyeRenderError as e:
            return False, str(e)
        return False, f"unknown request '{kind}'"

    def _undo_last_edit(self, message):
        """A render that failed after an edit: the edit is undone (the last good state) and the page told."""
        if self._last_edit:
            name, previous = self._last_edit.pop()
            try:
                self.editor.apply(name, previous)
                message += f"; {name} is back to {previous:g}"
            except EyeRenderError as e:
                message += f"; undoing {name} failed too: {e}"
        self.snapshot.say(message)


__all__ = ["Viewer", "Snapshot", "VIEW_AOVS", "PASS_SECONDS", "block_fill"]
