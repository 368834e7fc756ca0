"""The one error type the front end raises for bad input: its message is a single line meant for users."""


class EyeRenderError(Exception):
    """Bad input (stage, prim, attribute, option or output path), described in one line."""
