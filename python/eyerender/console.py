"""What eyerecord and eyestudy print on a terminal besides results: progress bars, warnings (each once), and the
summary line's list of written files. Bars draw only on a terminal's stderr, so logs and CI stay clean."""
import sys


class StatusLine:
    """One line redrawn in place on a terminal's stderr; nothing is written elsewhere (logs, CI)."""

    def __init__(self, enabled):
        self.enabled = enabled and sys.stderr.isatty()

    def draw(self, text):
        if self.enabled:
            sys.stderr.write(f"\r{text}")
            sys.stderr.flush()

    def finish(self):
        if self.enabled:
            sys.stderr.write("\n")


class ProgressBar(StatusLine):
    """One render's samples as a bar, with the time spent and the time left (by the samples left, or by the time
    limit when that comes first). Called between the render loop's passes."""

    def __init__(self, enabled, time_limit=0.0):
        super().__init__(enabled)
        self.label = ""
        self.time_limit = time_limit

    def __call__(self, done, total, seconds):
        if not self.enabled:
            return
        width = 30
        fraction = done / max(total, 1)
        eta = seconds / done * (total - done) if done else 0.0
        if self.time_limit:
            fraction, eta = max(fraction, min(1.0, seconds / self.time_limit)), min(eta, self.time_limit - seconds)
        filled = int(width * fraction)
        total_text = "" if self.time_limit else f"/{total}"  # under a limit the sample count is open
        self.draw(f"{self.label} [{'#' * filled}{'.' * (width - filled)}] {done}{total_text} spp "
                  f"{seconds:6.1f} s  eta {max(eta, 0.0):5.1f} s ")


class FarmProgressBar(StatusLine):
    """A farm job's progress (farm.Progress): frames, samples, time, time left."""

    def __call__(self, p):
        if self.enabled:
            eta = f"{p.eta:5.1f} s" if p.eta is not None else "  ?"
            self.draw(f"frames {p.frames_done}/{p.frames_total}  samples {p.samples_done}/{p.samples_total}  "
                      f"{p.seconds:6.1f} s  eta {eta} ")


def print_warnings(warnings, tool="eyerecord"):
    """Prints each distinct warning once, in order, on stderr, each one line of under 200 characters."""
    from .usd_diagnostics import one_line

    prefix = f"{tool}: warning: "
    for warning in dict.fromkeys(warnings):
        print(prefix + one_line(warning, 199 - len(prefix)), file=sys.stderr)


def warn_non_finite(count, tool="eyerecord"):
    """Says on stderr that `count` NaN/Inf samples were dropped (none leave a correct renderer)."""
    if count:
        print(f"{tool}: warning: {count} NaN/Inf samples were dropped (a renderer bug)", file=sys.stderr)


def describe_written(paths):
    """The files a render wrote, for its summary line."""
    if not paths:
        return "nothing written"
    return paths[0] if len(paths) == 1 else f"{paths[0]} .. {paths[-1]} ({len(paths)} files)"


__all__ = ["StatusLine", "ProgressBar", "FarmProgressBar", "print_warnings", "warn_non_finite", "describe_written"]
