"""Cryptomatte as Psyop's specification lays it out: MurmurHash3 ids with the exponent clamp, ranked id/coverage
channel pairs and the header's manifest; a small decoder here reads a matte back by name, and each prim's (each
instance's) decoded coverage is exactly the alpha of a render of that prim alone."""
import json

import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdRender, UsdShade  # noqa: E402

from eyerender._hdeye import read_exr_attributes  # noqa: E402
from eyerender.cli.eyerecord import main  # noqa: E402
from eyerender.cryptomatte import CoverageTable, id_bits, layer_key, murmurhash3_32  # noqa: E402

SPP, WIDTH = 8, 32


def decode(path, layer, name):
    """The coverage (float32 (h, w)) of `name` in cryptomatte layer `layer` of the EXR at `path`, read as a
    compositor reads it: the layer's key from the header, the name's id from its manifest, then the sum of the
    coverage of every rank whose id is that id."""
    header = read_exr_attributes(str(path))
    (prefix,) = [k[:-len("name")] for k, v in header.items() if k.startswith("cryptomatte/") and k.endswith("/name")
                 and v == layer]
    assert header[prefix + "hash"] == "MurmurHash3_32" and header[prefix + "conversion"] == "uint32_to_float32"
    manifest = json.loads(header[prefix + "manifest"])
    target = np.uint32(int(manifest[name], 16))
    channels = eyerender.read_exr(str(path))
    coverage = np.zeros_like(channels[f"{layer}00.R"])
    for rank in range(6):
        ids = channels[f"{layer}{rank // 2:02d}.{'RB'[rank % 2]}"].view(np.uint32)
        coverage += np.where(ids == target, channels[f"{layer}{rank // 2:02d}.{'GA'[rank % 2]}"], 0)
    return coverage


def test_ids_are_the_specification_s_murmurhash3_with_its_exponent_clamp():
    assert murmurhash3_32(b"") == 0 and murmurhash3_32(b"hello") == 0x248BFA47  # the reference's test vectors
    # The specification's example manifest: "bunny", "default", "bunny_porcelain_mat".
    assert (id_bits("bunny"), id_bits("default"), id_bits("bunny_porcelain_mat")) == \
        (0x13851A76, 0x42C9679F, 0xB24B26D4)
    for name in (f"/World/prim_{k}" for k in range(2000)):  # never a denormal, an infinity or a NaN
        assert 1 <= (id_bits(name) >> 23) & 0xFF <= 254
    assert len(layer_key("CryptoObject")) == 7


def test_coverage_tables_rank_by_coverage_and_merge_exactly():
    one = CoverageTable(1, 1)
    for sample_id in (5, 7, 7, 0, 7, 5, 9, 7):
        one.add(np.full((1, 1), sample_id, np.uint32), np.ones((1, 1)), np.ones((1, 1)))
    first, second = CoverageTable(1, 1), CoverageTable(1, 1)
    for table, ids in ((first, (5, 7, 7, 0)), (second, (7, 5, 9, 7))):
        for sample_id in ids:
            table.add(np.full((1, 1), sample_id, np.uint32), np.ones((1, 1)), np.ones((1, 1)))
    first.merge(second)
    for table in (one, first):
        encoded = table.encode()[0, 0]
        assert list(encoded[0::2].view(np.uint32)) == [7, 5, 9, 0, 0, 0]
        assert list(encoded[1::2]) == [0.5, 0.25, 0.125, 0, 0, 0]  # of 8 samples, one of them a miss


def quad(stage, path, x, y, size=4.0, z=0.0):
    mesh = UsdGeom.Mesh.Define(stage, path)
    h = size / 2
    mesh.CreatePointsAttr([(x - h, y - h, z), (x + h, y - h, z), (x + h, y + h, z), (x - h, y + h, z)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    mesh.CreateSubdivisionSchemeAttr("none")
    return mesh


@pytest.fixture
def crowd(tmp_path):
    """Two cards of one material in a component model, two native instances of a prototype card and a
    PointInstancer's two chips, side by side before a camera, and a render product of the three layers."""
    path = tmp_path / "crowd.usda"
    stage = Usd.Stage.CreateNew(str(path))
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(2)
    camera = UsdGeom.Camera.Define(stage, "/World/main_cam")
    camera.CreateFocalLengthAttr(35.0)
    camera.CreateHorizontalApertureAttr(36.0)
    camera.CreateVerticalApertureAttr(18.0)
    camera.AddTranslateOp().Set(Gf.Vec3d(0, 0, 30))
    props = UsdGeom.Xform.Define(stage, "/World/Props")
    Usd.ModelAPI(props.GetPrim()).SetKind(Kind.Tokens.component)
    shared = UsdShade.Material.Define(stage, "/World/Looks/shared")
    for name, x in (("cardL", -12.0), ("cardR", -6.0)):
        card = quad(stage, f"/World/Props/{name}", x, 3)
        UsdShade.MaterialBindingAPI.Apply(card.GetPrim()).Bind(shared)
    card_r = stage.GetPrimAtPath("/World/Props/cardR")
    card_r.GetAttribute("points").Set([(-8, 1, 0), (-4, 1, 0), (-4, 5, 0), (-8, 5, 0)], 1)
    card_r.GetAttribute("points").Set([(-8, 0, 0), (-4, 0, 0), (-4, 4, 0), (-8, 4, 0)], 2)  # moves down
    prototype = UsdGeom.Xform.Define(stage, "/Prototypes/Tile")
    quad(stage, "/Prototypes/Tile/geo", 0, 0)
    stage.GetPrimAtPath("/Prototypes").SetSpecifier(Sdf.SpecifierClass)
    for name, x in (("tileA", 0.0), ("tileB", 6.0)):
        tile = UsdGeom.Xform.Define(stage, f"/World/{name}")
        tile.AddTranslateOp().Set(Gf.Vec3d(x, 3, 0))
        tile.GetPrim().GetReferences().AddInternalReference(prototype.GetPath())
        tile.GetPrim().SetInstanceable(True)
    instancer = UsdGeom.PointInstancer.Define(stage, "/World/chips")
    quad(stage, "/World/chips/Protos/chip", 0, 0, size=3.0)
    instancer.CreatePrototypesRel().SetTargets(["/World/chips/Protos/chip"])
    instancer.CreateProtoIndicesAttr([0, 0])
    instancer.CreatePositionsAttr([(-4, -5, 0), (4, -5, 0)])
    instancer.CreateIdsAttr([10, 11])
    variables = []
    for layer in ("CryptoObject", "CryptoMaterial", "CryptoAsset"):
        var = UsdRender.Var.Define(stage, f"/Render/Vars/{layer}")
        var.CreateSourceNameAttr(layer)
        variables.append(var.GetPath())
    product = UsdRender.Product.Define(stage, "/Render/Products/mattes")
    product.CreateProductNameAttr(str(tmp_path / "mattes.#.exr"))
    product.CreateOrderedVarsRel().SetTargets(variables)
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    settings.CreateResolutionAttr(Gf.Vec2i(WIDTH, WIDTH // 2))
    settings.CreateProductsRel().SetTargets([product.GetPath()])
    stage.SetMetadata("renderSettingsPrimPath", "/Render/Settings")
    stage.GetRootLayer().Save()
    return path


OBJECTS = {  # object name -> the prim to keep visible alone for its reference alpha
    "/World/Props/cardL": "/World/Props/cardL",
    "/World/Props/cardR": "/World/Props/cardR",
    "/World/tileA/geo": "/World/tileA",
    "/World/tileB/geo": "/World/tileB",
    "/World/chips[10]/chip": None,  # the instancer's instance 0 (id 10): invisibleIds hides the other
    "/World/chips[11]/chip": None,
}


def alone_alpha(stage_path, tmp_path, name, keep):
    """The beauty's alpha of a render where only `name` is visible (the same samples: the image is a pure
    function of the seed, pixel and sample index)."""
    stage = Usd.Stage.Open(str(stage_path))
    for prim in ("/World/Props/cardL", "/World/Props/cardR", "/World/tileA", "/World/tileB"):
        if prim != keep:
            UsdGeom.Imageable(stage.GetPrimAtPath(prim)).MakeInvisible()
    # invisibleIds, not the instancer's visibility: the scene delegate renders an invisible PointInstancer's
    # instances (a bug of its own, outside cryptomatte).
    hidden = [10, 11] if keep is not None else [11 if name.endswith("[10]/chip") else 10]
    UsdGeom.PointInstancer(stage.GetPrimAtPath("/World/chips")).CreateInvisibleIdsAttr(hidden)
    alone = tmp_path / f"alone_{abs(hash(name))}.usda"
    stage.GetRootLayer().Export(str(alone))
    out = tmp_path / f"alone_{abs(hash(name))}.exr"  # at the start time code, frame 1, as the mattes
    assert main([str(alone), str(out), "--spp", str(SPP), "-q", "--disableCameraLight"]) == 0
    return eyerender.read_exr(str(out))["A"]


def test_a_decoder_recovers_each_prim_s_and_each_instance_s_coverage(crowd, tmp_path):
    assert main([str(crowd), "-f", "1", "--spp", str(SPP), "-q", "--disableCameraLight"]) == 0
    mattes = tmp_path / "mattes.1.exr"
    channels = eyerender.read_exr(str(mattes))
    assert set(channels) == {f"{layer}{n:02d}.{c}" for layer in ("CryptoObject", "CryptoMaterial", "CryptoAsset")
                             for n in range(3) for c in "RGBA"}
    total = np.zeros_like(channels["CryptoObject00.G"])
    for name, keep in OBJECTS.items():
        coverage = decode(mattes, "CryptoObject", name)
        expected = alone_alpha(crowd, tmp_path, name, keep)
        assert expected.sum() > 4, name  # on screen
        np.testing.assert_array_equal(coverage, expected, err_msg=name)
        total += coverage
    assert total.max() <= 1 + 1e-6 and (total > 0).sum() > 60
    cards = decode(mattes, "CryptoObject", "/World/Props/cardL") + decode(mattes, "CryptoObject", "/World/Props/cardR")
    np.testing.assert_allclose(decode(mattes, "CryptoMaterial", "/World/Looks/shared"), cards, atol=1e-6)
    np.testing.assert_allclose(decode(mattes, "CryptoAsset", "/World/Props"), cards, atol=1e-6)  # the component


def test_ids_are_stable_across_frames_and_follow_what_moves(crowd, tmp_path):
    assert main([str(crowd), "-f", "1:2", "--spp", "2", "-q", "--disableCameraLight"]) == 0
    frames = [tmp_path / f"mattes.{f}.exr" for f in (1, 2)]
    manifests = [json.loads(read_exr_attributes(str(f))[
        f"cryptomatte/{layer_key('CryptoObject')}/manifest"]) for f in frames]
    assert manifests[0] == manifests[1] and manifests[0]["/World/Props/cardR"] == f"{id_bits('/World/Props/cardR'):08x}"
    moved = [decode(f, "CryptoObject", "/World/Props/cardR") for f in frames]
    centre = [float((m.sum(axis=1) * np.arange(m.shape[0])).sum() / m.sum()) for m in moved]
    assert centre[1] > centre[0] + 0.5, centre  # rows go down the image: the card moved down
    still = [decode(f, "CryptoObject", "/World/tileA/geo") for f in frames]
    np.testing.assert_array_equal(still[0] > 0, still[1] > 0)


def test_aov_flag_writes_a_cryptomatte_layer_beside_the_beauty(crowd, tmp_path):
    out = tmp_path / "beauty.exr"
    assert main([str(crowd), str(out), "--spp", "2", "-q", "--aov", "CryptoObject"]) == 0
    channels = eyerender.read_exr(str(out))
    assert {"R", "CryptoObject00.R", "CryptoObject02.A"} <= set(channels)
    assert decode(out, "CryptoObject", "/World/tileB/geo").max() == 1.0
