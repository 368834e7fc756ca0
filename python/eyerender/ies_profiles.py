"""IES light profiles (UsdLuxShapingAPI's inputs:shaping:ies:file) read through Ar for the delegate.

The asset path resolves like any other (relative to the layer that authors it, inside a .usdz package too); its
bytes are read through Ar (`ArResolver.OpenAsset`, so packaged files and custom resolvers need no extraction) and
parsed by the delegate's LM-63 parser (`parse_ies`). A file that cannot be resolved, read or parsed is a
ProfileWarning: the light renders without its profile, and `eyerecord --strict` makes it an error.
"""
from pxr import Ar, Sdf

from ._hdeye import parse_ies
from .textures import TextureWarning


class ProfileWarning(TextureWarning):
    """An IES profile that cannot be read (the light renders unshaped by it). A TextureWarning, so `--strict`
    fails on it as on an unreadable texture."""


def _read_bytes(resolved):
    asset = Ar.GetResolver().OpenAsset(Ar.ResolvedPath(resolved))
    if asset is None:
        raise ValueError("cannot be opened through Ar")
    return bytes(asset.GetBuffer())


def read_ies_profile(attr, time, what):
    """(IesProfile or None, ProfileWarning or None) for an asset-valued attribute; (None, None) when it holds no
    path. `what` names the prim and attribute in the warning."""
    asset = attr.Get(time) if attr else None
    if not isinstance(asset, Sdf.AssetPath) or not asset.path:
        return None, None
    resolved = asset.resolvedPath
    try:
        if not resolved:
            raise ValueError("file not found")
        # LM-63 files are ASCII; latin-1 maps any stray byte to one character instead of failing the decode.
        return parse_ies(_read_bytes(resolved).decode("latin-1")), None
    except (OSError, ValueError) as e:
        return None, ProfileWarning(f"{what} '{asset.path}': {e}; the light renders without its profile")
