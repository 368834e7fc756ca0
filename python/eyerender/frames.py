"""usdrecord's frame syntax and output-name placeholders (UsdAppUtils.framesArgs is their specification).

A frame spec is a comma-separated list of FrameSpecs, each read as UsdUtils.TimeCodeRange reads it: a single frame
("12", "1.5") or a range "start:end" with an optional stride "start:endxstride" (end inclusive; "5:1" counts
down), e.g. "1:24", "1:24x2", "1,5,10:12".
An output name holds exactly one placeholder: a run of '#' ("###": the frame zero-padded to 3 characters) with an
optional second run after a dot ("###.##": 2 decimals, padded to 6 characters). A stride with decimals needs as
many decimals in the placeholder, so that no two frames write the same file.
"""
import math
import re

from .errors import EyeRenderError

_PLACEHOLDER = re.compile(r"^[^#]*(#+(\.#+)?)[^#]*$")  # exactly one placeholder
MAX_FRAMES = 1_000_000


def _decimals(text):
    parts = text.split(".")
    return len(parts[1]) if len(parts) > 1 else 0


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_FRAME_SPEC = re.compile(rf"^\s*({_NUMBER})(?:\s*:\s*({_NUMBER})(?:\s*x\s*({_NUMBER}))?)?\s*$")


def parse_frame_spec(part):
    """The frames of one FrameSpec, as UsdUtils.TimeCodeRange.CreateFromFrameSpec reads it (a range without a
    stride counts by 1 towards its end, down too; a stride must point from start to end). Parsed here, not by
    UsdUtils: its parser crashes the process on some malformed specs (e.g. a zero stride)."""
    match = _FRAME_SPEC.match(part)
    bad = EyeRenderError(f"--frames: '{part.strip()}' is not a frame or a range start:end[xstride]")
    if not match:
        raise bad
    start = float(match.group(1))
    if match.group(2) is None:
        return [start]
    end = float(match.group(2))
    stride = float(match.group(3)) if match.group(3) else (1.0 if end >= start else -1.0)
    if not all(map(math.isfinite, (start, end, stride))) or stride == 0 or (end - start) * stride < 0:
        raise bad
    count = int(math.floor((end - start) / stride + 1e-9)) + 1
    if count > MAX_FRAMES:
        raise EyeRenderError(f"--frames: '{part.strip()}' has more than {MAX_FRAMES} frames")
    return [start + i * stride for i in range(count)]


def parse_frames(spec):
    """The frames of a comma-separated list of FrameSpecs, in order, as floats; raises EyeRenderError for a
    malformed spec."""
    return [frame for part in spec.split(",") for frame in parse_frame_spec(part)]


def stride_decimals(spec):
    """The decimals a spec's strides need (usdrecord's minimum placeholder precision)."""
    return max((_decimals(part.split("x", 1)[1].strip()) for part in spec.split(",") if "x" in part), default=0)


def placeholder(path):
    """The output name's frame placeholder ("###" or "###.##"), or None unless it has exactly one."""
    match = _PLACEHOLDER.match(path)
    return match.group(1) if match else None


def has_placeholder(path):
    return "#" in path


def check_placeholder_precision(path, spec):
    """Raises EyeRenderError unless `path` has exactly one placeholder with the decimals `spec` needs."""
    found = placeholder(path)
    if found is None:
        raise EyeRenderError(f"output {path}: needs exactly one frame placeholder ('###' or '###.###')")
    needed = stride_decimals(spec)
    if _decimals(found) < needed:
        raise EyeRenderError(f"output {path}: --frames {spec} needs {needed} decimal(s) in the placeholder "
                             f"('{found}' has {_decimals(found)}), or frames would overwrite each other")


def output_path(pattern, frame):
    """pattern with its placeholder replaced by `frame` as usdrecord formats it (zero-padded to the placeholder's
    width, with its decimals); a pattern without one is returned as is."""
    found = placeholder(pattern)
    if found is None:
        return pattern
    text = f"{frame:0{len(found)}.{_decimals(found)}f}"
    return pattern.replace(found, text, 1)
