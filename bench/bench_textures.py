"""Texture filtering: what the ray-cone footprint buys and costs. A tilted ground plane under a dome, its diffuse
colour a fine 2048^2 checker-and-noise texture (written here), seen from a perspective camera so that texel density
per pixel grows with distance; rendered point sampled (filtering off) and filtered (MIP-mapped, anisotropic, the ray
cone of delegate/hdeye/rayCone.h) with the camera cone 1, 0.5 and 0.25 pixels wide (RenderSettings::
textureFootprintScale), at 1 to 64 samples per pixel. Prints each one's relative RMSE against the converged
point-sampled image (the pixel integral of the texture itself), the bias a filtered image converges to, and the
median render time at 16 spp relative to point sampling.

    PYTHONPATH=python python3 bench/bench_textures.py [--width 96] [--repeats 3]
"""
import argparse
import os
import pathlib
import statistics
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parents[1]
os.environ.setdefault("PXR_PLUGINPATH_NAME", str(REPO / "schemas"))


def make_stage(directory):
    import numpy as np
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade

    from eyerender._hdeye import write_image

    n = 2048
    y, x = np.mgrid[0:n, 0:n]
    checker = ((x // 4 + y // 4) % 2).astype(np.float32)
    noise = np.random.default_rng(3).random((n, n), np.float32)
    image = np.stack([0.2 + 0.6 * checker, 0.2 + 0.3 * noise, 0.5 * checker * noise], axis=2).astype(np.float32)
    write_image(str(directory / "ground.png"), np.ascontiguousarray(image))

    stage = Usd.Stage.CreateNew(str(directory / "ground.usda"))
    cam = UsdGeom.Camera.Define(stage, "/World/main_cam")
    cam.CreateFocalLengthAttr(35.0)
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 1.5, 4))
    cam.AddRotateXOp().Set(-20.0)
    ground = UsdGeom.Mesh.Define(stage, "/World/ground")
    ground.CreatePointsAttr([(-10, 0, -30), (10, 0, -30), (10, 0, 5), (-10, 0, 5)])
    ground.CreateFaceVertexCountsAttr([4])
    ground.CreateFaceVertexIndicesAttr([0, 3, 2, 1])
    ground.CreateSubdivisionSchemeAttr("none")
    st = UsdGeom.PrimvarsAPI(ground).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
    st.Set([(0, 1), (1, 1), (1, 0), (0, 0)])
    material = UsdShade.Material.Define(stage, "/World/Looks/ground")
    surface = UsdShade.Shader.Define(stage, "/World/Looks/ground/surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.8)
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    texture = UsdShade.Shader.Define(stage, "/World/Looks/ground/texture")
    texture.CreateIdAttr("UsdUVTexture")
    texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("ground.png")
    for name in ("wrapS", "wrapT"):
        texture.CreateInput(name, Sdf.ValueTypeNames.Token).Set("repeat")
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
        texture.CreateOutput("rgb", Sdf.ValueTypeNames.Float3))
    UsdShade.MaterialBindingAPI.Apply(ground.GetPrim()).Bind(material)
    UsdLux.DomeLight.Define(stage, "/World/sky")
    sun = UsdLux.DistantLight.Define(stage, "/World/sun")
    sun.CreateIntensityAttr(2.0)
    sun.AddRotateXOp().Set(-50.0)
    stage.GetRootLayer().Save()
    return stage


def render(stage, width, spp, filtering, first_sample=0, scale=1.0):
    from eyerender import RenderSession

    session = RenderSession(stage, width=width, settings={"texture_filtering": filtering, "threads": 2,
                                                          "texture_footprint_scale": scale})
    session.render(spp=1)  # opens and MIP-maps the texture: not part of the timing
    start = time.perf_counter()
    session.render(spp=spp, first_sample=first_sample)
    return time.perf_counter() - start, session.image("color")[:, :, :3].copy()


def relative_rmse(image, reference):
    import numpy as np

    return float(np.sqrt(np.mean((image - reference) ** 2)) / max(1e-12, np.sqrt(np.mean(reference ** 2))))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--width", type=int, default=96)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--reference-spp", type=int, default=256)
    args = parser.parse_args(argv)
    import eyerender  # noqa: F401  (the schema plugin, before pxr is used)

    counts = (1, 4, 16, 64)
    with tempfile.TemporaryDirectory() as tmp:
        stage = make_stage(pathlib.Path(tmp))
        # The truth is the pixel integral of the texture itself: point sampled, converged (other sample indices).
        truth = render(stage, args.width, args.reference_spp, False, first_sample=10000)[1]
        print(f"texture filtering, {args.width} px wide, 2 threads; relative RMSE against the point-sampled image at "
              f"{args.reference_spp} spp; bias: the filtered image at {args.reference_spp} spp against it")
        print(f"{'footprint':>10} {'bias':>7} " + " ".join(f"{f'{n} spp':>9}" for n in counts) + f" {'time ratio':>11}")
        rows = [(None, "point")] + [(scale, f"{scale:g} px") for scale in (1.0, 0.5, 0.25)]
        base_seconds = None
        for scale, label in rows:
            filtering = scale is not None
            scale = scale or 1
            converged = render(stage, args.width, args.reference_spp, filtering, first_sample=10000, scale=scale)[1]
            errors = [relative_rmse(render(stage, args.width, n, filtering, scale=scale)[1], truth) for n in counts]
            seconds = statistics.median(render(stage, args.width, 16, filtering, scale=scale)[0]
                                        for _ in range(args.repeats))
            base_seconds = base_seconds or seconds
            bias = f"{relative_rmse(converged, truth):.4f}" if filtering else "-"  # point sampled: the truth itself
            print(f"{label:>10} {bias:>7} " + " ".join(f"{e:>9.4f}" for e in errors) +
                  f" {seconds / base_seconds:>11.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
