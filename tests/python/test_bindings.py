"""The nanobind module as Python sees it: the generated type stubs cover it, and the plan reaches Python as structs."""
import ast
import pathlib

import pytest

hdeye = pytest.importorskip("eyerender._hdeye")


def test_the_installed_type_stub_declares_every_public_name_of_the_module():
    stub = pathlib.Path(hdeye.__file__).with_name("_hdeye.pyi")
    assert stub.is_file(), f"no generated stub at {stub}"
    assert stub.with_name("py.typed").is_file(), "no PEP 561 marker beside the stub"
    tree = ast.parse(stub.read_text())
    declared = {node.name for node in tree.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))}
    assigned = (t for node in tree.body if isinstance(node, ast.Assign) for t in node.targets)
    declared |= {t.id for t in assigned if isinstance(t, ast.Name)}
    public = {name for name in dir(hdeye) if not name.startswith("_")}
    assert public - declared == set(), f"bound but missing from {stub.name}: {sorted(public - declared)}"


def test_plan_names_are_made_from_the_enums_at_the_edge():
    assert hdeye.to_string(hdeye.LightStrategy.MNEE) == "mnee"
    assert hdeye.to_string(hdeye.LightStrategy.BSDF) == "bsdf"
    assert hdeye.to_string(hdeye.LightStrategy.NONE) == "none"
    assert hdeye.to_string(hdeye.ScleraModel.RANDOM_WALK) == "randomWalk"
    assert hdeye.to_string(hdeye.ScleraModel.DIFFUSE) == "diffuse"
    assert hdeye.to_string(hdeye.LightType.DOME) == "dome"
