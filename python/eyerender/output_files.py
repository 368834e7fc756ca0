"""Housekeeping of a render's output files: the temporary files an interrupted atomic write leaves, and how a
render that fails part-way says what it wrote.

Outputs are written atomically (delegate/hdeye/imageWriter.cpp): a hidden `.NAME.tmp.PID.N` beside NAME is written,
fsync'ed and renamed over NAME. A process killed during the write (SIGKILL, power loss) leaves that temporary file;
the next write of NAME removes the ones whose process is gone. A failed render keeps the files it completed (each
is whole: nothing is rolled back) and its error line says which they are.
"""
import os
import re

from .console import describe_written

OUTPUT_EXTENSIONS = (".exr", ".png")  # what an output path may end in (case aside)

# usdrecord's --colorCorrectionMode values, for PNG outputs (EXRs always hold linear values): sRGB encodes the
# colour with the sRGB transfer curve; disabled writes the linear values as they are (clamped to [0, 1]);
# openColorIO has no OCIO configuration to read here and encodes sRGB, like OCIO's default sRGB display.
COLOR_CORRECTION_MODES = ("disabled", "sRGB", "openColorIO")


def _process_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: alive
        return True
    return True


def stale_temp_files(path):
    """The temporary files of output `path` left by writers that are no longer running (never a live writer's)."""
    directory, name = os.path.split(os.path.abspath(path))
    pattern = re.compile(r"\." + re.escape(name) + r"\.tmp\.(\d+)\.\d+$")
    try:
        entries = os.listdir(directory)
    except OSError:
        return []
    stale = []
    for entry in entries:
        match = pattern.match(entry)
        if match and int(match.group(1)) != os.getpid() and not _process_alive(int(match.group(1))):
            stale.append(os.path.join(directory, entry))
    return sorted(stale)


def remove_stale_temp_files(path):
    """Removes stale_temp_files(path); returns the paths removed (a file that vanished meanwhile is not listed)."""
    removed = []
    for tmp in stale_temp_files(path):
        try:
            os.remove(tmp)
            removed.append(tmp)
        except OSError:
            pass
    return removed


def partial_failure(message, written):
    """An error message for a render that failed after writing `written` (paths, in order): which files were
    written first (the line may be cut at its end, never there), then the message."""
    return f"wrote {describe_written(written)}, then: {message}" if written else message


__all__ = ["COLOR_CORRECTION_MODES", "OUTPUT_EXTENSIONS", "stale_temp_files", "remove_stale_temp_files",
           "partial_failure"]
