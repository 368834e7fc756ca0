"""The defaults every entry point shares (eyerecord, RenderSession, the farm), in one table."""

DEFAULT_WIDTH = 960  # pixels, when neither the options nor a render settings prim give one
DEFAULT_SPP = 32  # samples per pixel, when neither --spp nor a time limit says

__all__ = ["DEFAULT_SPP", "DEFAULT_WIDTH"]
