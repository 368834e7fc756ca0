"""eyerender: a renderer for human eyes (iris caustics, limbal arcs) from USD.

The package registers its codeless EyeAPI schema plugin with USD on import. USD reads plugin paths once, when
pxr first loads, so ``PXR_PLUGINPATH_NAME`` is extended here when pxr has not been imported yet, and the plugin
is registered at run time otherwise (which still works as long as no stage has built the schema registry).
"""
import os
import pathlib
import sys

SCHEMAS_DIR = pathlib.Path(__file__).resolve().parent / "schemas"


def _declares_eye_schema(directory):
    info = pathlib.Path(directory) / "plugInfo.json"
    return info.is_file() and "EyeRenderEyeAPI" in info.read_text(errors="replace")


def _register_schema_plugin():
    if not SCHEMAS_DIR.is_dir():  # running from a source tree without the installed plugin copy
        return
    if "pxr" not in sys.modules:
        paths = [p for p in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep) if p]
        # Another copy of the plugin already on the path (a source checkout's schemas/) wins: registering the
        # same plugin twice makes USD complain.
        if not any(_declares_eye_schema(p) for p in paths):
            os.environ["PXR_PLUGINPATH_NAME"] = os.pathsep.join([str(SCHEMAS_DIR)] + paths)
    else:
        from pxr import Plug

        Plug.Registry().RegisterPlugins(str(SCHEMAS_DIR))


_register_schema_plugin()

from ._hdeye import (  # noqa: E402  (the plugin path must be set before pxr loads)
    CameraParams,
    CorneaModel,
    EyeParams,
    LightParams,
    MaterialParams,
    RenderDelegate,
    RenderIndex,
    RenderPass,
    RenderSettings,
    RenderStats,
    SceneStore,
    read_exr,
    write_exr,
    write_png_preview,
)
from .errors import EyeRenderError  # noqa: E402
from .render_session import RenderSession  # noqa: E402
from .usd_scene_delegate import UsdSceneDelegate  # noqa: E402

__all__ = [
    "CameraParams", "CorneaModel", "EyeParams", "LightParams", "MaterialParams", "RenderDelegate", "RenderIndex",
    "RenderPass", "RenderSettings", "RenderStats", "SceneStore", "read_exr", "write_exr", "write_png_preview",
    "EyeRenderError", "UsdSceneDelegate", "RenderSession",
]
