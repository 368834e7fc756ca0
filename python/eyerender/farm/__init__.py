"""Rendering on a Dask cluster (docs/farm.md): `Farm` runs a `RenderJob`'s frames as tasks on workers.

cluster.py is the client side (Farm, its report and progress), tasks.py what runs on a worker, job.py the job a
task carries, merge.py the exact merge of a frame split into sample ranges. The command line's farm path is
eyerender.cli.farm.
"""
from .cluster import Farm, FarmReport, Progress
from .job import RenderJob, split_samples

__all__ = ["Farm", "FarmReport", "Progress", "RenderJob", "split_samples"]
