"""pytest setup for the Python tests: make the codeless eye schema plugin (schemas/) visible to usd-core.

USD builds its schema registry once, on first use, from the plugins it knows then; so the schemas folder is added
to PXR_PLUGINPATH_NAME here, at conftest import time, before any test module imports pxr. This makes the tests
work from a clean checkout with nothing installed but usd-core and pytest.
"""
import os
import pathlib
import sys

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
SCHEMAS_DIR = REPO_ROOT / "schemas"

_existing = [p for p in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep) if p]
if str(SCHEMAS_DIR) not in _existing:
    os.environ["PXR_PLUGINPATH_NAME"] = os.pathsep.join([str(SCHEMAS_DIR)] + _existing)

if "pxr.Usd" in sys.modules:
    # Something imported USD before us: register at run time. This only helps if the schema registry has not
    # been built yet (it is built on first stage/schema use, not on import).
    from pxr import Plug

    Plug.Registry().RegisterPlugins(str(SCHEMAS_DIR))


@pytest.fixture(scope="session")
def schemas_dir():
    """The repository's schemas/ folder (schema.usda, generatedSchema.usda, plugInfo.json)."""
    return SCHEMAS_DIR
