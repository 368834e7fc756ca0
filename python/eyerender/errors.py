"""The one error type the front end raises for bad input: its message is a single line meant for users; and how a
command-line tool reports it."""
import os
import sys

MAX_MESSAGE = 199  # characters of a printed error line, the tool's name included


class EyeRenderError(Exception):
    """Bad input (stage, prim, attribute, option or output path), described in one line."""


def print_error(name, message):
    """Prints "NAME: error: message" on stderr as one line of at most MAX_MESSAGE characters."""
    from .usd_diagnostics import one_line

    prefix = f"{name}: error: "
    print(prefix + one_line(message, MAX_MESSAGE - len(prefix)), file=sys.stderr)


def run_command(name, run, argv, interrupted="interrupted"):
    """Runs a command-line tool's `run(argv)` and returns its exit status: run's own, 1 after an EyeRenderError
    (printed as "NAME: error: ..." on stderr), 1 after any other exception (USD's own errors summarised to their
    first line; set EYERENDER_TRACEBACK=1 to see a traceback instead), 130 after Ctrl-C."""
    try:
        return run(argv)
    except EyeRenderError as e:
        print_error(name, str(e))
        return 1
    except KeyboardInterrupt:
        print(f"\n{name}: {interrupted}", file=sys.stderr)
        return 130
    except Exception as e:  # the last net: a user never sees a traceback
        if os.environ.get("EYERENDER_TRACEBACK"):
            raise
        from .usd_diagnostics import summarise_tf_error

        kind = "USD error" if type(e).__name__ == "ErrorException" else f"internal error ({type(e).__name__})"
        print_error(name, f"{kind}: {summarise_tf_error(e)}")
        return 1
