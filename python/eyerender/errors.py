"""The one error type the front end raises for bad input: its message is a single line meant for users; and how a
command-line tool reports it."""
import sys


class EyeRenderError(Exception):
    """Bad input (stage, prim, attribute, option or output path), described in one line."""


def run_command(name, run, argv, interrupted="interrupted"):
    """Runs a command-line tool's `run(argv)` and returns its exit status: run's own, 1 after an EyeRenderError
    (printed as "NAME: error: ..." on stderr), 130 after Ctrl-C (printed as "NAME: INTERRUPTED")."""
    try:
        return run(argv)
    except EyeRenderError as e:
        print(f"{name}: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"\n{name}: {interrupted}", file=sys.stderr)
        return 130
