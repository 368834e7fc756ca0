"""Rendering on a Dask cluster: frames as tasks, heavy frames split into sample ranges merged exactly.

    from eyerender.farm import Farm, RenderJob

    job = RenderJob("/show/shot.usda", ["/show/out/shot.####.exr"], spp=64, width=960)
    with Farm(scheduler="tcp://farm:8786") as farm:          # or Farm(workers=4): a local cluster
        report = farm.render(job, frames=range(1, 25))      # skips frames already written
        print(report.summary(), report.errors)

    future = farm.submit_frame(job, 12, split=4)             # one frame: a future of its statistics
    part = farm.submit_samples(job, 12, first_sample=0, spp=16)  # one sample range, not written

Workers open the stage and write the outputs themselves, so both paths must be reachable from every worker (a shared
file system); `render` checks that on every worker first. A task whose worker dies is rerun elsewhere by the Dask
scheduler (outputs are written atomically, so never half-written); a task that raises fails its frame alone, and the
report names the frame and the error. Samples of a split frame are a pure function of (seed, pixel, sample index),
so the merged frame is the unsplit frame, certified bit for bit (merge.py); `exact=False` accepts values within one
float32 ulp instead of re-rendering a frame the certificate cannot cover.
"""
import dataclasses
import math
import os
import threading
import time as clock
import uuid
from typing import Callable, Optional

from ..errors import EyeRenderError
from . import tasks
from .job import RenderJob, split_samples


@dataclasses.dataclass
class Progress:
    """Where a job is: frames finished of the frames to render, samples per pixel rendered summed over them."""
    frames_done: int
    frames_total: int
    samples_done: int
    samples_total: int
    seconds: float

    @property
    def eta(self):
        """Seconds left at the rate so far (None before the first sample)."""
        if not self.samples_done:
            return None
        return self.seconds / self.samples_done * (self.samples_total - self.samples_done)


@dataclasses.dataclass
class FarmReport:
    """The outcome of Farm.render: per-frame statistics, per-frame one-line errors, frames skipped as written."""
    frames: list[Optional[float]]
    stats: dict[Optional[float], dict]
    errors: dict[Optional[float], str]
    skipped: list[Optional[float]]
    seconds: float
    workers: int
    split: int

    @property
    def ok(self):
        return not self.errors

    def summary(self):
        rendered = len(self.stats)
        rays = sum(s["rays"] for s in self.stats.values())
        size = next((f"{s['width']}x{s['height']}, " for s in self.stats.values()), "")
        spp = next((f"{s['samples_per_pixel']} spp " for s in self.stats.values()), "")
        split = f", split {self.split}" if self.split > 1 else ""
        shutter = next((f", {s['shutter']}" for s in self.stats.values() if s.get("shutter")), "")
        return (f"{rendered} frame(s) {size}{spp}on {self.workers} worker(s){split}{shutter}, {self.seconds:.1f} s, "
                f"{rays / self.seconds / 1e6 if self.seconds > 0 else 0.0:.2f} Mrays/s, "
                f"{len(self.skipped)} skipped, {len(self.errors)} failed")


def _one_line(error):
    """An exception from a worker as one line for a report."""
    from distributed import KilledWorker

    if isinstance(error, KilledWorker):
        return "its workers kept dying while rendering it (out of memory or killed?)"
    text = str(error).strip().splitlines()
    message = text[0] if text else ""
    return message if isinstance(error, EyeRenderError) else f"{type(error).__name__}: {message}"


class Farm:
    """A connection to a Dask cluster that renders RenderJobs. Give one of: scheduler (an address, e.g.
    tcp://host:8786), workers (start a local cluster of that many worker processes), client (a distributed.Client
    the caller owns). timeout: seconds to wait for the scheduler."""

    def __init__(self, scheduler=None, workers=None, client=None, timeout=10.0):
        try:
            import distributed
        except ImportError:
            raise EyeRenderError("rendering on a farm needs dask and distributed: pip install 'eyerender[farm]'") \
                from None
        self._cluster, self._owns_client = None, client is None
        if client is not None:
            self.client = client
        elif scheduler:
            try:
                self.client = distributed.Client(scheduler, timeout=timeout, set_as_default=False)
            except (OSError, TimeoutError) as e:
                raise EyeRenderError(f"cannot reach the Dask scheduler at {scheduler} within {timeout:g} s "
                                     f"({str(e).splitlines()[0] if str(e) else type(e).__name__})") from None
        elif workers:
            # One thread per worker process: the renderer uses every core itself. Logs are silenced: errors come in
            # the report.
            self._cluster = distributed.LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                                                     dashboard_address=None, silence_logs=50)
            self.client = distributed.Client(self._cluster, set_as_default=False)
        else:
            raise EyeRenderError("a farm needs a scheduler address or a number of local workers")

    def close(self):
        if self._owns_client:
            self.client.close()
        if self._cluster is not None:
            self._cluster.close()

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.close()

    # -- the building blocks ----------------------------------------------------------------------------------------

    def worker_threads(self):
        """Task slots: the workers' threads summed."""
        return sum(w["nthreads"] for w in self.client.scheduler_info()["workers"].values())

    def check_workers(self, job, timeout=60.0):
        """Waits up to `timeout` s for a worker, then checks on every worker that it reaches the stage and the
        output folders. Returns {worker address: process id}."""
        try:
            self.client.wait_for_workers(1, timeout=timeout)
        except TimeoutError:
            raise EyeRenderError(f"no Dask worker joined the scheduler within {timeout:g} s") from None
        return self.client.run(tasks.check_worker, job)

    def submit_samples(self, job, frame, first_sample, spp, job_id=None, priority=0):
        """A future of samples [first_sample, first_sample + spp) of `frame`, accumulated (tasks.render_samples);
        nothing is written. Merge such futures, in sample order, with submit_merge."""
        job_id = job_id or uuid.uuid4().hex
        task = f"eyerender-samples-{frame}-{first_sample}-{job_id}"
        return self.client.submit(tasks.render_samples, job, frame, first_sample, spp, job_id, task,
                                  key=task, priority=priority)

    def submit_merge(self, job, frame, parts, exact=True, job_id=None, priority=0):
        """A future of the statistics of `frame` once its sample-range futures `parts` are merged and written."""
        job_id = job_id or uuid.uuid4().hex
        task = f"eyerender-merge-{frame}-{job_id}"
        return self.client.submit(tasks.merge_and_write, job, frame, parts, exact, job_id, task, key=task,
                                  priority=priority)

    def submit_frame(self, job, frame, split=1, exact=True, job_id=None, priority=0):
        """A future of the statistics of `frame` (None: the stage's earliest time), rendered and written: one
        task, or `split` sample-range tasks and a merge task."""
        job_id = job_id or uuid.uuid4().hex
        if split > 1 and job.time_limit:
            raise EyeRenderError("a time limit cannot be combined with a split: the ranges would not add up")
        if split <= 1 or job.spp < 2:
            task = f"eyerender-frame-{frame}-{job_id}"
            return self.client.submit(tasks.render_frame, job, frame, job_id, task, key=task,
                                      priority=priority)
        parts = [self.submit_samples(job, frame, first, count, job_id, priority)
                 for first, count in split_samples(0, job.spp, split)]
        return self.submit_merge(job, frame, parts, exact, job_id, priority)

    def auto_split(self, job, frames):
        """Sample ranges per frame so that every task slot has work: 1 once frames alone fill the slots."""
        if job.time_limit or not frames:
            return 1
        return max(1, min(job.spp, math.ceil(self.worker_threads() / len(frames))))

    # -- a whole job ------------------------------------------------------------------------------------------------

    def render(self, job, frames=(None,), split=None, overwrite=False, exact=True,
               progress: Optional[Callable[[Progress], None]] = None, on_frame=None):
        """Renders `frames` (None: the single unanimated render) of `job`, skipping frames whose outputs all exist
        unless `overwrite`; split: sample ranges per frame (None: auto_split). progress(Progress) is called as
        samples arrive (from a Dask thread) and on_frame(frame, stats or None, error or None) as frames finish.
        Returns a FarmReport; a failing frame does not stop the others."""
        frames = list(frames)
        skipped = [] if overwrite else [f for f in frames if all(os.path.exists(p) for p in job.output_paths(f))]
        todo = [f for f in frames if f not in skipped]
        start = clock.perf_counter()
        workers = len(self.check_workers(job))
        split = self.auto_split(job, todo) if split is None else max(1, int(split))
        report = FarmReport(frames, {}, {}, skipped, 0.0, workers, split)
        if not todo:
            return report
        tracker = _ProgressTracker(len(todo), job.spp, start, progress)
        job_id = uuid.uuid4().hex
        topic_handler = tracker.event_handler(job_id)
        self.client.subscribe_topic(tasks.PROGRESS_TOPIC, topic_handler)
        try:
            from distributed import as_completed

            futures = {self.submit_frame(job, f, split, exact, job_id, priority=-n): f for n, f in enumerate(todo)}
            for future in as_completed(futures, loop=self.client.loop):
                frame = futures[future]
                try:
                    report.stats[frame] = future.result()
                except Exception as e:  # noqa: BLE001  (any task error fails its frame alone, reported)
                    report.errors[frame] = _one_line(e)
                future.release()  # drop the result (and a split frame's ranges) from the cluster's memory
                tracker.frame_done(frame)
                if on_frame:
                    on_frame(frame, report.stats.get(frame), report.errors.get(frame))
        finally:
            self.client.unsubscribe_topic(tasks.PROGRESS_TOPIC)
        report.seconds = clock.perf_counter() - start
        return report


class _ProgressTracker:
    """Turns worker progress events and finished frames into Progress calls; events may arrive on Dask's thread."""

    def __init__(self, frames, spp, start, callback):
        self.frames, self.spp, self.start, self.callback = frames, spp, start, callback
        self.lock = threading.Lock()
        self.task_samples = {}  # task -> samples done (a rerun after a lost worker starts again from 0)
        self.frame_of_task = {}
        self.done = set()

    def event_handler(self, job_id):
        def handle(event):
            message = event[1] if isinstance(event, tuple) else event
            if not isinstance(message, dict) or message.get("job") != job_id:
                return
            with self.lock:
                if message["frame"] in self.done:
                    return
                self.task_samples[message["task"]] = message["samples"]
                self.frame_of_task[message["task"]] = message["frame"]
            self._report()
        return handle

    def frame_done(self, frame):
        with self.lock:
            self.done.add(frame)
        self._report()

    def _report(self):
        if not self.callback:
            return
        with self.lock:
            running = sum(n for t, n in self.task_samples.items() if self.frame_of_task[t] not in self.done)
            state = Progress(len(self.done), self.frames, len(self.done) * self.spp + running,
                             self.frames * self.spp, clock.perf_counter() - self.start)
        self.callback(state)


__all__ = ["Farm", "FarmReport", "Progress", "RenderJob", "split_samples"]
