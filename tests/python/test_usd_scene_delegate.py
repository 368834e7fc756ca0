"""The USD scene delegate: what it populates, what it re-syncs when time moves (counted), and how it reports bad
input (one line naming the prim and attribute)."""
import math

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade  # noqa: E402

from eyerender import RenderSession  # noqa: E402


def quad_grid_mesh(stage, path, n=4, size=2.0, scheme="catmullClark"):
    """An n x n quad grid in the xy plane, centred at the origin."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    pts = [(size * (i / n - 0.5), size * (j / n - 0.5), 0.0) for j in range(n + 1) for i in range(n + 1)]
    quads = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
             for j in range(n) for i in range(n)]
    mesh.CreatePointsAttr(pts)
    mesh.CreateFaceVertexCountsAttr([4] * len(quads))
    mesh.CreateFaceVertexIndicesAttr([i for q in quads for i in q])
    mesh.CreateSubdivisionSchemeAttr(scheme)
    return mesh


def base_stage():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(3)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 8))
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateIntensityAttr(20.0)
    light.AddTranslateOp().Set(Gf.Vec3d(2, 3, 4))
    return stage


def session(stage, **kwargs):
    kwargs.setdefault("width", 32)
    kwargs.setdefault("height", 24)
    return RenderSession(stage, **kwargs)


def skipped_with_one_warning(stage, path, **kwargs):
    """The one warning a session of `stage` gives for prim `path`, after checking that the prim was skipped and
    the rest of the stage still rendered."""
    s = session(stage, **kwargs)
    warnings = [w for w in s.scene.warnings if w.startswith(f"{path}: ")]
    assert len(warnings) == 1 and warnings[0].endswith("(skipped)"), s.scene.warnings
    assert "\n" not in warnings[0] and len(warnings[0]) < 200
    assert path not in s.index.rprim_ids() and path not in s.scene.eyes
    s.render(spp=1)
    return warnings[0]


def test_time_change_resyncs_only_what_varies():
    stage = base_stage()
    static = quad_grid_mesh(stage, "/World/static")
    animated = quad_grid_mesh(stage, "/World/animated")
    points = animated.GetPointsAttr().Get()
    for t in (1, 2, 3):
        animated.GetPointsAttr().Set([p + Gf.Vec3f(0, 0, 0.1 * t) for p in points], t)
    mover = UsdGeom.Xform.Define(stage, "/World/mover")
    op = mover.AddTranslateOp()
    op.Set(Gf.Vec3d(0, 0, 0), 1)
    op.Set(Gf.Vec3d(0, 1, 0), 3)
    quad_grid_mesh(stage, "/World/mover/child", scheme="none")
    intensity = UsdLux.LightAPI(stage.GetPrimAtPath("/World/key")).GetIntensityAttr()
    intensity.Set(20.0, 1)
    intensity.Set(40.0, 3)  # two samples: one alone would be a constant
    del static

    s = session(stage, time=1)
    s.render(spp=1)
    before = {p: s.index.mesh_stats(p) for p in ("/World/static", "/World/animated", "/World/mover/child")}
    counts = s.scene.set_time(2)
    assert dict(counts) == {"points": 1, "transform": 1, "light": 1}
    s.render(spp=1)
    after = {p: s.index.mesh_stats(p) for p in before}
    assert after["/World/static"] == before["/World/static"]  # untouched: nothing of it varies
    delta = {k: after["/World/animated"][k] - before["/World/animated"][k] for k in before["/World/animated"]}
    assert delta["stencil_evaluations"] == 1 and delta["point_uploads"] == 1
    assert delta["refinements"] == 0 and delta["topology_builds"] == 0  # topology is refined once
    child = {k: after["/World/mover/child"][k] - before["/World/mover/child"][k] for k in before["/World/mover/child"]}
    assert child["transform_updates"] == 1 and child["point_uploads"] == 0


def test_vt_arrays_are_accepted_without_conversion():
    stage = base_stage()
    mesh = quad_grid_mesh(stage, "/World/grid", scheme="none")
    store = eyerender.SceneStore(eyerender.RenderIndex(eyerender.RenderDelegate()))
    # Vt arrays expose their memory through the buffer protocol: they go straight to C++ (one copy, into the store).
    store.add_mesh("/m", mesh.GetFaceVertexCountsAttr().Get(), mesh.GetFaceVertexIndicesAttr().Get(),
                   mesh.GetPointsAttr().Get(), np.eye(4))
    with pytest.raises(TypeError):
        store.set_points("/m", np.zeros((3, 2), dtype=np.float32))  # not (n, 3): refused, not misread


def test_eye_on_xform_and_mesh_are_eyes_with_schema_fallbacks():
    stage = base_stage()
    xform = UsdGeom.Xform.Define(stage, "/World/analytic").GetPrim()
    xform.AddAppliedSchema("EyeAPI")
    mesh = quad_grid_mesh(stage, "/World/eyeMesh").GetPrim()
    mesh.AddAppliedSchema("EyeAPI")
    s = session(stage)
    assert s.scene.eyes == ["/World/analytic", "/World/eyeMesh"]
    s.render(spp=1)


def test_degenerate_and_nan_meshes_are_skipped_with_a_warning():
    stage = base_stage()
    mesh = quad_grid_mesh(stage, "/World/bad", scheme="none")
    pts = list(mesh.GetPointsAttr().Get())
    pts[3] = Gf.Vec3f(math.nan, 0, 0)
    mesh.GetPointsAttr().Set(pts)
    assert "points holds NaN" in skipped_with_one_warning(stage, "/World/bad")
    mesh.GetPointsAttr().Set([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    assert "faceVertexIndices refers to points outside" in skipped_with_one_warning(stage, "/World/bad")
    mesh.GetFaceVertexCountsAttr().Set([2])
    mesh.GetFaceVertexIndicesAttr().Set([0, 1])
    assert "fewer than 3" in skipped_with_one_warning(stage, "/World/bad")


def test_instancing_and_point_instancer_share_their_prototypes():
    stage = base_stage()
    proto = quad_grid_mesh(stage, "/Prototypes/card/geo", scheme="none")
    del proto
    for name, x in (("a", -2.0), ("b", 2.0)):
        inst = UsdGeom.Xform.Define(stage, f"/World/{name}")
        inst.AddTranslateOp().Set(Gf.Vec3d(x, 0, 0))
        inst.GetPrim().GetReferences().AddInternalReference("/Prototypes/card")
        inst.GetPrim().SetInstanceable(True)
    stage.GetPrimAtPath("/Prototypes").SetSpecifier(Sdf.SpecifierClass)  # not rendered itself
    pi = UsdGeom.PointInstancer.Define(stage, "/World/scatter")
    quad_grid_mesh(stage, "/World/scatter/protos/tile", scheme="none")
    pi.CreatePrototypesRel().SetTargets(["/World/scatter/protos/tile"])
    pi.CreatePositionsAttr([(0, 3, 0), (0, -3, 0), (3, 3, 0)])
    pi.CreateProtoIndicesAttr([0, 0, 0])
    s = session(stage)
    ids = s.index.rprim_ids()
    s.index.sync_all()
    assert s.index.mesh_stats("/World/a/__instances/geo")["instances_drawn"] == 2
    assert [i for i in ids if i.startswith("/World/scatter/")] == ["/World/scatter/__prototype0/tile"]
    assert s.index.mesh_stats("/World/scatter/__prototype0/tile")["instances_drawn"] == 3
    assert "/World/scatter/protos/tile" not in ids  # prototypes render only through the instancer


def test_purposes_and_visibility():
    stage = base_stage()
    guide = quad_grid_mesh(stage, "/World/guide", scheme="none")
    guide.CreatePurposeAttr(UsdGeom.Tokens.guide)
    hidden = quad_grid_mesh(stage, "/World/hidden", scheme="none")
    hidden.CreateVisibilityAttr(UsdGeom.Tokens.invisible)
    s = session(stage)
    assert "/World/guide" not in s.index.rprim_ids()
    assert "/World/guide" in session(stage, purposes=("guide",)).index.rprim_ids()
    s.render(spp=1)
    assert s.image("color")[:, :, 3].max() == 0  # the only geometry in view is invisible


def test_a_childs_own_purpose_overrides_the_one_it_inherits():
    # OpenUSD's InheritedPurpose stage: a default-purpose child of a guide scope renders, as USD computes it.
    stage = base_stage()
    UsdGeom.Scope.Define(stage, "/World/guides").CreatePurposeAttr(UsdGeom.Tokens.guide)
    quad_grid_mesh(stage, "/World/guides/inherits", scheme="none")
    quad_grid_mesh(stage, "/World/guides/own", scheme="none").CreatePurposeAttr(UsdGeom.Tokens.default_)
    ids = session(stage).index.rprim_ids()
    assert "/World/guides/own" in ids and "/World/guides/inherits" not in ids


def red_material(stage, path, color):
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, f"{path}/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(color)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return material


def test_a_preview_purpose_binding_wins_over_the_all_purpose_one_and_stands_alone():
    stage = base_stage()
    both = quad_grid_mesh(stage, "/World/both", n=1, size=0.9, scheme="none")
    both.AddTranslateOp().Set(Gf.Vec3d(-0.55, 0, 0))
    alone = quad_grid_mesh(stage, "/World/alone", n=1, size=0.9, scheme="none")
    alone.AddTranslateOp().Set(Gf.Vec3d(0.55, 0, 0))
    full, preview = red_material(stage, "/World/Looks/full", (0.1, 0.1, 0.9)), \
        red_material(stage, "/World/Looks/preview", (0.9, 0.1, 0.1))
    binding = UsdShade.MaterialBindingAPI.Apply(both.GetPrim())
    binding.Bind(full)
    binding.Bind(preview, materialPurpose=UsdShade.Tokens.preview)
    UsdShade.MaterialBindingAPI.Apply(alone.GetPrim()).Bind(preview, materialPurpose=UsdShade.Tokens.preview)
    s = session(stage, width=48, height=24, aovs=("albedo",))
    s.render(spp=1)
    albedo = s.image("albedo")
    assert albedo[12, 16, :3] == pytest.approx((0.9, 0.1, 0.1), abs=1e-6)  # both: the preview material
    assert albedo[12, 32, :3] == pytest.approx((0.9, 0.1, 0.1), abs=1e-6)  # alone: it (was the fallback grey)


def test_a_constant_display_color_is_inherited_from_an_ancestor_unless_the_prim_has_its_own():
    stage = base_stage()
    group = UsdGeom.Xform.Define(stage, "/World/group")
    UsdGeom.PrimvarsAPI(group).CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray,
                                             UsdGeom.Tokens.constant).Set([(0.8, 0.1, 0.1)])
    inherits = quad_grid_mesh(stage, "/World/group/inherits", n=1, size=0.9, scheme="none")
    inherits.AddTranslateOp().Set(Gf.Vec3d(-0.55, 0, 0))
    own = quad_grid_mesh(stage, "/World/group/own", n=1, size=0.9, scheme="none")
    own.AddTranslateOp().Set(Gf.Vec3d(0.55, 0, 0))
    # A color3f where color3f[] is meant (OpenUSD's InstancePrimvars stage) is read as one colour, as Storm does.
    spec = Sdf.AttributeSpec(stage.GetRootLayer().GetPrimAtPath(own.GetPath()), "primvars:displayColor",
                             Sdf.ValueTypeNames.Color3f)
    spec.default = Gf.Vec3f(0.1, 0.7, 0.2)
    s = session(stage, width=48, height=24, aovs=("albedo",))
    assert not s.scene.warnings
    s.render(spp=1)
    albedo = s.image("albedo")
    assert albedo[12, 16, :3] == pytest.approx((0.8, 0.1, 0.1), abs=1e-6)
    assert albedo[12, 32, :3] == pytest.approx((0.1, 0.7, 0.2), abs=1e-6)


@pytest.mark.parametrize("kind", ["Mesh", "Sphere"])
def test_point_instancer_prototypes_under_an_invisible_scope_render_through_the_instancer(kind):
    # OpenUSD's InstancePrimvars stage keeps its prototypes under an invisible Scope, so they do not render in place.
    stage = base_stage()
    UsdGeom.Scope.Define(stage, "/World/Prototypes").CreateVisibilityAttr(UsdGeom.Tokens.invisible)
    for name in ("tile", "hidden_tile"):
        if kind == "Mesh":
            quad_grid_mesh(stage, f"/World/Prototypes/{name}", size=0.5, scheme="none")
        else:
            UsdGeom.Sphere.Define(stage, f"/World/Prototypes/{name}").CreateRadiusAttr(0.25)
    hidden = UsdGeom.Imageable(stage.GetPrimAtPath("/World/Prototypes/hidden_tile"))
    hidden.CreateVisibilityAttr(UsdGeom.Tokens.invisible)  # a prototype's own visibility still counts
    pi = UsdGeom.PointInstancer.Define(stage, "/World/scatter")
    pi.CreatePrototypesRel().SetTargets(["/World/Prototypes/tile", "/World/Prototypes/hidden_tile"])
    pi.CreatePositionsAttr([(-1, 0, 0), (1, 0, 0)])
    pi.CreateProtoIndicesAttr([0, 1])
    s = session(stage)
    assert [i for i in s.index.rprim_ids() if i.startswith("/World/scatter/")] == ["/World/scatter/__prototype0/tile"]
    s.render(spp=1)
    alpha = s.image("color")[12, :, 3]  # the 32 px row through the instances: x = -1 at pixel 6, x = 1 at 25
    assert alpha[6] == 1 and alpha[16] == 0 and alpha[25] == 0, alpha  # the tile's instance; nothing in place


def test_a_point_instancer_prototype_under_an_over_renders_and_one_that_is_an_over_does_not():
    # OpenUSD's sphereInstancer stage: the prototype's own def counts, not its parent's.
    stage = base_stage()
    pi = UsdGeom.PointInstancer.Define(stage, "/World/scatter")
    UsdGeom.Sphere.Define(stage, "/World/scatter/protos/ball")
    UsdGeom.Sphere.Define(stage, "/World/scatter/protos/ghost/ball")
    for over in ("/World/scatter/protos", "/World/scatter/protos/ghost"):  # Define made them defs
        stage.GetPrimAtPath(over).SetSpecifier(Sdf.SpecifierOver)
    pi.CreatePrototypesRel().SetTargets(["/World/scatter/protos/ball", "/World/scatter/protos/ghost"])
    pi.CreatePositionsAttr([(0, 0, 0), (1, 0, 0), (2, 0, 0)])
    pi.CreateProtoIndicesAttr([0, 0, 1])
    s = session(stage)
    s.index.sync_all()
    assert [i for i in s.index.rprim_ids() if i.startswith("/World/scatter/")] == ["/World/scatter/__prototype0/ball"]
    assert s.index.mesh_stats("/World/scatter/__prototype0/ball")["instances_drawn"] == 2


def test_preview_surface_and_texture_are_read(tmp_path):
    stage = base_stage()
    mesh = quad_grid_mesh(stage, "/World/card", scheme="none")
    material = UsdShade.Material.Define(stage, "/World/Looks/red")
    shader = UsdShade.Shader.Define(stage, "/World/Looks/red/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set((0.8, 0.1, 0.1))
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.25)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
    params, st_name, ignored = eyerender.materials.read_material(material, Usd.TimeCode.Default())
    assert params.diffuse_color == pytest.approx((0.8, 0.1, 0.1)) and params.roughness == pytest.approx(0.25)
    assert params.ior == pytest.approx(1.5) and st_name == "st" and not ignored
    shader.GetInput("roughness").Set(1.5)
    s = session(stage)  # the mesh bound to the bad material is skipped, the warning names the shader
    assert s.scene.warnings == ["/World/Looks/red/surface: inputs:roughness = 1.5 is out of range (skipped)"]
    assert "/World/card" not in s.index.rprim_ids()


def test_diffuse_color_from_a_display_color_reader_renders_the_prims_display_color():
    # The usd-wg Teapot's and Pyramid's pattern: diffuseColor <- UsdPrimvarReader_float3(varname displayColor). A card
    # with displayColor shows it; one without shows the reader's fallback; a reader of another primvar is warned
    # about and the shader's own constant is rendered.
    stage = base_stage()
    cards = {}
    for k, (name, varname, color) in enumerate([("painted", "displayColor", (0.9, 0.2, 0.1)),
                                                ("bare", "displayColor", None),
                                                ("other", "myColor", (0.9, 0.2, 0.1))]):
        mesh = quad_grid_mesh(stage, f"/World/{name}", n=1, size=0.9, scheme="none")
        mesh.AddTranslateOp().Set(Gf.Vec3d(1.1 * (k - 1), 0, 0))
        if color:
            mesh.CreateDisplayColorAttr([color])
        material = UsdShade.Material.Define(stage, f"/World/Looks/{name}")
        shader = UsdShade.Shader.Define(stage, f"/World/Looks/{name}/surface")
        shader.CreateIdAttr("UsdPreviewSurface")
        reader = UsdShade.Shader.Define(stage, f"/World/Looks/{name}/color")
        reader.CreateIdAttr("UsdPrimvarReader_float3")
        reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set(varname)
        reader.CreateInput("fallback", Sdf.ValueTypeNames.Float3).Set((0.1, 0.5, 0.2))
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
            reader.ConnectableAPI(), "result")
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
        cards[name] = 24 + 16 * (k - 1)  # the card's centre column (the view is 3.4 wide at the cards, 48 px)
    s = session(stage, width=48, height=24, aovs=("albedo",))
    assert s.scene.warnings == ["/World/Looks/other/surface: inputs:diffuseColor reads primvar 'myColor' "
                                "(/World/Looks/other/color); only displayColor is read this way, so its constant is "
                                "rendered"]
    s.render(spp=1)
    albedo = s.image("albedo")
    for name, expected in [("painted", (0.9, 0.2, 0.1)), ("bare", (0.1, 0.5, 0.2)), ("other", (0.18, 0.18, 0.18))]:
        assert albedo[12, cards[name], :3] == pytest.approx(expected, abs=1e-6), name


def test_a_primvar_that_does_not_fit_its_mesh_is_dropped_with_one_warning():
    # OpenUSD's testUsdImagingGLColorOpacityPrimvar has such a mesh (WarnBadUniformColorUniformOpacity); the render
    # ended with an error.
    stage = base_stage()
    mesh = quad_grid_mesh(stage, "/World/card", n=2, scheme="none")
    UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray,
                                            UsdGeom.Tokens.uniform).Set([(1, 0, 0)] * 3)  # 4 faces
    s = session(stage, aovs=("albedo",))
    s.render(spp=1)
    s.render(spp=1)
    assert s.scene.warnings == ["/World/card: primvars:displayColor: uniform needs 4 elements, got 3: ignored"]
    albedo = s.image("albedo")
    assert albedo[12, 16, :3] == pytest.approx((0.18, 0.18, 0.18), abs=1e-6)  # the fallback surface's grey


def test_default_camera_frames_a_stage_without_one():
    stage = Usd.Stage.CreateInMemory()
    quad_grid_mesh(stage, "/World/card", scheme="none")
    UsdLux.DomeLight.Define(stage, "/World/sky")
    s = session(stage)
    s.render(spp=1)
    coverage = (s.image("color")[:, :, 3] > 0).mean()
    assert 0.1 < coverage < 1.0  # the card is in view, framed with a margin


@pytest.mark.parametrize("light_type", ["DomeLight", "DistantLight", "SphereLight", "RectLight", "DiskLight"])
def test_each_light_kind_lights_a_card(light_type):
    # The light's kind comes from its prim type alone (a dome once rendered as a sphere light at the origin).
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    quad_grid_mesh(stage, "/card", n=1, size=20, scheme="none")
    light = getattr(UsdLux, light_type).Define(stage, "/light")
    light.CreateIntensityAttr(1.0)
    if light_type == "DistantLight":  # intensity 1 is the radiance of a 0.53 degree disc: normalize makes it 1 lux
        light.CreateNormalizeAttr(True)
    if light_type not in ("DomeLight", "DistantLight"):
        light.AddTranslateOp().Set(Gf.Vec3d(0, 0, 3))
    s = session(stage, width=8, height=8)
    s.render(spp=8)
    card = s.image("color")[:, :, :3]
    assert card.mean() > 1e-3 and np.isfinite(card).all()
    if light_type == "DomeLight":  # a furnace: the card returns about its albedo (0.18, plus its 4 % coat)
        assert 0.15 < card.mean() < 0.3


def test_an_eye_stays_an_eye_without_the_schema_plugin(tmp_path):
    # A process that opened the stage before importing eyerender has built USD's schema registry without the
    # EyeAPI: GetAppliedSchemas() no longer lists it. The composed apiSchemas metadata still does, and the
    # renderer's own fallbacks stand in for the schema's.
    import os
    import subprocess
    import sys

    path = tmp_path / "eye.usda"
    path.write_text('#usda 1.0\ndef Xform "Eye" (prepend apiSchemas = ["EyeAPI"]) {}\n')
    script = ("from pxr import Usd\n"
              f"stage = Usd.Stage.Open({str(path)!r})\n"
              "prim = stage.GetPrimAtPath('/Eye')\n"
              "registered = 'EyeAPI' in prim.GetAppliedSchemas()\n"
              "from eyerender import eyes\n"
              "print(registered, eyes.is_eye(prim), eyes.read_eye_params(prim).iris_depth)\n")
    env = {k: v for k, v in os.environ.items() if k != "PXR_PLUGINPATH_NAME"}
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False", "True", "3.735"]


def test_zero_radius_light_is_warned_about():
    stage = base_stage()
    UsdLux.SphereLight(stage.GetPrimAtPath("/World/key")).CreateRadiusAttr(0.0)
    s = session(stage)
    assert any("radius 0 emits nothing" in w for w in s.scene.warnings)
