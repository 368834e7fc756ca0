"""The AOVs the renderer writes: one registry, AOV name -> EXR channel names (the component count is their number).

color's RGB are plain R, G, B so that any viewer shows the beauty. The data AOVs (albedo, normal, depth, primId) come
from each pixel's first sample. irisMnee is the light MNEE brought to irises. The eye AOVs split color by where its
light came from and sum to it (RGB): nonEye (met before any eye, or with none), glint (reflected off the cornea at
entry), iris (refracted into the cornea: the caustic, the chamber's light), sclera, and limbalArc (everything after a
sclera walk that crossed the teleportation cylinder). The cryptomatte layers hold ranked ids and coverage
(cryptomatte.py).
"""
from .cryptomatte import TYPES as CRYPTO_TYPES
from .cryptomatte import layer_channels

AOV_CHANNELS = {
    "color": ("R", "G", "B", "A"),
    "albedo": ("albedo.R", "albedo.G", "albedo.B"),
    "normal": ("N.X", "N.Y", "N.Z"),
    "depth": ("depth.Z",),
    "primId": ("primId",),
    "irisMnee": ("irisMnee.R", "irisMnee.G", "irisMnee.B"),
    "nonEye": ("nonEye.R", "nonEye.G", "nonEye.B"),
    "glint": ("glint.R", "glint.G", "glint.B"),
    "iris": ("iris.R", "iris.G", "iris.B"),
    "sclera": ("sclera.R", "sclera.G", "sclera.B"),
    "limbalArc": ("limbalArc.R", "limbalArc.G", "limbalArc.B"),
    **{layer: layer_channels(layer) for layer in CRYPTO_TYPES},
}
AOV_NAMES = tuple(AOV_CHANNELS)
# The eye AOVs, whose sum is color's RGB.
EYE_PART_AOVS = ("nonEye", "glint", "iris", "sclera", "limbalArc")

__all__ = ["AOV_CHANNELS", "AOV_NAMES", "EYE_PART_AOVS"]
