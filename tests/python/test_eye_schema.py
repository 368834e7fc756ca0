"""The codeless EyeAPI schema (schemas/): registration, application, the attribute contract, persistence,
schema.usda / generatedSchema.usda consistency, and USD validation.

The attribute names, types and fallbacks below are a contract other tools (the scene delegate, eyerecord,
pipeline scripts) rely on; changing one here means changing it for them too.
"""
import json
import os
import subprocess
import sys

import pytest
from pxr import Gf, Sdf, Tf, Usd, UsdGeom

SCHEMA = "EyeAPI"
SCHEMA_TF_TYPE = "EyeRenderEyeAPI"
FLOAT_TOL = 1e-6  # fallbacks are float32; compare relative to that precision

# name -> (type name, fallback). None fallback = no fallback value (asset).
CONTRACT_ATTRIBUTES = {
    "eye:corneaModel": (Sdf.ValueTypeNames.Token, "ellipsoidCone"),
    "eye:corneaIor": (Sdf.ValueTypeNames.Float, 1.376),
    "eye:irisDepth": (Sdf.ValueTypeNames.Float, 3.735),
    "eye:limbusInnerRatio": (Sdf.ValueTypeNames.Float, 0.772),
    "eye:limbusOuterRatio": (Sdf.ValueTypeNames.Float, 0.855),
    "eye:pupilDiameter": (Sdf.ValueTypeNames.Float, 4.0),
    "eye:irisColor": (Sdf.ValueTypeNames.Color3f, (0.35, 0.2, 0.1)),
    "eye:scleraColor": (Sdf.ValueTypeNames.Color3f, (0.8, 0.78, 0.75)),
    "eye:irisTexture": (Sdf.ValueTypeNames.Asset, None),
    "eye:modelTransform": (Sdf.ValueTypeNames.Matrix4d, Gf.Matrix4d(1.0)),
    "eye:limbalArc": (Sdf.ValueTypeNames.Bool, True),
}
CONTRACT_RELATIONSHIPS = ["eye:irisProjection", "eye:corneaShell"]
CORNEA_MODELS = ["ellipsoidCone", "paraboloid"]

# Attributes with a physical dimension must say their unit in the doc the registry carries (userDocBrief).
UNIT_WORDS = {
    "eye:irisDepth": "millimetres",
    "eye:pupilDiameter": "millimetres",
    "eye:limbusInnerRatio": "15.08 mm",
    "eye:limbusOuterRatio": "15.08 mm",
    "eye:modelTransform": "millimetres",
    "eye:irisTexture": "mm",
    "eye:corneaIor": "dimensionless",
}


def _assert_value_equal(actual, expected, what):
    if isinstance(expected, float):
        assert actual == pytest.approx(expected, rel=FLOAT_TOL), what
    elif isinstance(expected, tuple):
        assert actual is not None, what
        assert tuple(actual) == pytest.approx(expected, rel=FLOAT_TOL), what
    else:
        assert actual == expected, what


def _new_stage():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    return stage


@pytest.fixture
def stage():
    return _new_stage()


@pytest.fixture(params=["Xform", "Mesh"])
def eye_prim(request, stage):
    """A prim of each supported kind with EyeAPI applied."""
    schema = {"Xform": UsdGeom.Xform, "Mesh": UsdGeom.Mesh}[request.param]
    prim = schema.Define(stage, "/World/eye").GetPrim()
    assert prim.ApplyAPI(SCHEMA)
    return prim


# --- registration --------------------------------------------------------------------------------------------

def test_schema_registers_with_the_plugin_from_schemas_folder():
    tf_type = Usd.SchemaRegistry.GetTypeFromSchemaTypeName(SCHEMA)
    assert tf_type != Tf.Type.Unknown, "EyeAPI not registered: is schemas/ on PXR_PLUGINPATH_NAME?"
    assert tf_type.typeName == SCHEMA_TF_TYPE
    assert Usd.SchemaRegistry().FindAppliedAPIPrimDefinition(SCHEMA) is not None


def test_schema_is_single_apply_api():
    assert Usd.SchemaRegistry.GetSchemaKind(SCHEMA) == Usd.SchemaKind.SingleApplyAPI
    assert Usd.SchemaRegistry.IsAppliedAPISchema(SCHEMA)
    assert not Usd.SchemaRegistry.IsMultipleApplyAPISchema(SCHEMA)
    assert not Usd.SchemaRegistry.IsConcrete(SCHEMA)


def test_schema_inherits_api_schema_base():
    tf_type = Usd.SchemaRegistry.GetTypeFromSchemaTypeName(SCHEMA)
    assert tf_type.IsA(Tf.Type.FindByName("UsdAPISchemaBase"))


# --- applying ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("prim_type", ["Xform", "Mesh"])
def test_apply_api_to_xform_and_mesh_sets_has_api(stage, prim_type):
    prim = stage.DefinePrim("/World/eye", prim_type)
    assert not prim.HasAPI(SCHEMA)
    assert prim.CanApplyAPI(SCHEMA)
    assert prim.ApplyAPI(SCHEMA)
    assert prim.HasAPI(SCHEMA)
    assert prim.HasAPI(Usd.SchemaRegistry.GetTypeFromSchemaTypeName(SCHEMA))
    assert SCHEMA in prim.GetAppliedSchemas()
    assert list(prim.GetMetadata("apiSchemas").GetAppliedItems()) == [SCHEMA]


def test_prim_without_eye_api_has_no_eye_properties(stage):
    prim = UsdGeom.Mesh.Define(stage, "/World/notAnEye").GetPrim()
    assert not prim.HasAPI(SCHEMA)
    for name in list(CONTRACT_ATTRIBUTES) + CONTRACT_RELATIONSHIPS:
        assert not prim.HasProperty(name), name


def test_remove_api_removes_schema_properties(stage):
    prim = UsdGeom.Xform.Define(stage, "/World/eye").GetPrim()
    prim.ApplyAPI(SCHEMA)
    assert prim.RemoveAPI(SCHEMA)
    assert not prim.HasAPI(SCHEMA)
    assert not prim.HasAttribute("eye:irisDepth")


# --- the attribute contract ----------------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(CONTRACT_ATTRIBUTES))
def test_contract_attribute_has_type_and_fallback(eye_prim, name):
    type_name, fallback = CONTRACT_ATTRIBUTES[name]
    attr = eye_prim.GetAttribute(name)
    assert attr.IsValid(), f"{name} missing"
    assert attr.GetTypeName() == type_name, f"{name}: {attr.GetTypeName()} != {type_name}"
    assert not attr.HasAuthoredValue(), f"{name} should come from the schema, not be authored by ApplyAPI"
    if fallback is None:
        assert attr.Get() is None, f"{name} should have no fallback"
    else:
        assert attr.HasFallbackValue(), f"{name} has no fallback"
        _assert_value_equal(attr.Get(), fallback, name)


def test_cornea_model_allowed_tokens_are_ellipsoid_cone_and_paraboloid(eye_prim):
    attr = eye_prim.GetAttribute("eye:corneaModel")
    assert list(attr.GetMetadata("allowedTokens")) == CORNEA_MODELS
    assert attr.Get() == "ellipsoidCone"
    assert attr.GetVariability() == Sdf.VariabilityUniform


def test_model_transform_fallback_is_identity(eye_prim):
    assert eye_prim.GetAttribute("eye:modelTransform").Get() == Gf.Matrix4d(1.0)


def test_limbal_arc_fallback_is_on(eye_prim):
    assert eye_prim.GetAttribute("eye:limbalArc").Get() is True


def test_limbus_fallbacks_match_the_paper_diameters_in_mm(eye_prim):
    iris_diameter_mm = 15.08
    inner = eye_prim.GetAttribute("eye:limbusInnerRatio").Get() * iris_diameter_mm
    outer = eye_prim.GetAttribute("eye:limbusOuterRatio").Get() * iris_diameter_mm
    assert inner == pytest.approx(11.64, abs=0.01)
    assert outer == pytest.approx(12.89, abs=0.01)


@pytest.mark.parametrize("name", CONTRACT_RELATIONSHIPS)
def test_relationship_has_no_default_targets(eye_prim, name):
    rel = eye_prim.GetRelationship(name)
    assert rel.IsValid(), f"{name} missing"
    assert not eye_prim.GetAttribute(name).IsValid()
    assert rel.GetTargets() == []


def test_schema_declares_every_contract_property():
    definition = Usd.SchemaRegistry().FindAppliedAPIPrimDefinition(SCHEMA)
    names = set(definition.GetPropertyNames())
    missing = (set(CONTRACT_ATTRIBUTES) | set(CONTRACT_RELATIONSHIPS)) - names
    assert not missing
    for name in CONTRACT_ATTRIBUTES:
        assert definition.GetAttributeDefinition(name), name
    for name in CONTRACT_RELATIONSHIPS:
        assert definition.GetRelationshipDefinition(name), name


@pytest.mark.parametrize("name", sorted(UNIT_WORDS))
def test_registered_doc_states_the_unit(name):
    definition = Usd.SchemaRegistry().FindAppliedAPIPrimDefinition(SCHEMA)
    spec = definition.GetSchemaAttributeSpec(name)
    brief = spec.customData.get("userDocBrief", "")
    assert UNIT_WORDS[name] in brief, f"{name} doc {brief!r} does not state its unit"


# --- persistence ---------------------------------------------------------------------------------------------

AUTHORED = {
    "eye:corneaModel": "paraboloid",
    "eye:corneaIor": 1.4,
    "eye:irisDepth": 3.1,
    "eye:limbusInnerRatio": 0.7,
    "eye:limbusOuterRatio": 0.9,
    "eye:pupilDiameter": 6.5,
    "eye:irisColor": (0.1, 0.3, 0.5),
    "eye:scleraColor": (0.9, 0.85, 0.8),
    "eye:irisTexture": Sdf.AssetPath("textures/iris.exr"),
    "eye:modelTransform": Gf.Matrix4d().SetScale(Gf.Vec3d(0.1, 0.1, 0.1)).SetTranslateOnly(Gf.Vec3d(1, 2, 3)),
    "eye:limbalArc": False,
}


def test_authored_values_round_trip_through_usda_file(tmp_path):
    stage = _new_stage()
    UsdGeom.Xform.Define(stage, "/World/projection")
    prim = UsdGeom.Mesh.Define(stage, "/World/eye").GetPrim()
    prim.ApplyAPI(SCHEMA)
    for name, value in AUTHORED.items():
        assert prim.GetAttribute(name).Set(value), name
    prim.GetRelationship("eye:irisProjection").SetTargets([Sdf.Path("/World/projection")])
    path = tmp_path / "eye.usda"
    assert stage.GetRootLayer().Export(str(path))
    text = path.read_text()
    assert 'prepend apiSchemas = ["EyeAPI"]' in text

    reopened = Usd.Stage.Open(str(path))
    assert reopened.GetRootLayer() is not stage.GetRootLayer()
    eye = reopened.GetPrimAtPath("/World/eye")
    assert eye.HasAPI(SCHEMA)
    for name, value in AUTHORED.items():
        attr = eye.GetAttribute(name)
        assert attr.HasAuthoredValue(), name
        got = attr.Get()
        if isinstance(value, Sdf.AssetPath):
            assert got.path == value.path, name
        else:
            _assert_value_equal(got, value, name)
    assert eye.GetRelationship("eye:irisProjection").GetTargets() == [Sdf.Path("/World/projection")]


def test_unauthored_attributes_are_not_written_to_the_file(tmp_path):
    stage = _new_stage()
    prim = UsdGeom.Xform.Define(stage, "/World/eye").GetPrim()
    prim.ApplyAPI(SCHEMA)
    path = tmp_path / "eye.usda"
    stage.GetRootLayer().Export(str(path))
    assert "eye:" not in path.read_text()
    reopened = Usd.Stage.Open(str(path))
    eye = reopened.GetPrimAtPath("/World/eye")
    assert eye.HasAPI(SCHEMA)
    _assert_value_equal(eye.GetAttribute("eye:irisDepth").Get(), 3.735, "eye:irisDepth")


# --- schema sources are consistent ---------------------------------------------------------------------------

def _without_comment_lines(text):
    return [line for line in text.splitlines() if not line.lstrip().startswith("#")]


def _plug_info_types(path):
    text = "".join(line for line in path.read_text().splitlines(True) if not line.lstrip().startswith("#"))
    return json.loads(text)["Plugins"][0]["Info"]["Types"]


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory, schemas_dir):
    """Run usdGenSchema on schemas/schema.usda into a temp dir (with a clean plugin path)."""
    out = tmp_path_factory.mktemp("regenerated")
    env = dict(os.environ)
    env.pop("PXR_PLUGINPATH_NAME", None)
    result = subprocess.run(
        [sys.executable, "-m", "pxr.Usd.usdGenSchema", str(schemas_dir / "schema.usda"), str(out)],
        env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    return out


def test_generated_schema_matches_regenerating_from_schema_usda(regenerated, schemas_dir):
    committed = _without_comment_lines((schemas_dir / "generatedSchema.usda").read_text())
    fresh = _without_comment_lines((regenerated / "generatedSchema.usda").read_text())
    assert committed == fresh, (
        "schemas/generatedSchema.usda is stale: run "
        "`python3 -m pxr.Usd.usdGenSchema schemas/schema.usda schemas/` and fix up plugInfo.json (schemas/README.md)")


def test_plug_info_types_match_regenerating_from_schema_usda(regenerated, schemas_dir):
    assert _plug_info_types(schemas_dir / "plugInfo.json") == _plug_info_types(regenerated / "plugInfo.json")


def test_plug_info_is_a_relocatable_resource_plugin_without_placeholders(schemas_dir):
    text = (schemas_dir / "plugInfo.json").read_text()
    assert "@PLUG_INFO" not in text
    assert not any(line.lstrip().startswith("#") for line in text.splitlines())
    plugin = json.loads(text)["Plugins"][0]
    assert plugin["Type"] == "resource"
    assert plugin["Root"] == "."
    assert plugin["ResourcePath"] == "."
    assert "LibraryPath" not in plugin


# --- validation ----------------------------------------------------------------------------------------------

def _validate(stage):
    UsdValidation = pytest.importorskip("pxr.UsdValidation")
    registry = UsdValidation.ValidationRegistry()
    validators = registry.GetOrLoadAllValidators()
    assert validators, "no validators loaded"
    return UsdValidation.ValidationContext(validators).Validate(stage)


def _describe(errors):
    return "\n".join(f"{e.GetValidator().GetMetadata().name}: {e.GetMessage()}" for e in errors)


def _schema_related(errors, eye_paths):
    """Errors from USD core validators (type mismatches, composition) or located on an eye prim."""
    related = []
    for e in errors:
        core = "UsdCoreValidators" in e.GetValidator().GetMetadata().GetKeywords()
        on_eye = False
        for site in e.GetSites():
            obj = site.GetPrim() if site.IsPrim() else site.GetProperty()
            if obj and any(obj.GetPath().HasPrefix(p) for p in eye_paths):
                on_eye = True
        if core or on_eye:
            related.append(e)
    return related


def test_validation_reports_no_schema_errors_for_applied_eye_api(tmp_path):
    stage = _new_stage()
    UsdGeom.Xform.Define(stage, "/World/projection")
    xform_eye = UsdGeom.Xform.Define(stage, "/World/analyticEye").GetPrim()
    mesh_eye = UsdGeom.Mesh.Define(stage, "/World/meshEye").GetPrim()
    for prim in (xform_eye, mesh_eye):
        prim.ApplyAPI(SCHEMA)
    for name, value in AUTHORED.items():
        mesh_eye.GetAttribute(name).Set(value)
    mesh_eye.GetRelationship("eye:irisProjection").SetTargets([Sdf.Path("/World/projection")])
    path = tmp_path / "eyes.usda"
    stage.GetRootLayer().Export(str(path))

    errors = _validate(Usd.Stage.Open(str(path)))
    related = _schema_related(errors, [xform_eye.GetPath(), mesh_eye.GetPath()])
    assert not related, _describe(related)


def test_validation_flags_an_eye_attribute_authored_with_the_wrong_type():
    # Negative control: proves the validators see the EyeAPI definition, so the test above means something.
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString("""#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 0.01
    upAxis = "Y"
)
def Xform "World"
{
    def Mesh "eye" (
        prepend apiSchemas = ["EyeAPI"]
    )
    {
        double eye:irisDepth = 3
    }
}
""")
    errors = _validate(Usd.Stage.Open(layer))
    mismatches = [e for e in errors if e.GetValidator().GetMetadata().name == "usdValidation:AttributeTypeMismatch"]
    assert mismatches, _describe(errors) or "no errors reported"
    assert "eye:irisDepth" in mismatches[0].GetMessage()
