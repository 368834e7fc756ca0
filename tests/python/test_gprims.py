"""Implicit gprims tessellated for the delegate (gprims.py): every shape and axis closed where it should be, wound
outward, inside USD's own extent, shaded as its surface is (smooth where round, flat where edged), and rendered."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Usd, UsdGeom  # noqa: E402

from eyerender import RenderSession  # noqa: E402
from eyerender.gprims import tessellate_gprim  # noqa: E402

SHAPES = {  # type: attributes authored (others keep their schema fallbacks)
    "Sphere": {"radius": 1.5},
    "Cube": {"size": 3.0},
    "Plane": {"width": 3.0, "length": 1.0},
    "Cylinder": {"radius": 0.5, "height": 3.0},
    "Cone": {"radius": 1.0, "height": 2.0},
    "Capsule": {"radius": 0.5, "height": 2.0},
    "Cylinder_1": {"radiusBottom": 1.0, "radiusTop": 0.25, "height": 2.0},
    "Capsule_1": {"radiusBottom": 1.0, "radiusTop": 0.5, "height": 2.0},
}
AXES = ("X", "Y", "Z")


def gprim(kind, axis="Z", **values):
    stage = Usd.Stage.CreateInMemory()
    prim = stage.DefinePrim("/shape", kind)
    for name, value in {**SHAPES[kind], **values}.items():
        prim.GetAttribute(name).Set(value)
    if prim.HasAttribute("axis"):
        prim.GetAttribute("axis").Set(axis)
    return stage, prim


def face_normals_and_centroids(counts, indices, points):
    """Newell normals (area-weighted, unnormalised) and centroids per face."""
    normals, centroids, start = [], [], 0
    for n in counts:
        face = points[indices[start:start + n]].astype(np.float64)
        start += n
        nxt = np.roll(face, -1, axis=0)
        normals.append(np.cross(face, nxt).sum(axis=0) / 2)
        centroids.append(face.mean(axis=0))
    return np.array(normals), np.array(centroids)


@pytest.mark.parametrize("axis", AXES)
@pytest.mark.parametrize("kind", SHAPES)
def test_each_shape_is_wound_outward_inside_usds_extent_and_closed_unless_a_plane(kind, axis):
    stage, prim = gprim(kind, axis)
    counts, indices, points = tessellate_gprim(prim, Usd.TimeCode.Default())
    assert counts.sum() == len(indices) and indices.min() >= 0 and indices.max() < len(points)
    extent = np.array(UsdGeom.Boundable.ComputeExtentFromPlugins(UsdGeom.Boundable(prim), Usd.TimeCode.Default()))
    if kind == "Capsule_1":  # usd-core's extent is not this hull's (nor GeomUtil's, which Storm draws): the hull's
        spine = "XYZ".index(axis)
        extent = np.full((2, 3), [[-1.0], [1.0]])
        extent[:, spine] = [-(1.0 + 1.0), 1.0 + 0.5]  # -(height / 2 + radiusBottom), height / 2 + radiusTop
    assert np.all(points.min(axis=0) >= extent[0] - 1e-5) and np.all(points.max(axis=0) <= extent[1] + 1e-5)
    assert np.allclose(points.min(axis=0), extent[0], atol=2e-3) and np.allclose(points.max(axis=0), extent[1],
                                                                                   atol=2e-3), (points.min(0), extent)
    normals, centroids = face_normals_and_centroids(counts, indices, points)
    areas = np.linalg.norm(normals, axis=1)
    assert np.all(areas > 0), "degenerate faces"
    spine = np.eye(3)["XYZ".index(axis)]
    if kind == "Plane":
        assert np.allclose(normals / areas[:, None], spine)  # it faces +axis
        return
    # Outward: each shape is convex around the origin, so every face faces away from it; closed: the normals sum
    # to zero.
    assert np.all(np.einsum("ij,ij->i", normals, centroids) > 0)
    assert np.linalg.norm(normals.sum(axis=0)) < 1e-5 * areas.sum()


def test_a_bad_size_or_axis_is_an_error_naming_the_prim():
    for kind, values, message in (("Cylinder", {"radius": -1.0}, "Cylinder radius -1 must be positive"),
                                  ("Capsule_1", {"height": float("nan")}, "Capsule_1 height nan must be non-negative"),
                                  ("Cylinder_1", {"radiusTop": 0.0, "radiusBottom": 0.0}, "are both 0"),
                                  ("Cone", {"axis": "W"}, "Cone axis 'W' must be X, Y or Z")):
        stage, prim = gprim(kind)
        for name, value in values.items():
            prim.GetAttribute(name).Set(value)
        with pytest.raises(eyerender.EyeRenderError, match=f"/shape: .*{message}"):
            tessellate_gprim(prim, Usd.TimeCode.Default())


def stage_with(kind, axis="Z"):
    stage = Usd.Stage.CreateInMemory()
    cam = UsdGeom.Camera.Define(stage, "/cam")
    cam.AddTranslateOp().Set(Gf.Vec3d(6, 5, 7))  # looking at the origin from a corner
    cam.AddRotateXYZOp().Set(Gf.Vec3f(-30, 40, 0))
    prim = stage.DefinePrim("/World/shape", kind)
    for name, value in SHAPES[kind].items():
        prim.GetAttribute(name).Set(value)
    if prim.HasAttribute("axis"):
        prim.GetAttribute("axis").Set(axis)
    return stage


def rendered_normals(stage):
    s = RenderSession(stage, width=48, height=48, aovs=["normal", "color"])
    s.render(spp=1)
    alpha = s.image("color")[..., 3]
    return s.image("normal")[..., :3][alpha > 0.999], s


def test_a_cube_shades_flat_and_a_cylinder_smooth_on_its_side_with_flat_caps():
    normals, s = rendered_normals(stage_with("Cube"))
    assert not s.scene.warnings
    assert len(normals) > 200
    # Three faces in view, each one normal: every covered pixel's normal is within 1e-3 of one of three.
    distinct = np.unique(np.round(normals, 2), axis=0)
    assert len(distinct) == 3, distinct
    normals, s = rendered_normals(stage_with("Cylinder", axis="Y"))
    assert not s.scene.warnings
    caps = np.abs(normals[:, 1]) > 0.999  # the top cap, flat
    side = np.abs(normals[:, 1]) < 1e-3  # the side: radial, a different normal in every column of pixels
    assert caps.sum() > 20 and side.sum() > 100 and (caps | side).all()
    assert len(np.unique(np.round(normals[side], 2), axis=0)) > 10


@pytest.mark.parametrize("kind", [k for k in SHAPES if k not in ("Sphere", "Cube")])
def test_cones_cylinders_capsules_and_planes_render_without_a_warning(kind):
    normals, s = rendered_normals(stage_with(kind, axis="X"))
    assert not s.scene.warnings
    assert len(normals) > 50
