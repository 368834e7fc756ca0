"""USD's own diagnostics as short lines: a Tf error raised into Python summarised to its first meaningful line,
and the warnings USD would print (missing references, bad xform ops...) captured and repeated as one-line warnings.

USD's messages carry C++ namespaces, source files and line numbers; a user needs the sentence inside them. Text is
decoded with errors='replace': a .usda holding a non-UTF-8 byte makes str() of its parse error raise otherwise.
"""
import re

MAX_LINE = 150  # characters of USD text kept in one line (the tool name and context fit in the 200 around it)

_TF_MESSAGE = re.compile(r"Error in '[^']*' at line \d+ in file \S+ : '(.*)'\s*$", re.S)
_NAMESPACE = re.compile(r"pxrInternal_v\w+?__pxrReserved__::")
_IN_PRIM = re.compile(r"In <([^>]*)>: (.*)$")  # USD's prefix naming the prim a composition error was met in
_PRIM_PATH = re.compile(r"<[^>]*>")


def _text(obj):
    """str(obj), with undecodable bytes replaced instead of raising."""
    try:
        return str(obj)
    except UnicodeDecodeError as e:
        raw = e.object if isinstance(e.object, bytes) else b""
        return raw.decode("utf-8", errors="replace")


def one_line(text, limit=MAX_LINE):
    """text's first non-empty line, C++ namespaces removed, cut to `limit` characters (an ellipsis marks a cut)."""
    line = next((s.strip() for s in _NAMESPACE.sub("", text).splitlines() if s.strip()), "")
    # Parser errors go on to list grammar rules: the position and "parse error" are what a user can act on.
    line = line.split(" matching ", 1)[0] if "parse error matching" in line else line
    return line if len(line) <= limit else line[:limit - 3].rstrip() + "..."


def summarise_tf_error(error):
    """The first meaningful line of a Tf.ErrorException (or any exception): the commentary of its first Tf error,
    without the C++ function, file and line that wrap it."""
    for part in getattr(error, "args", ()) or (error,):
        text = _text(part)
        match = _TF_MESSAGE.search(text.strip())
        line = one_line(match.group(1) if match else text)
        if line:
            return line
    return one_line(_text(error)) or type(error).__name__


class UsdDiagnostics:
    """Captures the diagnostics USD would print on stderr while it lives (UsdUtils' coalescing delegate), so that
    they reach the user as one-line warnings instead of multi-line reports."""

    def __init__(self):
        from pxr import UsdUtils

        self._delegate = UsdUtils.CoalescingDiagnosticDelegate()

    def take_warnings(self):
        """The diagnostics captured since the last call, each as one line ("USD: ..."), duplicates dropped. The same
        problem met in many prims ("In </a>: Could not open asset @x@ ...", one per prim that references x) is one
        line naming the first prim and how many more."""
        groups = {}  # the message with its prim paths blanked -> [first prim, message, count]
        for diagnostic in self._delegate.TakeUncoalescedDiagnostics():
            line = one_line(_text(diagnostic.commentary), limit=10_000)
            if not line:
                continue
            match = _IN_PRIM.match(line)
            prim, message = match.groups() if match else ("", line)
            group = groups.setdefault(_PRIM_PATH.sub("<>", message), [prim, message, 0])
            group[2] += 1
        lines = []
        for prim, message, count in groups.values():
            where = "" if not prim else f"In <{prim}>: " if count == 1 else f"In <{prim}> and {count - 1} more prims: "
            lines.append(f"USD: {one_line(where + message)}")
        return list(dict.fromkeys(lines))


__all__ = ["MAX_LINE", "one_line", "summarise_tf_error", "UsdDiagnostics"]
