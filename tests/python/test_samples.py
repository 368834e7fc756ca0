"""The sample stages in usd_samples/: fresh (the generator reproduces them), valid USD, in-range eye parameters,
sane meshes, and an eyeball whose subdivision limit surface lies on the analytic cornea.

conftest.py puts schemas/ on PXR_PLUGINPATH_NAME before pxr is imported, so EyeAPI is a known schema here.
"""
import functools
import importlib.util
import math
import pathlib
import subprocess
import sys
import zlib

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdValidation

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
SAMPLES_DIR = REPO_ROOT / "usd_samples"
GENERATOR = SAMPLES_DIR / "generate_samples.py"

# Tolerances of the eyeball's limit surface against the analytic model, mm. The generator prints what it reaches
# (apex ~4e-5 mm from writing the points at 1e-5 cm, cornea and limbus ~8e-3 mm, sclera ~9e-3 mm); these bounds
# leave a little room and are what usd_samples/README.md promises.
CORNEA_TOLERANCE_MM = 0.01
APEX_TOLERANCE_MM = 1e-4
SCLERA_TOLERANCE_MM = 0.012

# The analytic cornea, written out independently of the generator (eyelib/include/eyelib/anterior_surface.h).
JUNCTION_RADIUS = 10.02 / 2
TAN_CONE = math.tan(math.radians(38.0))
LIMBUS_OUTER_RADIUS = 12.89 / 2
IRIS_DIAMETER = 15.08


def cornea_sag(r):
    r = np.asarray(r, dtype=np.float64)
    ellipsoid = lambda q: -q * q / (7.8 + np.sqrt(np.maximum(0.0, 7.8 ** 2 - 0.75 * q * q)))  # noqa: E731
    return np.where(r < JUNCTION_RADIUS, ellipsoid(r),
                    ellipsoid(JUNCTION_RADIUS) - (r - JUNCTION_RADIUS) * TAN_CONE)


def _load_generator():
    spec = importlib.util.spec_from_file_location("generate_samples", GENERATOR)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


gen = _load_generator()
STAGES = sorted(name for name in gen.GENERATED_FILES if name.endswith(".usda"))


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    out = tmp_path_factory.mktemp("samples")
    result = subprocess.run([sys.executable, str(GENERATOR), "--out", str(out)], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    return out


@functools.cache
def open_stage(name):
    """The committed stage, opened once and kept alive (a Usd.Prim expires with its stage)."""
    stage = Usd.Stage.Open(str(SAMPLES_DIR / name))
    assert stage, name
    return stage


def _png_pixels(data):
    """The decompressed IDAT stream: equal for equal pixels and filters, whatever zlib build compressed it."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        length = int.from_bytes(data[pos:pos + 4], "big")
        tag = data[pos + 4:pos + 8]
        if tag == b"IDAT":
            idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    return zlib.decompress(idat)


# --- (a) freshness -------------------------------------------------------------------------------------------------
def test_generator_reproduces_the_committed_samples_byte_for_byte(regenerated):
    stale = []
    for name in gen.GENERATED_FILES:
        committed = (SAMPLES_DIR / name).read_bytes()
        fresh = (regenerated / name).read_bytes()
        if committed == fresh:
            continue
        if name.endswith(".png") and _png_pixels(committed) == _png_pixels(fresh):
            continue  # same pixels, different zlib build
        stale.append(name)
    assert not stale, "stale samples (rerun python3 usd_samples/generate_samples.py): %s" % stale


def test_samples_folder_holds_only_generated_files_readme_and_generator():
    known = set(gen.GENERATED_FILES) | {"README.md", "generate_samples.py", "production_head.py"}
    present = {p.relative_to(SAMPLES_DIR).as_posix() for p in SAMPLES_DIR.rglob("*")
               if p.is_file() and "__pycache__" not in p.parts}
    assert present == known, "unexpected: %s, missing: %s" % (sorted(present - known), sorted(known - present))


def test_every_sample_file_is_under_one_and_a_half_megabytes():
    sizes = {name: (SAMPLES_DIR / name).stat().st_size for name in gen.GENERATED_FILES}
    assert max(sizes.values()) < 1.5e6, sizes


# --- (b) UsdValidation ---------------------------------------------------------------------------------------------
# Every registered validator runs; none is excluded. The usdz-package, physics and skeleton validators have
# nothing to look at in these stages and pass trivially; they stay in so that a future sample that uses those
# features is checked too.
EXPECTED_VALIDATOR_KEYWORDS = {"UsdCoreValidators", "UsdGeomValidators", "UsdShadeValidators", "UsdLuxValidators",
                               "UsdUtilsValidators"}


@pytest.fixture(scope="module")
def validation_context():
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    keywords = {k for v in validators for k in v.GetMetadata().GetKeywords()}
    assert EXPECTED_VALIDATOR_KEYWORDS <= keywords, "validator families missing: %s" % (
        EXPECTED_VALIDATOR_KEYWORDS - keywords)
    return UsdValidation.ValidationContext(validators)


def _describe(errors):
    return "\n".join("%s [%s] %s" % (e.GetName(), e.GetType(), e.GetMessage()) for e in errors)


def test_validation_context_reports_a_deliberately_broken_stage(validation_context):
    """A clean result below means something: the same context flags a stage with a wrong-typed EyeAPI attribute
    (the EyeAPI plugin is loaded), no stage metadata and an unresolvable texture."""
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString('#usda 1.0\ndef Mesh "m" (\n    prepend apiSchemas = ["EyeAPI"]\n)\n{\n'
                           '    double eye:irisDepth = 1\n    asset eye:irisTexture = @./missing_iris.png@\n}\n')
    names = {e.GetName() for e in validation_context.Validate(Usd.Stage.Open(layer))}
    assert {"AttributeTypeMismatch", "MissingDefaultPrim", "MissingUpAxisMetadata"} <= names, names


@pytest.mark.parametrize("name", STAGES)
def test_stage_passes_every_registered_usd_validator(validation_context, name):
    errors = validation_context.Validate(open_stage(name))
    assert not errors, "%s:\n%s" % (name, _describe(errors))


@pytest.mark.parametrize("name", STAGES)
def test_stage_metadata_is_centimetres_y_up_with_a_default_prim(name):
    stage = open_stage(name)
    assert UsdGeom.GetStageMetersPerUnit(stage) == pytest.approx(0.01)
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    assert stage.GetDefaultPrim()
    if name != "assets/eye.usda":
        assert stage.GetDefaultPrim().GetPath() == Sdf.Path("/World")
        assert [p for p in stage.Traverse() if p.IsA(UsdGeom.Camera)], "no camera"
        from pxr import UsdLux
        assert [p for p in stage.Traverse() if p.HasAPI(UsdLux.LightAPI)], "no light"


# --- (c) eye parameters --------------------------------------------------------------------------------------------
def eye_prims(stage):
    return [p for p in Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies()) if p.HasAPI("EyeAPI")]


def test_the_eye_stages_contain_the_expected_eyes():
    counts = {name: len(eye_prims(open_stage(name))) for name in STAGES}
    assert counts == {"analytic_anterior.usda": 1, "assets/eye.usda": 1, "closeup.usda": 1,
                      "glass_sphere_table.usda": 0, "side_lit.usda": 1, "squash_stretch.usda": 1,
                      "two_eyes.usda": 2, "studio_eye_rig.usda": 1, "saccade.usda": 1, "blink.usda": 1,
                      "production_head.usda": 2}


def _check_eye(prim):
    """Out-of-range messages for one eye prim (empty when all is well)."""
    definition = Usd.SchemaRegistry().FindAppliedAPIPrimDefinition("EyeAPI")
    schema_names = set(definition.GetPropertyNames())
    bad = []
    for prop in prim.GetAuthoredProperties():
        if prop.GetName().startswith("eye:") and prop.GetName() not in schema_names:
            bad.append("%s is not an EyeAPI property" % prop.GetName())
    get = lambda n: prim.GetAttribute(n).Get()  # noqa: E731
    allowed = definition.GetPropertyMetadata("eye:corneaModel", "allowedTokens")
    if get("eye:corneaModel") not in allowed:
        bad.append("eye:corneaModel %r not in %s" % (get("eye:corneaModel"), list(allowed)))
    if not get("eye:corneaIor") >= 1:
        bad.append("eye:corneaIor %r < 1" % get("eye:corneaIor"))
    if not 0 < get("eye:irisDepth") < 10:
        bad.append("eye:irisDepth %r mm outside (0, 10)" % get("eye:irisDepth"))
    inner, outer = get("eye:limbusInnerRatio"), get("eye:limbusOuterRatio")
    if not (0 < inner <= 1 and 0 < outer <= 1 and inner <= outer):
        bad.append("limbus ratios inner %r outer %r not 0 < inner <= outer <= 1" % (inner, outer))
    if not 0 < get("eye:pupilDiameter") < IRIS_DIAMETER * inner:
        bad.append("eye:pupilDiameter %r mm not inside the inner limbus" % get("eye:pupilDiameter"))
    for name in ("eye:irisColor", "eye:scleraColor"):
        if not all(0 <= c <= 1 for c in get(name)):
            bad.append("%s %s outside [0, 1]" % (name, get(name)))
    texture = get("eye:irisTexture")
    if texture is not None and not (texture.resolvedPath and pathlib.Path(texture.resolvedPath).is_file()):
        bad.append("eye:irisTexture %s does not resolve" % texture)
    m = get("eye:modelTransform")
    rows = np.array([[m[i][j] for j in range(3)] for i in range(3)])
    scale = abs(np.linalg.det(rows)) ** (1 / 3)
    if not (np.linalg.det(rows) > 0 and np.allclose(rows @ rows.T, scale ** 2 * np.eye(3), atol=1e-9)):
        bad.append("eye:modelTransform is not a rotation times a uniform scale: %s" % m)
    if get("eye:limbalArc") not in (True, False):
        bad.append("eye:limbalArc %r not a bool" % get("eye:limbalArc"))
    return ["%s: %s" % (prim.GetPath(), b) for b in bad]


@pytest.mark.parametrize("name", [n for n in STAGES if n != "glass_sphere_table.usda"])
def test_every_eye_parameter_is_in_its_schema_range(name):
    prims = eye_prims(open_stage(name))
    problems = [b for prim in prims for b in _check_eye(prim)]
    assert prims and not problems, "\n".join(problems)


def test_eye_model_transform_scales_millimetres_to_centimetres():
    for name in ("assets/eye.usda", "analytic_anterior.usda"):
        for prim in eye_prims(open_stage(name)):
            m = prim.GetAttribute("eye:modelTransform").Get()
            assert Gf.Vec3d(m.Transform(Gf.Vec3d(10, 0, 0)) - m.Transform(Gf.Vec3d(0, 0, 0))).GetLength() == \
                pytest.approx(1.0), (name, m)


# --- (d) mesh sanity -----------------------------------------------------------------------------------------------
def _expected_count(interpolation, points, counts, indices):
    return {UsdGeom.Tokens.constant: 1, UsdGeom.Tokens.uniform: len(counts), UsdGeom.Tokens.vertex: len(points),
            UsdGeom.Tokens.varying: len(points), UsdGeom.Tokens.faceVarying: len(indices)}[interpolation]


def _mesh_problems(mesh):
    bad = []
    counts = np.array(mesh.GetFaceVertexCountsAttr().Get())
    indices = np.array(mesh.GetFaceVertexIndicesAttr().Get())
    times = mesh.GetPointsAttr().GetTimeSamples() or [Usd.TimeCode.Default()]
    for t in times:
        points = np.array(mesh.GetPointsAttr().Get(t))
        if not np.isfinite(points).all():
            bad.append("non-finite points at time %s" % t)
        if indices.min() < 0 or indices.max() >= len(points):
            bad.append("face vertex index outside [0, %d) at time %s" % (len(points), t))
        extent = np.array(mesh.GetExtentAttr().Get(t))
        if not (np.all(points >= extent[0] - 1e-6) and np.all(points <= extent[1] + 1e-6)):
            bad.append("extent does not bound the points at time %s" % t)
    points = np.array(mesh.GetPointsAttr().Get(times[0]))
    if (counts < 3).any():
        bad.append("faces with fewer than 3 vertices: %d" % (counts < 3).sum())
    if counts.sum() != len(indices):
        bad.append("sum(faceVertexCounts) %d != len(faceVertexIndices) %d" % (counts.sum(), len(indices)))
    for primvar in UsdGeom.PrimvarsAPI(mesh).GetPrimvarsWithValues():
        if not primvar.GetTypeName().isArray:  # a single value (UsdSkel's geomBindTransform) has no count to check
            continue
        values = primvar.Get(times[0])
        expected = _expected_count(primvar.GetInterpolation(), points, counts, indices)
        if primvar.IsIndexed():
            pv_indices = np.array(primvar.GetIndices())
            if len(pv_indices) != expected or pv_indices.min() < 0 or pv_indices.max() >= len(values):
                bad.append("%s: %d indices (want %d) into %d values" % (primvar.GetName(), len(pv_indices),
                                                                       expected, len(values)))
        elif len(values) != expected:
            bad.append("%s: %d values, %s interpolation wants %d" % (primvar.GetName(), len(values),
                                                                    primvar.GetInterpolation(), expected))
        if not np.isfinite(np.array(values, dtype=np.float64)).all():
            bad.append("%s has non-finite values" % primvar.GetName())
    return ["%s: %s" % (mesh.GetPath(), b) for b in bad]


@pytest.mark.parametrize("name", STAGES)
def test_every_mesh_is_sane(name):
    stage = open_stage(name)
    meshes = [UsdGeom.Mesh(p) for p in Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies())
              if p.IsA(UsdGeom.Mesh)]
    problems = [b for m in meshes for b in _mesh_problems(m)]
    assert meshes or name == "analytic_anterior.usda", "no meshes"   # the analytic eye alone has none
    assert not problems, "\n".join(problems)


def test_eyeball_mesh_has_st_and_rest_primvars_and_a_textured_sclera_material():
    from pxr import UsdShade
    prim = open_stage("assets/eye.usda").GetPrimAtPath("/Eye/Eyeball")
    mesh = UsdGeom.Mesh(prim)
    assert mesh.GetSubdivisionSchemeAttr().Get() == UsdGeom.Tokens.catmullClark
    primvars = UsdGeom.PrimvarsAPI(mesh)
    rest = primvars.GetPrimvar("rest")
    assert rest.GetInterpolation() == UsdGeom.Tokens.vertex
    assert np.array_equal(np.array(rest.Get()), np.array(mesh.GetPointsAttr().Get()))
    assert primvars.GetPrimvar("st").GetInterpolation() == UsdGeom.Tokens.faceVarying
    assert 300 <= len(mesh.GetPointsAttr().Get()) <= 2000
    material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
    surface = material.ComputeSurfaceSource()[0]
    assert surface.GetIdAttr().Get() == "UsdPreviewSurface"
    texture = surface.GetInput("diffuseColor").GetConnectedSources()[0][0].source
    assert UsdShade.Shader(texture.GetPrim()).GetIdAttr().Get() == "UsdUVTexture"


def test_squash_stretch_is_a_volume_preserving_scale_of_the_rest_points_about_the_eyeball_centre():
    stage = open_stage("squash_stretch.usda")
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Eye/Eyeball"))
    rest = np.array(UsdGeom.PrimvarsAPI(mesh).GetPrimvar("rest").Get(), dtype=np.float64)
    times = mesh.GetPointsAttr().GetTimeSamples()
    assert times == list(range(1, 25)) and stage.GetStartTimeCode() == 1 and stage.GetEndTimeCode() == 24
    along = []
    for t in times:
        points = np.array(mesh.GetPointsAttr().Get(t), dtype=np.float64)
        scale = np.linalg.lstsq(rest, points, rcond=None)[0]                 # rest @ S = points
        assert np.allclose(scale, np.diag(np.diag(scale)), atol=1e-4), (t, scale)
        sx, sy, sz = np.diag(scale)
        assert sx * sy * sz == pytest.approx(1.0, abs=2e-3), (t, sx, sy, sz)
        along.append(sz)
    assert max(along) == pytest.approx(1.5, abs=0.01) and min(along) == pytest.approx(1 / 1.5, abs=0.01)


def _gaze_yaw(stage, time):
    xf = UsdGeom.Xformable(stage.GetPrimAtPath("/World/Eye/Eyeball")).ComputeLocalToWorldTransform(time)
    gaze = xf.TransformDir(Gf.Vec3d(0, 0, 1))
    return math.degrees(math.atan2(gaze[0], gaze[2]))


def test_saccade_turns_ten_degrees_within_frame_elevens_180_degree_shutter():
    stage = open_stage("saccade.usda")
    camera = UsdGeom.Camera(stage.GetPrimAtPath("/World/Camera"))
    opens, closes = camera.GetShutterOpenAttr().Get(), camera.GetShutterCloseAttr().Get()
    assert (opens, closes) == (-0.25, 0.25) and stage.GetFramesPerSecond() == 24
    swept = _gaze_yaw(stage, 11 + closes) - _gaze_yaw(stage, 11 + opens)
    assert swept == pytest.approx(10.0, abs=1e-6), swept
    speed = swept / ((closes - opens) / stage.GetFramesPerSecond())  # degrees per second
    assert 300 <= speed <= 700, speed
    for frame in (10, 12):  # the eye is still through the neighbouring frames' shutters
        assert _gaze_yaw(stage, frame + opens) == pytest.approx(_gaze_yaw(stage, frame + closes), abs=1e-9)


def test_blink_lids_clear_the_cornea_and_shut_over_it():
    stage = open_stage("blink.usda")
    upper = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Eye/UpperLid"))
    lower = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Eye/LowerLid"))
    apex_cm = -gen.EYEBALL_CENTER_Z * gen.MM_TO_CM
    margins = {}
    for t in upper.GetPointsAttr().GetTimeSamples():
        points = np.array(upper.GetPointsAttr().Get(t), dtype=np.float64)
        assert np.linalg.norm(points, axis=1).min() > apex_cm  # never through the cornea
        margins[t] = math.degrees(math.asin(points[:, 1].min() / np.linalg.norm(points[0])))
    lower_points = np.array(lower.GetPointsAttr().Get(), dtype=np.float64)
    assert np.linalg.norm(lower_points, axis=1).min() > apex_cm
    lower_margin = lower_points[:, 1].max()  # shut, the upper lid comes down past it (they overlap)
    assert margins[1] > 20 and margins[12] < math.degrees(math.asin(lower_margin / (gen.LOWER_LID_RADIUS_MM / 10)))
    assert margins[24] == pytest.approx(margins[1])


def test_two_eyes_are_instances_that_look_at_the_common_point():
    stage = open_stage("two_eyes.usda")
    look_at = UsdGeom.Xformable(stage.GetPrimAtPath("/World/LookAt"))
    target = look_at.ComputeLocalToWorldTransform(0).ExtractTranslation()
    for path in ("/World/EyeL", "/World/EyeR"):
        prim = stage.GetPrimAtPath(path)
        assert prim.IsInstance(), path
        xf = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(0)
        gaze = xf.TransformDir(Gf.Vec3d(0, 0, 1)).GetNormalized()
        to_target = (target - xf.ExtractTranslation()).GetNormalized()
        assert math.degrees(math.acos(min(1.0, gaze * to_target))) < 0.01, path


# --- (e) the eyeball follows the analytic cornea -------------------------------------------------------------------
def test_limit_stencil_agrees_with_refinement():
    """The limit position of a vertex does not change under refinement: the stencil on the refined mesh gives the
    same points at the original vertices (refined vertex i is original vertex i). Checks the stencil and the
    refinement step the cornea test below relies on."""
    dirs, faces = gen.cube_sphere(4)
    cage = dirs * (1 + 0.3 * dirs[:, :1] ** 2)                              # not a sphere: a real test
    refined, refined_faces = gen.catmull_clark_step(cage, faces)
    before = gen.limit_stencil(cage, faces)
    after = gen.limit_stencil(refined, refined_faces)[:len(cage)]
    assert np.abs(before - after).max() < 1e-12


def test_eyeball_limit_surface_lies_on_the_analytic_cornea_and_sclera():
    prim = open_stage("assets/eye.usda").GetPrimAtPath("/Eye/Eyeball")
    mesh = UsdGeom.Mesh(prim)
    points_cm = np.array(mesh.GetPointsAttr().Get(), dtype=np.float64)
    counts = np.array(mesh.GetFaceVertexCountsAttr().Get())
    assert (counts == 4).all(), "the check below assumes an all-quad closed cage"
    faces = np.array(mesh.GetFaceVertexIndicesAttr().Get()).reshape(-1, 4)
    # Exact limit points: 25 per cage face (2 refinements, then the limit stencil).
    limit_cm = gen.limit_samples(points_cm, faces, levels=2)
    to_canonical = prim.GetAttribute("eye:modelTransform").Get().GetInverse()
    canonical = np.array([to_canonical.Transform(Gf.Vec3d(*p)) for p in limit_cm])   # mm, apex at the origin
    centre = np.array(to_canonical.Transform(Gf.Vec3d(0, 0, 0)))                     # the eyeball centre, mm
    r = np.hypot(canonical[:, 0], canonical[:, 1])
    front = (canonical[:, 2] > centre[2]) & (r < LIMBUS_OUTER_RADIUS)
    err = canonical[front, 2] - cornea_sag(r[front])
    apex = np.argmin(np.where(front, r, np.inf))
    assert r[apex] < 1e-6 and abs(canonical[apex, 2]) < APEX_TOLERANCE_MM, canonical[apex]
    worst = np.argmax(np.abs(err))
    assert np.abs(err).max() < CORNEA_TOLERANCE_MM, "cornea error %.4f mm at r = %.3f mm (%d samples)" % (
        err[worst], r[front][worst], front.sum())
    assert front.sum() > 500
    # Sclera: beyond the 0.5 mm blend and at the back, a sphere about the eyeball centre.
    sclera = (canonical[:, 2] < centre[2]) | (r > LIMBUS_OUTER_RADIUS + 0.55)
    radius = np.linalg.norm(canonical[sclera] - centre, axis=1)
    assert 11.0 < np.median(radius) < 13.0
    assert np.abs(radius - np.median(radius)).max() < SCLERA_TOLERANCE_MM, np.abs(radius - np.median(radius)).max()
    # The whole surface stays between the two: no dent or bulge anywhere in the blend band either.
    band = ~front & ~sclera
    rho = np.linalg.norm(canonical[band] - centre, axis=1)
    assert band.any() and np.all(rho > np.median(radius) - SCLERA_TOLERANCE_MM)


def test_production_head_lids_and_lashes_are_skinned_and_the_lashes_stay_outside_the_eye():
    """The upper lids and their lashes follow their joints (UsdSkel's own skinning, baked): at the last frame the
    upper margin has come down by the authored drop, the lower lid has not moved, and every lash point lies outside
    the eyeball's corneal apex sphere (13.03 mm about the eyeball centre), in front of the lid at every frame."""
    from pxr import UsdSkel
    spec = importlib.util.spec_from_file_location("production_head", SAMPLES_DIR / "production_head.py")
    head = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(SAMPLES_DIR))
    try:
        spec.loader.exec_module(head)
    finally:
        sys.path.remove(str(SAMPLES_DIR))
    stage = open_stage("production_head.usda")
    cache = UsdSkel.Cache()
    root = UsdSkel.Root(stage.GetPrimAtPath("/World/Head"))
    cache.Populate(root, Usd.TraverseInstanceProxies())

    def skinned(path, frame):
        prim = stage.GetPrimAtPath(path)
        binding = cache.ComputeSkelBinding(root, UsdSkel.Skeleton(stage.GetPrimAtPath("/World/Head/Skel")),
                                           Usd.TraverseInstanceProxies())
        target = next(t for t in binding.GetSkinningTargets() if t.GetPrim() == prim)
        skel_query = cache.GetSkelQuery(binding.GetSkeleton())
        xforms = skel_query.ComputeSkinningTransforms(frame)
        points = UsdGeom.PointBased(prim).GetPointsAttr().Get(frame)
        assert target.ComputeSkinnedPoints(xforms, points, frame)
        return np.array(points, np.float64)

    first, last = head.FRAMES
    for side, centre in head.EYE_CENTERS_CM.items():
        c = np.array(centre)
        for frame, drop in ((first, 0.0), (last, head.LID_DROP_DEG)):
            upper = skinned(f"/World/Head/UpperLid_{side}", frame) - c
            margin = np.degrees(np.arcsin(upper[:, 1] / np.linalg.norm(upper, axis=1))).min()
            assert margin == pytest.approx(head.UPPER_LID["elevation_deg"][0] - drop, abs=0.05), (side, frame)
            lower = skinned(f"/World/Head/LowerLid_{side}", frame) - c
            top = np.degrees(np.arcsin(lower[:, 1] / np.linalg.norm(lower, axis=1))).max()
            assert top == pytest.approx(head.LOWER_LID["elevation_deg"][1], abs=0.05)
            lashes = skinned(f"/World/Head/Lashes_{side}", frame) - c
            assert np.linalg.norm(lashes, axis=1).min() * 10 > 13.03
