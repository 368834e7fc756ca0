"""What a farm render is, as plain data a Dask worker can unpickle: the stage, the session options, the outputs, and
how a frame's sample range splits into tasks. No Dask and no pxr here, so the client can build jobs cheaply."""
import dataclasses
import os
from typing import Optional, Tuple

from .errors import EyeRenderError
from .frames import output_path


@dataclasses.dataclass(frozen=True)
class RenderJob:
    """One render of one stage: every frame of it uses these options.

    stage_path and outputs are absolute paths that every worker must reach (a shared file system). width None means
    the render settings prim's, else 960 (eyerecord's default); outputs are '#'-placeholder patterns (.exr/.png)
    written atomically by the worker that finishes the frame. settings are RenderSettings overrides as (name, value)
    pairs (seed, threads, max_depth, mnee, mnee_all_solutions); time_limit (seconds, 0: none) only for unsplit frames;
    plan: the render plan's fixed options (eyerecord.plan_options), so workers plan frames as a local render does.
    """
    stage_path: str
    outputs: Tuple[str, ...]
    spp: int = 32
    width: Optional[int] = None
    height: Optional[int] = None
    camera: Optional[str] = None
    aovs: Tuple[str, ...] = ()
    render_settings_prim: Optional[str] = None
    purposes: Tuple[str, ...] = ("default", "proxy")
    refine_level: int = 2
    cornea_model: Optional[str] = None
    settings: Tuple[Tuple[str, object], ...] = ()
    exposure: float = 0.0
    time_limit: float = 0.0
    # What the render plan may not decide (eyerecord.plan_options: e.g. (("mnee", False),)); () plans everything, as
    # eyerecord does by default; None renders with no plan (the settings as given).
    plan: Optional[Tuple[Tuple[str, object], ...]] = ()

    def __post_init__(self):
        # Workers run in other directories: relative paths would name other files there.
        object.__setattr__(self, "stage_path", os.path.abspath(self.stage_path))
        object.__setattr__(self, "outputs", tuple(os.path.abspath(o) for o in self.outputs))
        object.__setattr__(self, "aovs", tuple(self.aovs))
        object.__setattr__(self, "purposes", tuple(self.purposes))
        object.__setattr__(self, "settings", tuple(sorted(dict(self.settings).items())))
        if self.spp < 1:
            raise EyeRenderError("spp must be at least 1")
        if not self.outputs:
            raise EyeRenderError("a render job needs at least one output")
        for out in self.outputs:
            if os.path.splitext(out)[1].lower() not in (".exr", ".png"):
                raise EyeRenderError(f"output {out}: extension must be .exr or .png")

    def output_paths(self, frame):
        """The files frame `frame` (None: the single unanimated render) writes."""
        return [out if frame is None else output_path(out, frame) for out in self.outputs]

    def session_key(self):
        """What a cached RenderSession must match to be reused for another frame (everything but the time)."""
        return (self.width, self.height, self.camera, self.aovs, self.render_settings_prim, self.purposes,
                self.refine_level, self.cornea_model, self.settings, self.plan)


def split_samples(first_sample, spp, parts):
    """[first_sample, first_sample + spp) as `parts` contiguous (first, count) ranges in sample order, the first
    ones one sample longer when spp does not divide; never an empty range."""
    parts = max(1, min(int(parts), spp))
    base, extra = divmod(spp, parts)
    ranges, first = [], first_sample
    for i in range(parts):
        count = base + (1 if i < extra else 0)
        ranges.append((first, count))
        first += count
    return ranges


__all__ = ["RenderJob", "split_samples"]
