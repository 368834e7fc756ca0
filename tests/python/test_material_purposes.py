"""UsdRender's materialBindingPurposes: the material a prim renders with is its binding for the first purpose in the
settings prim's list that binds one ("" the all-purpose binding); without the attribute, "preview" then all-purpose
(Storm's). Checked on a card bound to three emissive materials, one per purpose, through eyerecord."""
import numpy as np
import pytest
from pxr import Gf, Sdf, Usd, UsdGeom, UsdRender, UsdShade

import eyerender
from eyerender.cli.eyerecord import main
from eyerender.materials import bound_material

COLOURS = {"full": (1, 0, 0), "preview": (0, 1, 0), "": (0, 0, 1)}


def emissive(stage, path, colour):
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, f"{path}/surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0, 0, 0))
    shader.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*colour))
    shader.CreateInput("ior", Sdf.ValueTypeNames.Float).Set(1.0)  # no specular: the emission alone
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return material


def card_stage(path, purposes=None):
    stage = Usd.Stage.CreateNew(str(path))
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 10))
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    binding = UsdShade.MaterialBindingAPI.Apply(card.GetPrim())
    for purpose, colour in COLOURS.items():
        material = emissive(stage, f"/World/Looks/{purpose or 'all'}", colour)
        binding.Bind(material, UsdShade.Tokens.fallbackStrength, purpose or UsdShade.Tokens.allPurpose)
    settings = UsdRender.Settings.Define(stage, "/Render/settings")
    settings.CreateResolutionAttr(Gf.Vec2i(8, 8))
    if purposes is not None:
        settings.CreateMaterialBindingPurposesAttr(purposes)
    stage.SetMetadata("renderSettingsPrimPath", "/Render/settings")  # the settings the render reads
    stage.GetRootLayer().Save()
    return stage


@pytest.mark.parametrize("purposes, expected", [
    (None, "preview"), (["full", ""], "full"), (["preview", "full", ""], "preview"), ([""], ""),
    (["unknownPurpose", ""], ""), (["full"], "full"),
])
def test_the_first_purpose_that_binds_a_material_is_rendered(tmp_path, purposes, expected):
    path = tmp_path / "card.usda"
    card_stage(path, purposes)
    out = tmp_path / "card.exr"
    assert main([str(path), str(out), "--spp", "1", "-q"]) == 0
    channels = eyerender.read_exr(str(out))
    rgb = np.array([float(channels[c].mean()) for c in "RGB"])
    assert np.allclose(rgb, COLOURS[expected], atol=1e-3), (purposes, rgb)


def test_a_purpose_list_that_binds_nothing_gives_no_material(tmp_path):
    stage = card_stage(tmp_path / "card.usda")
    card = stage.GetPrimAtPath("/World/card")
    assert not bound_material(card, ("unknownPurpose",))
    assert bound_material(card, ("unknownPurpose", "full")).GetPath() == "/World/Looks/full"
    assert bound_material(card).GetPath() == "/World/Looks/preview"


def test_pixel_aspect_ratio_stretches_the_film_over_the_pixels(tmp_path):
    # A card's edge seen through 2:1 pixels: each pixel of the 16-wide image covers what two of the 32-wide image with
    # square pixels cover, so its alpha is their mean (to the samples' noise).
    def render(width, aspect):
        path = tmp_path / f"edge_{width}.usda"
        stage = card_stage(path)
        card = UsdGeom.Xformable(stage.GetPrimAtPath("/World/card"))
        card.AddTranslateOp().Set(Gf.Vec3d(50.37, 0, 0))  # its left edge just right of the view's centre
        settings = UsdRender.Settings(stage.GetPrimAtPath("/Render/settings"))
        settings.GetResolutionAttr().Set(Gf.Vec2i(width, 8))
        if aspect != 1:
            settings.CreatePixelAspectRatioAttr(aspect)
        stage.GetRootLayer().Save()
        out = tmp_path / f"edge_{width}.exr"
        assert main([str(path), str(out), "--spp", "64", "-q"]) == 0
        return eyerender.read_exr(str(out))["A"].astype(np.float64)

    square, wide = render(32, 1.0), render(16, 2.0)
    assert wide.shape == (8, 16)
    paired = 0.5 * (square[:, 0::2] + square[:, 1::2])
    assert 0.2 < wide.mean() < 0.8  # the edge is in view
    assert np.abs(wide - paired).max() < 0.05, np.abs(wide - paired).max()
