"""usdrecord's frame syntax and output-name placeholders.

A frame spec is a comma-separated list of single frames ("12", "1.5") and ranges "start:end" or
"start:end xstride" written "start:endxstride" (end inclusive), e.g. "1:24", "1:24x2", "1,5,10:12".
An output name holds one run of '#' for the frame number: "###" pads the integer frame to 3 digits, "###.##"
also writes 2 decimals (usdrecord's convention); rendering several frames needs a placeholder.
"""
import re

from .errors import EyeRenderError

_PLACEHOLDER = re.compile(r"#+(\.#+)?")


def parse_frames(spec):
    """The frames of a spec, in order, as floats; raises EyeRenderError for a malformed spec."""
    frames = []
    for part in spec.split(","):
        part = part.strip()
        try:
            if ":" in part:
                start, rest = part.split(":", 1)
                end, _, stride = rest.partition("x")
                start, end, stride = float(start), float(end), float(stride) if stride else 1.0
                if stride <= 0:
                    raise ValueError
                count = int((end - start) / stride + 1e-9) + 1
                if end < start or count > 1_000_000:
                    raise ValueError
                frames += [start + i * stride for i in range(count)]
            else:
                frames.append(float(part))
        except ValueError:
            raise EyeRenderError(f"--frames: '{part}' is not a frame or a range start:end[xstride]") from None
    return frames


def has_placeholder(path):
    return bool(_PLACEHOLDER.search(path))


def output_path(pattern, frame):
    """pattern with its '#' run replaced by `frame`; a pattern without one is returned as is."""
    match = _PLACEHOLDER.search(pattern)
    if not match:
        return pattern
    integer_digits = len(match.group(0).split(".")[0])
    decimals = len(match.group(1)) - 1 if match.group(1) else 0
    width = integer_digits + (decimals + 1 if decimals else 0)
    text = f"{frame:0{width}.{decimals}f}" if decimals else f"{int(round(frame)):0{integer_digits}d}"
    return pattern[:match.start()] + text + pattern[match.end():]
