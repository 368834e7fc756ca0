"""Textures through the USD front end: UsdUVTexture networks (formats, UDIM, wrap, scale/bias, colour spaces,
UsdTransform2d, UsdPrimvarReader_float2 varname), textures inside .usdz packages, the eye's iris texture and a
dome's .hdr, and what happens when a texture cannot be read (one warning, the fallback; --strict fails). Every
image is written here, through the package's own OpenImageIO bindings."""
import math
import os

import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade, UsdUtils  # noqa: E402

import eyerender  # noqa: F401  (registers the EyeAPI schema before pxr is used)
from eyerender import RenderSession, materials  # noqa: E402
from eyerender._hdeye import read_image, write_image  # noqa: E402
from eyerender.cli.eyerecord import main  # noqa: E402
from eyerender.errors import EyeRenderError  # noqa: E402
from eyerender.textures import TextureWarning  # noqa: E402


def srgb_decode(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def quadrants(n, colours):
    """n x n RGB pixels: top-left, top-right, bottom-left, bottom-right quadrants of the given colours."""
    img = np.zeros((n, n, 3), np.float32)
    h = n // 2
    img[:h, :h], img[:h, h:], img[h:, :h], img[h:, h:] = colours
    return img


def card_stage(path, texture_file, *, st_range=((0, 0), (1, 1)), texture_inputs=None, st_name="st",
               transform=None, surface_input="emissiveColor", output="rgb"):
    """A stage at `path`: a 4 x 4 card filling a perspective camera's view, its UsdPreviewSurface's `surface_input`
    (emissiveColor by default: the image is the texture, with no light and no noise) fed by a UsdUVTexture of
    `texture_file` through a UsdPrimvarReader_float2 of `st_name` (and a UsdTransform2d if `transform` is a dict of
    its inputs). Returns the stage (saved) and the texture shader."""
    stage = Usd.Stage.CreateNew(str(path))
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(50.0)
    cam.CreateHorizontalApertureAttr(20.0)
    cam.CreateVerticalApertureAttr(20.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    (s0, t0), (s1, t1) = st_range
    st = UsdGeom.PrimvarsAPI(card).CreatePrimvar(st_name, Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
    st.Set([(s0, t0), (s1, t0), (s1, t1), (s0, t1)])
    material = UsdShade.Material.Define(stage, "/World/Looks/card")
    surface = UsdShade.Shader.Define(stage, "/World/Looks/card/surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set((0, 0, 0))
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    reader = UsdShade.Shader.Define(stage, "/World/Looks/card/reader")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set(st_name)
    st_source = reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    if transform is not None:
        xform = UsdShade.Shader.Define(stage, "/World/Looks/card/transform")
        xform.CreateIdAttr("UsdTransform2d")
        xform.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(st_source)
        for name, value in transform.items():
            value_type = Sdf.ValueTypeNames.Float if name == "rotation" else Sdf.ValueTypeNames.Float2
            xform.CreateInput(name, value_type).Set(value)
        st_source = xform.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    texture = UsdShade.Shader.Define(stage, "/World/Looks/card/texture")
    texture.CreateIdAttr("UsdUVTexture")
    texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(texture_file)
    texture.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(st_source)
    for name, (type_name, value) in (texture_inputs or {}).items():
        texture.CreateInput(name, type_name).Set(value)
    out_type = Sdf.ValueTypeNames.Float3 if output == "rgb" else Sdf.ValueTypeNames.Float
    source = texture.CreateOutput(output, out_type)
    colour = surface_input in ("emissiveColor", "diffuseColor")
    in_type = Sdf.ValueTypeNames.Color3f if colour else Sdf.ValueTypeNames.Float
    surface.CreateInput(surface_input, in_type).ConnectToSource(source)
    UsdShade.MaterialBindingAPI.Apply(card.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()
    return stage, texture


def render(stage, size=16, spp=2, **kwargs):
    s = RenderSession(stage, width=size, height=size, **kwargs)
    s.render(spp=spp)
    return s, s.image("color")[:, :, :3]


REPEAT = {"wrapS": (Sdf.ValueTypeNames.Token, "repeat"), "wrapT": (Sdf.ValueTypeNames.Token, "repeat")}


def inner(img):
    """The image without its 2-pixel border, where footprints reach past the texture's edge (black by default)."""
    return img[2:-2, 2:-2]


def quadrant_means(img):
    """Mean RGB of the inner part of each quadrant (top-left, top-right, bottom-left, bottom-right)."""
    n = img.shape[0]
    q, e = n // 2, n // 8
    return [img[y + e:y + q - e, x + e:x + q - e].reshape(-1, 3).mean(axis=0)
            for y, x in ((0, 0), (0, q), (q, 0), (q, q))]


COLOURS = [(0.9, 0.1, 0.1), (0.1, 0.9, 0.1), (0.1, 0.1, 0.9), (0.6, 0.6, 0.1)]


def test_a_jpeg_texture_renders_its_colours_decoded_from_srgb(tmp_path):
    write_image(str(tmp_path / "q.jpg"), quadrants(64, COLOURS))
    stage, _ = card_stage(tmp_path / "s.usda", "q.jpg")
    s, img = render(stage)
    assert not s.scene.warnings
    for got, want in zip(quadrant_means(img), COLOURS):
        assert got == pytest.approx([srgb_decode(c) for c in want], abs=0.02)


def test_a_16_bit_png_renders_raw_under_auto_and_decoded_when_srgb(tmp_path):
    value = 32769 / 65535
    write_image(str(tmp_path / "a.png"), np.full((8, 8, 3), value, np.float32), "uint16")
    raw = render(card_stage(tmp_path / "raw.usda", "a.png")[0])[1]
    assert inner(raw).mean() == pytest.approx(value, abs=1e-5)
    srgb = card_stage(tmp_path / "srgb.usda", "a.png",
                      texture_inputs={"sourceColorSpace": (Sdf.ValueTypeNames.Token, "sRGB")})[0]
    assert inner(render(srgb)[1]).mean() == pytest.approx(srgb_decode(value), abs=1e-5)


def test_scale_bias_and_raw_colour_space_apply_as_usduvtexture_specifies(tmp_path):
    write_image(str(tmp_path / "a.png"), np.full((8, 8, 3), 200 / 255, np.float32))
    inputs = {"sourceColorSpace": (Sdf.ValueTypeNames.Token, "raw"),
              "scale": (Sdf.ValueTypeNames.Float4, Gf.Vec4f(0.5, 1, 2, 1)),
              "bias": (Sdf.ValueTypeNames.Float4, Gf.Vec4f(0.1, 0, -1, 0))}
    img = render(card_stage(tmp_path / "s.usda", "a.png", texture_inputs=inputs)[0])[1]
    v = 200 / 255
    assert inner(img).reshape(-1, 3).mean(axis=0) == pytest.approx([0.5 * v + 0.1, v, 2 * v - 1], abs=1e-5)


def test_udim_tiles_render_side_by_side(tmp_path):
    write_image(str(tmp_path / "t.1001.png"), np.full((8, 8, 3), (1, 0, 0), np.float32))
    write_image(str(tmp_path / "t.1002.png"), np.full((8, 8, 3), (0, 1, 0), np.float32))
    stage, _ = card_stage(tmp_path / "s.usda", "t.<UDIM>.png", st_range=((0, 0), (2, 1)))
    s, img = render(stage)
    assert not s.scene.warnings
    tl, tr, bl, br = quadrant_means(img)
    assert tl == pytest.approx((1, 0, 0), abs=1e-3) and bl == pytest.approx((1, 0, 0), abs=1e-3)
    assert tr == pytest.approx((0, 1, 0), abs=1e-3) and br == pytest.approx((0, 1, 0), abs=1e-3)


@pytest.mark.parametrize("wrap, outside", [("repeat", 0.2), ("mirror", 0.8), ("clamp", 0.8), ("black", 0.0)])
def test_wrap_modes_decide_what_lies_beyond_the_image(tmp_path, wrap, outside):
    # Left half 0.2, right half 0.8 (raw). The card's s runs over [0, 2]: its right half is s in [1, 2], where
    # a quarter in (s = 1.25) repeat shows 0.2, mirror and clamp 0.8, black 0.
    img = np.zeros((8, 64, 3), np.float32)
    img[:, :32], img[:, 32:] = 0.2, 0.8
    write_image(str(tmp_path / "h.exr"), img, "float")
    inputs = {"wrapS": (Sdf.ValueTypeNames.Token, wrap), "wrapT": (Sdf.ValueTypeNames.Token, wrap)}
    stage, _ = card_stage(tmp_path / "s.usda", "h.exr", st_range=((0, 0), (2, 1)), texture_inputs=inputs)
    out = render(stage, size=32)[1]
    assert out[16, 20, 0] == pytest.approx(outside, abs=1e-4)  # s = 1.28
    assert out[16, 4, 0] == pytest.approx(0.2, abs=1e-4)       # s = 0.28, inside the image


def test_transform2d_and_primvar_reader_varname_move_the_lookup(tmp_path):
    write_image(str(tmp_path / "q.exr"), quadrants(64, COLOURS), "float")
    # st from primvar "uv"; UsdTransform2d translates by (0.5, 0.5): every quadrant shows its diagonal opposite.
    stage, _ = card_stage(tmp_path / "s.usda", "q.exr", st_name="uv", transform={"translation": Gf.Vec2f(0.5, 0.5)},
                          texture_inputs=REPEAT)
    got = quadrant_means(render(stage)[1])
    for g, want in zip(got, COLOURS[::-1]):
        assert g == pytest.approx(want, abs=1e-3)
    # Rotation by 90 degrees about the origin, then translation by (1, 0): s' = 1 - t, t' = s.
    stage, _ = card_stage(tmp_path / "r.usda", "q.exr", st_name="uv",
                          transform={"rotation": 90.0, "translation": Gf.Vec2f(1, 0)}, texture_inputs=REPEAT)
    tl, tr, bl, br = quadrant_means(render(stage)[1])
    # The image's top-left quadrant (s < .5, t > .5) is now where s' < .5 and t' > .5: t > .5 and s > .5: top-right.
    assert tr == pytest.approx(COLOURS[0], abs=1e-3)
    params = materials.read_material(UsdShade.Material(stage.GetPrimAtPath("/World/Looks/card")),
                                     Usd.TimeCode.Default())
    assert params[1] == "uv"
    assert params[0].texture("emissiveColor").rotation == pytest.approx(90)


def test_a_texture_inside_a_usdz_package_renders_from_a_content_hash_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("EYERENDER_CACHE", str(tmp_path / "cache"))
    (tmp_path / "tex").mkdir()
    write_image(str(tmp_path / "tex" / "q.png"), quadrants(32, COLOURS))
    card_stage(tmp_path / "asset.usda", "tex/q.png")
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(tmp_path / "asset.usda")), str(tmp_path / "asset.usdz"))
    (tmp_path / "tex" / "q.png").unlink()  # only the package holds the image now
    stage = Usd.Stage.Open(str(tmp_path / "asset.usdz"))
    asset = stage.GetPrimAtPath("/World/Looks/card/texture").GetAttribute("inputs:file").Get()
    assert "asset.usdz[" in asset.resolvedPath
    s, img = render(stage)
    assert not s.scene.warnings
    for got, want in zip(quadrant_means(img), COLOURS):
        assert got == pytest.approx([srgb_decode(c) for c in want], abs=0.01)
    cached = [os.path.join(d, f) for d, _, files in os.walk(tmp_path / "cache") for f in files]
    assert len(cached) == 1 and cached[0].endswith("q.png")
    assert len(os.path.basename(os.path.dirname(cached[0]))) == 32  # the directory is the content hash
    # A second render reuses the cached file.
    mtime = os.path.getmtime(cached[0])
    render(Usd.Stage.Open(str(tmp_path / "asset.usdz")))
    assert os.path.getmtime(cached[0]) == mtime


def test_a_missing_texture_is_one_warning_with_the_fallback_rendered_and_strict_fails(tmp_path, capsys):
    inputs = {"fallback": (Sdf.ValueTypeNames.Float4, Gf.Vec4f(0.25, 0.5, 0.75, 1))}
    card_stage(tmp_path / "s.usda", "missing.png", texture_inputs=inputs)
    out = tmp_path / "out.exr"
    # No camera light (eyerecord adds one to an unlit stage, as usdrecord does): the image is the emission alone.
    assert main([str(tmp_path / "s.usda"), str(out), "-w", "8", "--spp", "1", "-q", "--no-auto-plan",
                 "--disableCameraLight"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(err) == 1, err
    assert "/World/Looks/card/texture" in err[0] and "missing.png" in err[0] and "fallback" in err[0]
    img = read_image(str(out))
    assert img[4, 4, :3] == pytest.approx((0.25, 0.5, 0.75), abs=1e-5)

    assert main([str(tmp_path / "s.usda"), str(tmp_path / "strict.exr"), "-w", "8", "--spp", "1", "-q",
                 "--strict"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("eyerecord: error: ") and "missing.png" in err[0], err
    assert len(err[0]) < 200
    assert not (tmp_path / "strict.exr").exists()


def test_corrupted_and_unsupported_textures_are_warnings_and_magenta_without_a_fallback(tmp_path):
    write_image(str(tmp_path / "good.png"), np.random.default_rng(1).random((128, 128, 3), np.float32))
    data = (tmp_path / "good.png").read_bytes()
    (tmp_path / "cut.png").write_bytes(data[:len(data) // 2])
    # A truncated JPEG decodes without an error in libjpeg (grey where the bytes end): caught all the same.
    write_image(str(tmp_path / "good.jpg"), np.random.default_rng(1).random((128, 128, 3), np.float32))
    data = (tmp_path / "good.jpg").read_bytes()
    (tmp_path / "cut.jpg").write_bytes(data[:len(data) // 2])
    (tmp_path / "notes.tif").write_text("not an image")
    for name in ("cut.png", "cut.jpg", "notes.tif"):
        stage, _ = card_stage(tmp_path / f"{name}.usda", name)
        s, img = render(stage, size=8, spp=1)
        problems = [w for w in s.scene.warnings if isinstance(w, TextureWarning)]
        assert len(problems) == 1 and name in problems[0], s.scene.warnings
        assert img[4, 4] == pytest.approx((1, 0, 1), abs=1e-6)  # magenta: no fallback authored
        with pytest.raises(EyeRenderError, match=name):
            RenderSession(stage, width=8, height=8, strict=True)


def eye_stage(path, iris_texture):
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(50.0)
    cam.CreateHorizontalApertureAttr(24.0)
    cam.CreateVerticalApertureAttr(24.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 40))
    eye = UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim()
    eye.AddAppliedSchema("EyeAPI")
    eye.CreateAttribute("eye:irisColor", Sdf.ValueTypeNames.Color3f).Set((1, 1, 1))
    eye.CreateAttribute("eye:irisTexture", Sdf.ValueTypeNames.Asset).Set(iris_texture)
    UsdLux.DomeLight.Define(stage, "/World/sky")
    stage.GetRootLayer().Save()
    return stage


def test_a_jpeg_iris_texture_colours_the_iris(tmp_path):
    write_image(str(tmp_path / "iris.jpg"), np.full((64, 64, 3), (0.1, 0.7, 0.2), np.float32))
    s, img = render(eye_stage(tmp_path / "eye.usda", "iris.jpg"), size=24, spp=4, aovs=["albedo"])
    assert not s.scene.warnings
    # The iris between 3 and 6 mm from the axis (the camera sees 9.6 mm either side of it over 12 pixels).
    y, x = np.mgrid[0:24, 0:24]
    r_mm = np.hypot(x + 0.5 - 12, y + 0.5 - 12) * 9.6 / 12
    iris = s.image("color")[(r_mm > 3) & (r_mm < 6), :3].mean(axis=0)
    assert iris[1] > 2 * iris[0] and iris[1] > 2 * iris[2], iris
    s, _ = render(eye_stage(tmp_path / "missing.usda", "nope.jpg"), size=8, spp=1)
    assert len(s.scene.warnings) == 1 and "eye:irisTexture" in s.scene.warnings[0] and "nope.jpg" in s.scene.warnings[0]


def test_a_dome_texture_in_radiance_hdr_format_lights_the_scene(tmp_path):
    sky = np.zeros((16, 32, 3), np.float32)
    sky[:8] = (2.0, 1.0, 0.5)  # the upper hemisphere
    write_image(str(tmp_path / "sky.hdr"), sky, "float")
    stage, _ = card_stage(tmp_path / "s.usda", "none.png")
    UsdShade.Shader(stage.GetPrimAtPath("/World/Looks/card/surface")).GetInput("emissiveColor").GetAttr().Clear()
    surface = UsdShade.Shader(stage.GetPrimAtPath("/World/Looks/card/surface"))
    surface.GetInput("emissiveColor").ClearSources()
    surface.GetInput("diffuseColor").Set((0.5, 0.5, 0.5))
    surface.CreateInput("ior", Sdf.ValueTypeNames.Float).Set(1.0)
    dome = UsdLux.DomeLight.Define(stage, "/World/sky")
    dome.CreateTextureFileAttr(str(tmp_path / "sky.hdr"))
    dome.AddRotateXOp().Set(90)  # the image's +y pole to +z, the card's normal
    s, img = render(stage, spp=64)
    assert not s.scene.warnings
    # A Lambertian card under a dome of radiance L above its horizon returns albedo x L.
    assert img.reshape(-1, 3).mean(axis=0) == pytest.approx((1.0, 0.5, 0.25), rel=0.05)


def test_every_texturable_preview_surface_input_is_read_with_its_channel(tmp_path):
    write_image(str(tmp_path / "rgba.png"), np.full((4, 4, 4), 0.5, np.float32))
    stage, texture = card_stage(tmp_path / "s.usda", "rgba.png", surface_input="roughness", output="g")
    surface = UsdShade.Shader(stage.GetPrimAtPath("/World/Looks/card/surface"))
    for name, out in (("metallic", "b"), ("opacity", "a"), ("normal", "rgb"), ("diffuseColor", "rgb")):
        type_name = Sdf.ValueTypeNames.Normal3f if name == "normal" else (
            Sdf.ValueTypeNames.Color3f if name == "diffuseColor" else Sdf.ValueTypeNames.Float)
        surface.CreateInput(name, type_name).ConnectToSource(texture.ConnectableAPI(), out)
    surface.CreateInput("opacityThreshold", Sdf.ValueTypeNames.Float).Set(0.5)
    surface.CreateInput("clearcoat", Sdf.ValueTypeNames.Float).Set(1.0)
    surface.CreateInput("useSpecularWorkflow", Sdf.ValueTypeNames.Int).Set(1)
    surface.CreateInput("specularColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(texture.ConnectableAPI(), "rgb")
    surface.CreateInput("displacement", Sdf.ValueTypeNames.Float).Set(0.5)
    params, st, ignored = materials.read_material(UsdShade.Material(stage.GetPrimAtPath("/World/Looks/card")),
                                                  Usd.TimeCode.Default())
    assert params.texture("roughness").channel == 1 and params.texture("metallic").channel == 2
    assert params.texture("opacity").channel == 3 and params.texture("normal").channel == -1
    assert params.texture("roughness").texture.file.endswith("rgba.png")
    assert params.opacity_threshold == pytest.approx(0.5)
    assert params.clearcoat == pytest.approx(1) and params.use_specular_workflow
    assert params.texture("specularColor").channel == -1
    assert ignored == ["/World/Looks/card/surface: inputs:displacement is not rendered"]


def test_a_uv_texture_without_a_file_renders_its_fallback_with_one_warning(tmp_path):
    # As in usd-wg's TextureFileFormatTests/_scene.usda, whose files come from the stages that reference it; the
    # specification's fallback is "the value to be used when no texture is connected".
    stage, texture = card_stage(tmp_path / "s.usda", "x.png", surface_input="diffuseColor")
    texture.GetInput("file").GetAttr().Clear()
    texture.CreateInput("fallback", Sdf.ValueTypeNames.Float4).Set((0.2, 0.4, 0.6, 1.0))
    surface = UsdShade.Shader(stage.GetPrimAtPath("/World/Looks/card/surface"))
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).ConnectToSource(texture.ConnectableAPI(), "g")
    params, _, ignored = materials.read_material(UsdShade.Material(stage.GetPrimAtPath("/World/Looks/card")),
                                                 Usd.TimeCode.Default())
    assert ignored == [f"/World/Looks/card/surface: inputs:{name}: its UsdUVTexture /World/Looks/card/texture has no "
                       f"file, so its fallback (0.2, 0.4, 0.6, 1.0) is rendered"
                       for name in ("diffuseColor", "roughness")]
    assert params.diffuse_color == pytest.approx((0.2, 0.4, 0.6)) and params.roughness == pytest.approx(0.4)
    assert params.texture("diffuseColor").texture.file == ""


def test_a_materialx_only_material_warns_and_renders_its_preview_surface_fallback(tmp_path):
    stage = Usd.Stage.CreateInMemory()
    material = UsdShade.Material.Define(stage, "/Looks/mtlx")
    mtlx = UsdShade.Shader.Define(stage, "/Looks/mtlx/standard")
    mtlx.CreateIdAttr("ND_standard_surface_surfaceshader")
    material.CreateSurfaceOutput("mtlx").ConnectToSource(mtlx.ConnectableAPI(), "out")
    _, _, ignored = materials.read_material(material, Usd.TimeCode.Default())
    assert len(ignored) == 1 and "no UsdPreviewSurface" in ignored[0] and "ND_standard_surface" in ignored[0]
    preview = UsdShade.Shader.Define(stage, "/Looks/mtlx/preview")
    preview.CreateIdAttr("UsdPreviewSurface")
    preview.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.125)
    material.CreateSurfaceOutput("fallbackContext").ConnectToSource(preview.ConnectableAPI(), "surface")
    params, _, ignored = materials.read_material(material, Usd.TimeCode.Default())
    assert params.roughness == pytest.approx(0.125)
    assert len(ignored) == 1 and "renders its UsdPreviewSurface" in ignored[0]


def test_texture_filtering_lowers_the_noise_of_a_fine_checker_at_equal_samples(tmp_path):
    n = 256
    checker = ((np.add.outer(np.arange(n), np.arange(n)) % 2).astype(np.float32))[:, :, None].repeat(3, axis=2)
    write_image(str(tmp_path / "c.png"), checker)
    stage, _ = card_stage(tmp_path / "s.usda", "c.png",
                          texture_inputs={"sourceColorSpace": (Sdf.ValueTypeNames.Token, "raw"), **REPEAT})
    var = {}
    for filtering in (False, True):
        _, img = render(stage, spp=4, settings={"texture_filtering": filtering})
        var[filtering] = float(inner(img)[:, :, 0].var())
    assert var[True] < var[False] / 20, var
    assert math.isfinite(var[True])


def test_udim_tiles_inside_a_usdz_package_are_extracted_together_and_render(tmp_path, monkeypatch):
    monkeypatch.setenv("EYERENDER_CACHE", str(tmp_path / "cache"))
    (tmp_path / "tex").mkdir()
    write_image(str(tmp_path / "tex" / "t.1001.png"), np.full((8, 8, 3), (1, 0, 0), np.float32))
    write_image(str(tmp_path / "tex" / "t.1002.png"), np.full((8, 8, 3), (0, 1, 0), np.float32))
    card_stage(tmp_path / "asset.usda", "tex/t.<UDIM>.png", st_range=((0, 0), (2, 1)))
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(tmp_path / "asset.usda")), str(tmp_path / "asset.usdz"))
    for tile in (tmp_path / "tex").iterdir():
        tile.unlink()
    s, img = render(Usd.Stage.Open(str(tmp_path / "asset.usdz")))
    assert not s.scene.warnings
    tl, tr, _, _ = quadrant_means(img)
    assert tl == pytest.approx((1, 0, 0), abs=1e-3) and tr == pytest.approx((0, 1, 0), abs=1e-3)
    cached = sorted(f for _, _, files in os.walk(tmp_path / "cache") for f in files)
    assert cached == ["t.1001.png", "t.1002.png"]


def test_a_rect_light_texture_is_read_and_a_missing_one_is_a_warning(tmp_path):
    write_image(str(tmp_path / "panel.png"), np.full((4, 4, 3), 0.5, np.float32))
    stage, _ = card_stage(tmp_path / "s.usda", "none.png")
    surface = UsdShade.Shader(stage.GetPrimAtPath("/World/Looks/card/surface"))
    surface.GetInput("emissiveColor").ClearSources()
    surface.GetInput("diffuseColor").Set((0.5, 0.5, 0.5))
    light = UsdLux.RectLight.Define(stage, "/World/panel")
    light.CreateTextureFileAttr("panel.png")
    light.AddTranslateOp().Set(Gf.Vec3d(0, 0, 3))
    lit = render(stage, size=8, spp=4)
    assert not [w for w in lit[0].scene.warnings if "panel" in w], lit[0].scene.warnings
    light.GetTextureFileAttr().Set("missing_panel.png")
    s, magenta = render(stage, size=8, spp=4)
    problems = [w for w in s.scene.warnings if isinstance(w, TextureWarning)]
    assert len(problems) == 1 and "/World/panel" in problems[0] and "missing_panel.png" in problems[0]
    # The texture halves the panel's radiance (0.5, sRGB-decoded: 0.214); the missing one lights it magenta.
    lit_card, magenta_card = inner(lit[1]).reshape(-1, 3).mean(axis=0), inner(magenta).reshape(-1, 3).mean(axis=0)
    assert lit_card[0] == pytest.approx(lit_card[1], rel=1e-6) and magenta_card[1] == 0
    assert lit_card[0] == pytest.approx(magenta_card[0] * srgb_decode(0.5), rel=0.02)
