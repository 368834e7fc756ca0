"""Materials the Python tests author (importable from tests/python, which pytest puts on sys.path)."""
from pxr import Gf, Sdf, UsdShade


def preview_material(stage, path, color):
    """A UsdPreviewSurface material at `path` with diffuseColor `color` (linear RGB)."""
    mat = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, path + "/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*color))
    mat.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return mat
