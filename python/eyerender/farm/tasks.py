"""What runs on a Dask worker: check that the worker reaches the job's files, render a whole frame and write it,
render a sample range of a frame, and merge a split frame's ranges and write it.

Each worker process keeps one RenderSession (stage opened, scene synced) for the last job it served and moves it to
the next frame's time, as eyerecord does on one machine, so a frame costs a stage load only on a worker's first
task of a job. Tasks are idempotent: outputs are written atomically by the _hdeye writers (temporary file, fsync,
rename), so a task rerun after its worker died mid-task, or mid-write, rewrites identical bytes, and a reader never
sees half a file. Progress goes to the client as Dask events on PROGRESS_TOPIC.
"""
import os
import threading
import time as clock

from ..errors import EyeRenderError
from ..job import open_session, open_stage
from .merge import RangeAccumulator, certify, merge

PROGRESS_TOPIC = "eyerender-farm-progress"
_PROGRESS_INTERVAL = 0.25  # seconds between progress events of one task (the last sample is always sent)

# One session per worker process; the lock serialises tasks of a worker that runs several threads (the renderer
# already uses every core, so they would only compete).
_session_lock = threading.Lock()
_cached = {"key": None, "session": None}


def _worker_address():
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):  # called outside a Dask worker (tests, the local fallback)
        return "local"


def _stage_key(job):
    """The job's session options plus the stage file's identity, so an edited stage is reopened."""
    try:
        info = os.stat(job.stage_path)
    except OSError as e:
        raise EyeRenderError(f"stage {job.stage_path} is not reachable from worker {_worker_address()} "
                             f"({e.strerror})") from None
    return (job.stage_path, info.st_mtime_ns, info.st_size, job.session_key())


def check_worker(job, dask_worker=None):
    """Run on every worker (Client.run, which passes dask_worker) before a job: the stage is readable and the
    outputs' folders writable from here. Returns this worker's process id."""
    where = dask_worker.address if dask_worker is not None else _worker_address()
    if not os.path.isfile(job.stage_path):
        raise EyeRenderError(f"stage {job.stage_path} is not reachable from worker {where} (no such file)")
    if not os.access(job.stage_path, os.R_OK):
        raise EyeRenderError(f"stage {job.stage_path} is not readable from worker {where}")
    for out in job.outputs:
        directory = os.path.dirname(out)
        if not os.path.isdir(directory) or not os.access(directory, os.W_OK):
            raise EyeRenderError(f"output folder {directory} is not writable from worker {where}")
    return os.getpid()


def _build_session(job, time):
    """A RenderSession with the job's options, resolved as eyerecord resolves its command line."""
    return open_session(open_stage(job.stage_path), job.session_options(), time)


def _forget_session_on_error(function):
    """A task that fails may leave the cached session half moved to its time: the next task starts afresh."""
    def task(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except BaseException:
            _cached["key"] = _cached["session"] = None
            raise
    task.__name__, task.__qualname__, task.__doc__ = function.__name__, function.__qualname__, function.__doc__
    return task


def _session_for(job, frame):
    """(session, seconds spent loading, time to pass to render()): the cached session when it fits the job."""
    key = _stage_key(job)
    if _cached["key"] == key:
        from pxr import Usd

        return _cached["session"], 0.0, frame if frame is not None else Usd.TimeCode.EarliestTime()
    _cached["key"] = _cached["session"] = None  # free the old stage before loading the new one
    start = clock.perf_counter()
    session = _build_session(job, frame)
    _cached["key"], _cached["session"] = key, session
    return session, clock.perf_counter() - start, None


class _Progress:
    """Sends (samples done) of one task to the client, at most every _PROGRESS_INTERVAL seconds."""

    def __init__(self, job_id, task, frame, total):
        self.job_id, self.task, self.frame, self.total = job_id, task, frame, total
        self.worker = None
        self.last = 0.0
        try:
            from distributed import get_worker

            self.worker = get_worker()
        except (ImportError, ValueError):
            pass

    def __call__(self, done, *_):
        now = clock.monotonic()
        if self.worker is None or (done < self.total and now - self.last < _PROGRESS_INTERVAL):
            return
        self.last = now
        self.worker.log_event(PROGRESS_TOPIC, {"job": self.job_id, "task": self.task, "frame": self.frame,
                                               "samples": done, "worker": self.worker.address, "pid": os.getpid()})


def _frame_stats(session, frame, stats, load_seconds, job):
    return {"frame": frame, "width": session.width, "height": session.height,
            "samples_per_pixel": stats["samples_per_pixel"], "first_sample": stats["first_sample"],
            "render_seconds": stats["seconds"], "rays": stats["rays"],
            "non_finite_samples": stats["non_finite_samples"], "load_seconds": load_seconds,
            "worker": _worker_address(), "pid": os.getpid(), "warnings": list(dict.fromkeys(session.scene.warnings)),
            "outputs": job.output_paths(frame),
            "shutter": session.scene.shutter.describe() if session.scene.shutter.blurred else None}


def write_outputs(job, frame, images, header, manifests=None):
    """Writes frame `frame` of `job` from AOV images ({aov: float32 (h, w, c)}): each plain output with every AOV,
    each render product with exactly its vars; header: the EXR attributes (the render plan), or None; manifests:
    the cryptomatte layers' {name: id bits}."""
    from ..render_session import write_images, write_product_images

    for path, product in job.frame_writes(frame):
        if product is None:
            write_images(path, images, job.exposure, attributes=header, manifests=manifests)
        else:
            write_product_images(path, product, images, header, job.exposure,
                                 settings_path=job.render_settings_prim, manifests=manifests)


@_forget_session_on_error
def render_frame(job, frame, job_id=None, task=None):
    """Renders samples [0, job.spp) of `frame` (None: the stage's earliest time) and writes its outputs.
    Returns the frame's statistics."""
    with _session_lock:
        session, load_seconds, time = _session_for(job, frame)
        progress = _Progress(job_id, task, frame, job.spp)
        stats = session.render(time, spp=job.spp, time_limit=job.time_limit, progress=progress)
        start = clock.perf_counter()
        images = {aov: session.image(aov) for aov in session.aovs}
        write_outputs(job, frame, images, session.header(), session.manifests())
        result = _frame_stats(session, frame, stats, load_seconds, job)
    result.update(write_seconds=clock.perf_counter() - start, tasks=1, merge_seconds=0.0, uncertified_values=0,
                  rerendered_unsplit=False)
    return result


@_forget_session_on_error
def render_samples(job, frame, first_sample, spp, job_id=None, task=None):
    """Renders samples [first_sample, first_sample + spp) of `frame` and returns them accumulated
    ({"stats": ..., "aovs": {aov: RangeAccumulator}}), for `merge_and_write`. One render call with one sample per
    pass: after each pass the buffers (holding that sample alone) go to the accumulators and are cleared, so each
    float sample is read exactly, which the exactness certificates need (merge.py)."""
    from ..render_session import AOV_CHANNELS
    with _session_lock:
        session, load_seconds, time = _session_for(job, frame)
        progress = _Progress(job_id, task, frame, spp)
        accumulators = {aov: RangeAccumulator(session.height, session.width, len(AOV_CHANNELS[aov]))
                        for aov in session.buffer_aovs}
        crypto = _range_coverage(session)

        def take_sample(p):  # one sample per pass: each merged on its own, then the buffers emptied for the next
            for aov, accumulator in accumulators.items():
                accumulator.add(*session.buffer_state(aov))
            if crypto is not None:  # integer counts: merged exactly in any grouping
                _merge_coverage(crypto, session.crypto.tables, session.crypto.manifests)
            session.clear_buffers()
            progress(p.samples_done)

        stats = session.render(time, spp=spp, first_sample=first_sample, on_pass=take_sample, pass_seconds=0)
        stats = {"samples_per_pixel": spp, "first_sample": first_sample, "seconds": stats["seconds"],
                 "rays": stats["rays"], "non_finite_samples": stats["non_finite_samples"]}
        return {"stats": _frame_stats(session, frame, stats, load_seconds, job), "aovs": accumulators,
                "header": session.header(), "crypto": crypto}


def _range_coverage(session):
    """Empty coverage of the session's cryptomatte layers, {"tables": {layer: CoverageTable}, "manifests":
    {layer: {name: id bits}}} (plain data a worker ships), or None without cryptomatte."""
    if not session.crypto:
        return None
    from ..cryptomatte import CoverageTable

    return {"tables": {layer: CoverageTable(session.height, session.width) for layer in session.crypto_layers},
            "manifests": {layer: {} for layer in session.crypto_layers}}


def _merge_coverage(into, tables, manifests):
    for layer, table in into["tables"].items():
        table.merge(tables[layer])
        into["manifests"][layer].update(manifests[layer])


def _merged_coverage(parts):
    """The ranges' cryptomatte coverage merged in sample order: ({layer: encoded image}, manifests), or ({}, {})."""
    if parts[0].get("crypto") is None:
        return {}, {}
    merged = parts[0]["crypto"]
    for part in parts[1:]:
        _merge_coverage(merged, part["crypto"]["tables"], part["crypto"]["manifests"])
    return {layer: table.encode() for layer, table in merged["tables"].items()}, merged["manifests"]


def merge_and_write(job, frame, parts, exact=True, job_id=None, task=None):
    """Merges a frame's sample ranges (render_samples results, in sample order), and writes the outputs. Where a
    value cannot be certified equal to the single-machine render's (merge.py), `exact` re-renders the frame
    unsplit here instead; otherwise such values are within one float32 ulp. Returns the frame's statistics."""
    from ..render_session import resolve_states  # imported on use: pxr after the schema plugin

    start = clock.perf_counter()
    states, uncertified = {}, 0
    for aov in parts[0]["aovs"]:
        sums, counts, abs_sums, grain = merge([p["aovs"][aov] for p in parts])
        uncertified += int((~certify(sums, counts, abs_sums, grain, job.spp)).sum())
        states[aov] = (sums, counts)
    if uncertified and exact:
        result = render_frame(job, frame, job_id, task)
        result.update(uncertified_values=uncertified, rerendered_unsplit=True, tasks=len(parts) + 1)
        return result
    images = resolve_states(states)
    crypto_images, manifests = _merged_coverage(parts)
    images.update(crypto_images)
    merge_seconds = clock.perf_counter() - start
    write_outputs(job, frame, images, parts[0].get("header"), manifests)  # every range planned the frame alike
    stats = [p["stats"] for p in parts]
    return {**stats[0], "samples_per_pixel": sum(s["samples_per_pixel"] for s in stats),
            "render_seconds": sum(s["render_seconds"] for s in stats), "rays": sum(s["rays"] for s in stats),
            "non_finite_samples": sum(s["non_finite_samples"] for s in stats),
            "load_seconds": sum(s["load_seconds"] for s in stats), "worker": _worker_address(), "pid": os.getpid(),
            "range_workers": [s["worker"] for s in stats], "tasks": len(parts) + 1, "merge_seconds": merge_seconds,
            "write_seconds": clock.perf_counter() - start - merge_seconds, "uncertified_values": uncertified,
            "rerendered_unsplit": False}


__all__ = ["PROGRESS_TOPIC", "check_worker", "write_outputs", "render_frame", "render_samples", "merge_and_write"]
