"""UsdRender as the specification of eyerecord's outputs: products and their ordered vars, each product one file
with exactly its vars' channels (half or float, one part or one per var, cropped to its data window), per-product
camera and resolution, and the command line's flags over them."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
OpenEXR = pytest.importorskip("OpenEXR", reason="the openexr Python package reads multi-part files")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdRender  # noqa: E402

from eyerender.aovs import AOV_CHANNELS, EYE_PART_AOVS  # noqa: E402
from eyerender.cli.eyerecord import main  # noqa: E402


def define_var(stage, name, source, data_type, source_type=None):
    var = UsdRender.Var.Define(stage, f"/Render/Vars/{name}")
    var.CreateSourceNameAttr(source)
    var.CreateDataTypeAttr(data_type)
    if source_type:
        var.CreateSourceTypeAttr(source_type)
    return var


def define_product(stage, name, file_name, variables):
    product = UsdRender.Product.Define(stage, f"/Render/Products/{name}")
    product.CreateProductNameAttr(str(file_name))
    product.CreateOrderedVarsRel().SetTargets([v.GetPath() for v in variables])
    return product


@pytest.fixture
def two_products(tmp_path):
    """A lit card and an analytic eye, two cameras; render settings with two products ordering five vars the
    renderer can write, a primvar var and an LPE it cannot."""
    path = tmp_path / "shot.usda"
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageMetersPerUnit(stage, 0.001)
    for name, z in (("main_cam", 40), ("far_cam", 80)):
        cam = UsdGeom.Camera.Define(stage, f"/World/{name}")
        cam.CreateFocalLengthAttr(50.0)
        cam.CreateHorizontalApertureAttr(24.0)
        cam.CreateVerticalApertureAttr(12.0)
        cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, z))
    UsdGeom.Xform.Define(stage, "/World/Eye").GetPrim().AddAppliedSchema("EyeAPI")
    light = UsdLux.SphereLight.Define(stage, "/World/key")
    light.CreateIntensityAttr(2000.0)
    light.AddTranslateOp().Set(Gf.Vec3d(10, 10, 30))
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-30, -30, -20), (30, -30, -20), (30, 30, -20), (-30, 30, -20)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    beauty = define_var(stage, "beauty", "C.*", "color4f", "lpe")
    depth = define_var(stage, "depth", "depth", "float")
    normal = define_var(stage, "N", "normal", "normal3f")
    albedo = define_var(stage, "albedo", "albedo", "color3h")
    iris = define_var(stage, "iris", "irisMnee", "color3f")
    st = define_var(stage, "st", "st", "float2", "primvar")
    diffuse = define_var(stage, "diffuse", "C<RD>.*", "color3f", "lpe")
    main_product = define_product(stage, "main", tmp_path / "main.exr", [beauty, depth, normal])
    aovs = define_product(stage, "aovs", tmp_path / "aovs.exr", [albedo, st, iris, diffuse])
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    settings.CreateResolutionAttr(Gf.Vec2i(16, 8))
    settings.CreateCameraRel().SetTargets(["/World/main_cam"])
    settings.CreateProductsRel().SetTargets([main_product.GetPath(), aovs.GetPath()])
    stage.SetMetadata("renderSettingsPrimPath", "/Render/Settings")
    stage.GetRootLayer().Save()
    return path


def run(*args):
    return main([str(a) for a in args])


def channel_types(path):
    """{part name: {channel: numpy dtype}} of an EXR (the part name None in a single-part file)."""
    return {part.name(): {name: c.pixels.dtype for name, c in part.channels.items()}
            for part in OpenEXR.File(str(path), separate_channels=True).parts}


def warnings_of(text):
    return [line for line in text.splitlines() if line.startswith("eyerecord: warning:")]


def test_two_products_and_five_vars_render_two_files_with_exactly_those_channels(two_products, tmp_path, capsys):
    assert run(two_products, "--spp", 1, "-q") == 0
    main_file, aovs_file = tmp_path / "main.exr", tmp_path / "aovs.exr"
    assert set(eyerender.read_exr(str(main_file))) == {"R", "G", "B", "A", "depth", "N.X", "N.Y", "N.Z"}
    assert set(eyerender.read_exr(str(aovs_file))) == {"albedo.R", "albedo.G", "albedo.B",
                                                       "iris.R", "iris.G", "iris.B"}
    captured = capsys.readouterr()
    out, warnings = captured.out, warnings_of(captured.err)
    # Each var the renderer cannot produce: one warning naming it, and no channel.
    assert len(warnings) == 2, warnings
    assert "/Render/Vars/st" in warnings[0] and "primvar" in warnings[0]
    assert "/Render/Vars/diffuse" in warnings[1] and "LPE 'C<RD>.*'" in warnings[1]
    assert "-> " + str(main_file) in out.splitlines()[-1] and "(2 files)" in out.splitlines()[-1]
    image = eyerender.read_exr(str(main_file))
    assert image["R"].shape == (8, 16) and image["R"].max() > 0 and image["depth"].max() > 0


def test_product_channels_are_half_or_float_as_the_var_data_type_says(two_products, tmp_path):
    assert run(two_products, "--spp", 1, "-q") == 0
    types = channel_types(tmp_path / "aovs.exr")
    (part,) = types.values()
    assert {part[c] for c in ("albedo.R", "albedo.G", "albedo.B")} == {np.dtype(np.float16)}
    assert {part[c] for c in ("iris.R", "iris.G", "iris.B")} == {np.dtype(np.float32)}
    assert run(two_products, tmp_path / "cli.exr", "--spp", 1, "-q", "--aov", "albedo") == 0
    half = eyerender.read_exr(str(tmp_path / "aovs.exr"))["albedo.G"]
    full = eyerender.read_exr(str(tmp_path / "cli.exr"))["albedo.G"]
    assert full.max() > 0.1
    np.testing.assert_array_equal(half, full.astype(np.float16).astype(np.float32))  # rounded to half, no more


def test_the_exr_writer_keeps_half_parts_apart_clamps_them_and_checks_its_windows(tmp_path):
    from eyerender._hdeye import write_exr_parts

    ramp = np.linspace(-1e6, 1e6, 12, dtype=np.float32).reshape(3, 4)
    parts = [(f"p{k}", [(f"c{k}", ramp * (k + 1), "half"), (f"f{k}", ramp, "float")]) for k in range(3)]
    path = str(tmp_path / "parts.exr")
    write_exr_parts(path, 6, 5, parts, [("note", "x")], (1, 2, 4, 4))
    read = OpenEXR.File(path, separate_channels=True).parts
    assert [p.name() for p in read] == ["p0", "p1", "p2"] and all(p.header["note"] == "x" for p in read)
    for k, part in enumerate(read):
        expected = np.clip(ramp * (k + 1), -65504, 65504).astype(np.float16)
        np.testing.assert_array_equal(part.channels[f"c{k}"].pixels, expected)
        np.testing.assert_array_equal(part.channels[f"f{k}"].pixels, ramp)
    for x0, y0, x1, y1 in ((0, 0, 6, 2), (-1, 0, 2, 2)):
        plane = np.zeros((y1 - y0 + 1, x1 - x0 + 1), np.float32)
        with pytest.raises(RuntimeError, match="outside the 6x5 display window"):
            write_exr_parts(path, 6, 5, [("a", [("c", plane, "float")])], [], (x0, y0, x1, y1))
    with pytest.raises(RuntimeError, match="needs a name of its own"):
        write_exr_parts(path, 4, 3, [("", [("c", ramp, "half")]), ("", [("d", ramp, "half")])])


def test_the_beauty_var_holds_the_pixels_the_command_line_render_writes(two_products, tmp_path):
    assert run(two_products, "--spp", 2, "-q") == 0
    assert run(two_products, tmp_path / "cli.exr", "--spp", 2, "-q", "--aov", "depth") == 0
    product, cli = eyerender.read_exr(str(tmp_path / "main.exr")), eyerender.read_exr(str(tmp_path / "cli.exr"))
    for channel in ("R", "G", "B", "A"):
        np.testing.assert_array_equal(product[channel], cli[channel])
    np.testing.assert_array_equal(product["depth"], cli["depth.Z"])


def test_every_aov_of_the_registry_is_a_render_var_source_with_the_command_lines_pixels(two_products, tmp_path):
    """The eye AOVs (and every other AOV eyerecord's --aov knows) are render var sources: a product ordering them
    holds exactly the channels and pixels `--aov` writes (they were refused as unsupported once)."""
    stage = Usd.Stage.Open(str(two_products))
    eye_vars = [define_var(stage, name, name, "color3f") for name in EYE_PART_AOVS]
    UsdRender.Product(stage.GetPrimAtPath("/Render/Products/aovs")).GetOrderedVarsRel().SetTargets(
        [v.GetPath() for v in eye_vars])
    stage.GetRootLayer().Save()
    assert run(two_products, "--spp", 2, "-q") == 0
    flags = [f for name in EYE_PART_AOVS for f in ("--aov", name)]
    assert run(two_products, tmp_path / "cli.exr", "--spp", 2, "-q", *flags) == 0
    product, cli = eyerender.read_exr(str(tmp_path / "aovs.exr")), eyerender.read_exr(str(tmp_path / "cli.exr"))
    assert set(product) == {channel for name in EYE_PART_AOVS for channel in AOV_CHANNELS[name]}
    for channel in product:
        np.testing.assert_array_equal(product[channel], cli[channel])
    assert max(product[f"{name}.R"].max() for name in EYE_PART_AOVS if name != "nonEye") > 0  # the eye is in view


def test_multi_part_product_has_one_part_per_var(two_products, tmp_path):
    stage = Usd.Stage.Open(str(two_products))
    prim = stage.GetPrimAtPath("/Render/Products/main")
    prim.CreateAttribute("eyerender:multiPart", Sdf.ValueTypeNames.Bool).Set(True)
    stage.GetRootLayer().Save()
    assert run(two_products, "--spp", 1, "-q") == 0
    parts = channel_types(tmp_path / "main.exr")
    assert list(parts) == ["beauty", "depth", "N"]
    assert set(parts["beauty"]) == {"R", "G", "B", "A"} and set(parts["depth"]) == {"depth"}
    assert set(parts["N"]) == {"N.X", "N.Y", "N.Z"}
    header = OpenEXR.File(str(tmp_path / "main.exr")).parts[1].header
    assert header["eyerender:renderProduct"] == "/Render/Products/main"
    assert header["eyerender:renderSettings"] == "/Render/Settings" and "eyerender:plan" in header


def test_per_product_camera_resolution_and_data_window(two_products, tmp_path):
    stage = Usd.Stage.Open(str(two_products))
    aovs = UsdRender.Product(stage.GetPrimAtPath("/Render/Products/aovs"))
    aovs.CreateResolutionAttr(Gf.Vec2i(10, 5))
    aovs.CreateCameraRel().SetTargets(["/World/far_cam"])
    main_product = UsdRender.Product(stage.GetPrimAtPath("/Render/Products/main"))
    main_product.CreateDataWindowNDCAttr(Gf.Vec4f(0.25, 0.5, 0.75, 1.0))  # the top middle of the image
    stage.GetRootLayer().Save()
    assert run(two_products, "--spp", 1, "-q") == 0
    assert eyerender.read_exr(str(tmp_path / "aovs.exr"))["iris.R"].shape == (5, 10)
    header = OpenEXR.File(str(tmp_path / "main.exr")).parts[0].header
    assert [list(v) for v in header["dataWindow"]] == [[4, 0], [11, 3]]
    assert [list(v) for v in header["displayWindow"]] == [[0, 0], [15, 7]]
    assert run(two_products, tmp_path / "full.exr", "--spp", 1, "-q") == 0  # the same render, uncropped
    cropped, full = eyerender.read_exr(str(tmp_path / "main.exr")), eyerender.read_exr(str(tmp_path / "full.exr"))
    np.testing.assert_array_equal(cropped["R"], full["R"][0:4, 4:12])


def test_flags_override_the_products_size_and_camera(two_products, tmp_path):
    stage = Usd.Stage.Open(str(two_products))
    UsdRender.Product(stage.GetPrimAtPath("/Render/Products/aovs")).CreateResolutionAttr(Gf.Vec2i(10, 5))
    stage.GetRootLayer().Save()
    assert run(two_products, "-w", 12, "--spp", 1, "-q") == 0
    for name in ("main.exr", "aovs.exr"):  # -w wins, the height follows the camera's 2:1 aperture
        assert next(iter(eyerender.read_exr(str(tmp_path / name)).values())).shape == (6, 12)
    assert run(two_products, "-cam", "far_cam", "--spp", 1, "-q") == 0
    far = eyerender.read_exr(str(tmp_path / "main.exr"))["depth"]
    assert run(two_products, "--spp", 1, "-q") == 0
    near = eyerender.read_exr(str(tmp_path / "main.exr"))["depth"]
    assert far.max() > near.max() + 30  # the far camera is 40 mm further back


def test_frame_placeholders_in_product_names(two_products, tmp_path):
    stage = Usd.Stage.Open(str(two_products))
    UsdRender.Product(stage.GetPrimAtPath("/Render/Products/main")).GetProductNameAttr().Set(
        str(tmp_path / "main.$F4.exr"))
    UsdRender.Product(stage.GetPrimAtPath("/Render/Products/aovs")).GetProductNameAttr().Set(
        str(tmp_path / "aovs.##.exr"))
    stage.GetRootLayer().Save()
    assert run(two_products, "-f", "1:2", "-w", 8, "--spp", 1, "-q") == 0
    names = sorted(p.name for p in tmp_path.glob("*.exr"))
    assert names == ["aovs.01.exr", "aovs.02.exr", "main.0001.exr", "main.0002.exr"]


def test_an_output_path_writes_that_file_and_notes_the_products_left_unwritten(two_products, tmp_path, capsys):
    assert run(two_products, tmp_path / "one.exr", "--spp", 1, "-q") == 0
    assert not (tmp_path / "main.exr").exists() and (tmp_path / "one.exr").exists()
    assert "2 product(s) not written" in capsys.readouterr().out


def test_without_products_or_an_output_path_is_one_error_line(two_products, tmp_path, capsys):
    stage = Usd.Stage.Open(str(two_products))
    stage.SetMetadata("renderSettingsPrimPath", "")
    stage.GetRootLayer().Save()
    assert run(two_products, "--spp", 1, "-q") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no outputImagePath and no render settings prim" in err[0]
    assert run(two_products, "--spp", 1, "-q", "-rs", "/Render/Settings", "--aov", "depth") == 1
    assert "--aov needs an outputImagePath" in capsys.readouterr().err


def test_included_purposes_of_the_render_settings_and_the_purposes_flag_over_them(two_products, tmp_path):
    stage = Usd.Stage.Open(str(two_products))
    blocker = UsdGeom.Mesh.Define(stage, "/World/blocker")  # a render-purpose card in front of everything
    blocker.CreatePointsAttr([(-30, -30, 10), (30, -30, 10), (30, 30, 10), (-30, 30, 10)])
    blocker.CreateFaceVertexCountsAttr([4])
    blocker.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    blocker.CreatePurposeAttr("render")
    stage.GetRootLayer().Save()

    def depth_max(*flags):
        assert run(two_products, "--spp", 1, "-q", *flags) == 0
        return float(eyerender.read_exr(str(tmp_path / "main.exr"))["depth"].max())

    assert depth_max() > 50  # proxy, usdrecord's default: the card at z = -20 is seen
    settings = UsdRender.Settings(stage.GetPrimAtPath("/Render/Settings"))
    settings.CreateIncludedPurposesAttr(["default", "render"])
    stage.GetRootLayer().Save()
    assert 30 <= depth_max() < 33  # the blocker, 30 mm in front of the camera (a ray's length, 31 at the corners)
    assert depth_max("--purposes", "proxy") > 50
