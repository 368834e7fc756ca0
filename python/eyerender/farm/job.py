"""What a farm render is, as plain data a Dask worker can unpickle: the stage, the session options, the outputs, and
how a frame's sample range splits into tasks. No Dask and no pxr here, so the client can build jobs cheaply."""
import dataclasses
import os

from ..errors import EyeRenderError
from ..job import SessionOptions, check_output_extension, frame_outputs
from ..product_output import product_outputs


@dataclasses.dataclass(frozen=True)
class _JobTarget:
    """What a job renders and how much; a base of RenderJob so that these three lead its constructor."""
    stage_path: str
    outputs: tuple[str, ...]
    spp: int = 32


@dataclasses.dataclass(frozen=True)
class RenderJob(SessionOptions, _JobTarget):
    """One render of one stage: every frame of it uses these options.

    stage_path and outputs are absolute paths that every worker must reach (a shared file system); outputs are
    '#'-placeholder patterns (.exr/.png) written atomically by the worker that finishes the frame; spp: samples per
    pixel; exposure: the PNG's, in stops; time_limit (seconds, 0: none) only for unsplit frames. The fields from
    width to plan are the session's, as SessionOptions documents them (width None: the render settings prim's, else
    960; plan: job.plan_options, so workers plan frames as a local render does); they follow spp because dataclass
    fields come base by base, the last base first. products: render_products.RenderProductSpecs written instead of
    plain outputs (their names and .png previews are then `outputs`; one session renders them all, so they share
    its camera and size); png: a .png preview beside each .exr product.
    """
    exposure: float = 0.0
    time_limit: float = 0.0
    products: tuple = ()
    png: bool = False

    def __post_init__(self):
        super().__post_init__()
        # Workers run in other directories: relative paths would name other files there.
        object.__setattr__(self, "stage_path", os.path.abspath(self.stage_path))
        object.__setattr__(self, "outputs", tuple(os.path.abspath(o) for o in self.outputs))
        object.__setattr__(self, "products", tuple(
            dataclasses.replace(p, name=os.path.abspath(p.name)) for p in self.products))
        if self.products:
            object.__setattr__(self, "outputs", tuple(o for p in self.products for o in product_outputs(p, self.png)))
        if self.spp < 1:
            raise EyeRenderError("spp must be at least 1")
        if not self.outputs:
            raise EyeRenderError("a render job needs at least one output")
        for out in self.outputs:
            check_output_extension(out)

    @classmethod
    def from_options(cls, stage_path, outputs, options, **job):
        """A job of `stage_path` writing `outputs` with the session of SessionOptions `options`; job: the other
        fields (spp, exposure, time_limit)."""
        return cls(stage_path, tuple(outputs), **options.as_dict(), **job)

    def session_options(self):
        """The SessionOptions every frame's session is made from."""
        return SessionOptions(**self.as_dict())

    def output_paths(self, frame):
        """The files frame `frame` (None: the single unanimated render) writes."""
        return frame_outputs(self.outputs, frame)

    def frame_writes(self, frame):
        """[(path, product or None)]: what frame `frame` writes, each product's files with it (None: a plain
        output of every AOV)."""
        if not self.products:
            return [(path, None) for path in self.output_paths(frame)]
        return [(path, p) for p in self.products for path in frame_outputs(product_outputs(p, self.png), frame)]

    def session_key(self):
        """What a cached RenderSession must match to be reused for another frame (everything but the time)."""
        return self.session_options()


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
