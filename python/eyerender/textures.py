"""Texture files as USD names them, to paths OpenImageIO reads: one place for every texture the renderer uses
(UsdUVTexture files, eye:irisTexture, dome light textures).

- Plain paths resolve through Ar like any asset.
- UDIM sets (`<UDIM>` in the path) resolve through UsdShade.UdimUtils: the delegate gets the pattern, with
  `<UDIM>` kept, and OpenImageIO picks the tile per lookup.
- Files inside a .usdz package (Ar resolves them to `pkg.usdz[textures/a.png]`) are read through Ar
  (`ArResolver.OpenAsset`, so any resolver works) and written once into a per-user cache keyed by a hash of
  their bytes (`$EYERENDER_CACHE`, else `$XDG_CACHE_HOME/eyerender/textures`, else `~/.cache/...`), keeping their
  file names. Why a file and not an in-memory buffer: OpenImageIO 2.4's TextureSystem reads through file names
  (its IOProxy reaches ImageInput, not the texture cache), a cached file is MIP-mapped and tiled by OIIO like
  any other, survives across renders and farm tasks, and the content hash makes it immutable, so a stale entry
  cannot exist.

A file that cannot be resolved or read is a TextureWarning (one line naming the prim, the attribute and the
file); the delegate then uses the fallback. `eyerecord --strict` turns these warnings into errors.
"""
import hashlib
import os
import re
import tempfile

from pxr import Ar, Sdf, UsdShade

from ._hdeye import texture_problem

UDIM_TOKEN = "<UDIM>"


class TextureWarning(str):
    """A warning about a texture that cannot be read (its fallback is rendered). A str, so it sits in the scene
    delegate's warnings like any other; `--strict` finds these by type and fails."""


def cache_dir():
    """The per-user directory where textures extracted from packages are kept (created on demand)."""
    root = os.environ.get("EYERENDER_CACHE")
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(base, "eyerender", "textures")
    return root


def _authoring_layer(attr, time):
    """The layer whose opinion gives attr its value: asset paths are relative to it."""
    for spec in attr.GetPropertyStack(time):
        if spec.HasDefaultValue() or spec.layer.ListTimeSamplesForPath(spec.path):
            return spec.layer
    return attr.GetStage().GetRootLayer()


def _extract(resolved_paths):
    """Local copies of package-relative resolved paths [(path, tile or '')], in one cache directory named by the
    hash of every file's name and bytes. Returns {package path: local path}. Raises OSError / ValueError."""
    resolver = Ar.GetResolver()
    contents = []
    digest = hashlib.sha256()
    for path in resolved_paths:
        asset = resolver.OpenAsset(Ar.ResolvedPath(path))
        if asset is None:
            raise ValueError(f"{path} cannot be opened through Ar")
        data = asset.GetBuffer()
        name = os.path.basename(Ar.SplitPackageRelativePathInner(path)[1] or path)
        contents.append((path, name, data))
        digest.update(name.encode() + b"\0" + hashlib.sha256(data).digest())
    directory = os.path.join(cache_dir(), digest.hexdigest()[:32])
    os.makedirs(directory, exist_ok=True)
    local = {}
    for path, name, data in contents:
        target = os.path.join(directory, name)
        if not os.path.isfile(target) or os.path.getsize(target) != len(data):
            fd, tmp = tempfile.mkstemp(dir=directory, prefix=".tmp-", suffix=os.path.splitext(name)[1])
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, target)  # atomic: a concurrent render sees the whole file or none
        local[path] = target
    return local


def _local_path(attr, asset, time):
    """(path for the delegate, problem or None) of a non-empty Sdf.AssetPath value of attr."""
    authored = asset.path
    if UsdShade.UdimUtils.IsUdimIdentifier(authored):
        layer = _authoring_layer(attr, time)
        pattern = UsdShade.UdimUtils.ResolveUdimPath(authored, layer)
        tiles = UsdShade.UdimUtils.ResolveUdimTilePaths(pattern, layer) if pattern else []
        if not tiles:
            return Sdf.ComputeAssetPathRelativeToLayer(layer, authored), "no UDIM tile of the set is found"
        if Ar.IsPackageRelativePath(pattern):
            local = _extract([p for p, _ in tiles])
            first_path, first_tile = tiles[0]
            return re.sub(re.escape(first_tile) + r"(?=[^0-9]*$)", UDIM_TOKEN, local[first_path], count=1), None
        return pattern, None
    resolved = asset.resolvedPath
    if not resolved:
        return Sdf.ComputeAssetPathRelativeToLayer(_authoring_layer(attr, time), authored), "file not found"
    if Ar.IsPackageRelativePath(resolved):
        return _extract([resolved])[resolved], None
    return resolved, None


def resolve_texture(attr, time, what):
    """(file for the delegate, TextureWarning or None) for an asset-valued attribute, or ("", None) when it holds
    no path. `what` names it in the warning (e.g. "/World/Mat/Tex: inputs:file"). The file always comes back, even
    when it cannot be read: the delegate then renders the fallback."""
    asset = attr.Get(time) if attr else None
    if not isinstance(asset, Sdf.AssetPath) or not asset.path:
        return "", None
    try:
        path, problem = _local_path(attr, asset, time)
    except (OSError, ValueError) as e:
        return "", TextureWarning(f"{what} '{asset.path}': cannot be extracted from its package ({e})")
    if problem:
        return path, TextureWarning(f"{what} '{asset.path}': {problem} ({path})")
    problem = texture_problem(path)
    return path, TextureWarning(f"{what} '{asset.path}': {problem}") if problem else None
