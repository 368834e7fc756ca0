"""Subdivision tags, schemes and holes (mesh_topology.Subdivision) and materialBind GeomSubsets through the USD scene
delegate: the rendered (limit) points of small authored meshes, triangle counts, the albedo per face, warnings."""
import numpy as np
import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Gf, Usd, UsdGeom, UsdLux, UsdShade  # noqa: E402

from eyerender import RenderSession  # noqa: E402
from shading_stages import preview_material  # noqa: E402

CUBE_POINTS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
# Faces counter-clockwise seen from outside: -z, +z, -y, +y, -x, +x.
CUBE_FACES = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (0, 4, 7, 3), (1, 2, 6, 5)]
CUBE_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]


def new_stage():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    camera = UsdGeom.Camera.Define(stage, "/World/main_cam")
    camera.AddTransformOp().Set(Gf.Matrix4d().SetLookAt(Gf.Vec3d(4, 5, 6), Gf.Vec3d(0, 0, 0),
                                                        Gf.Vec3d(0, 1, 0)).GetInverse())
    camera.CreateVerticalApertureAttr(camera.GetHorizontalApertureAttr().Get())  # square, as the test images
    UsdLux.DomeLight.Define(stage, "/World/dome")
    return stage


def cube(stage, path="/World/cube", scheme="catmullClark"):
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(CUBE_POINTS)
    mesh.CreateFaceVertexCountsAttr([4] * 6)
    mesh.CreateFaceVertexIndicesAttr([i for f in CUBE_FACES for i in f])
    mesh.CreateSubdivisionSchemeAttr(scheme)
    return mesh


def crease_all_edges(mesh, sharpness):
    """Every cube edge as its own two-vertex crease; `sharpness` one value (per crease) or a list (per edge)."""
    mesh.CreateCreaseIndicesAttr([i for e in CUBE_EDGES for i in e])
    mesh.CreateCreaseLengthsAttr([2] * len(CUBE_EDGES))
    values = sharpness if isinstance(sharpness, list) else [sharpness] * len(CUBE_EDGES)
    mesh.CreateCreaseSharpnessesAttr(values)


def synced(stage, refine_level=3):
    s = RenderSession(stage, width=16, height=16, refine_level=refine_level)
    s.index.sync_all()
    return s


def limit_points(stage, path="/World/cube", refine_level=3):
    return np.asarray(synced(stage, refine_level).index.mesh_points(path), dtype=np.float64)


def edge_midpoint_gap(points):
    """Distance from the cube edge y = z = -1 of the limit point over its middle (x = 0, y = z, furthest out)."""
    on = points[(np.abs(points[:, 0]) < 1e-5) & (np.abs(points[:, 1] - points[:, 2]) < 1e-5) & (points[:, 1] < 0)]
    return float(np.min(np.hypot(on[:, 1] + 1, on[:, 2] + 1)))


def test_infinitely_creased_cube_stays_on_its_faces_and_edges():
    stage = new_stage()
    crease_all_edges(cube(stage), 10.0)
    points = limit_points(stage)
    off_surface = np.abs(np.abs(points).max(axis=1) - 1).max()
    assert off_surface < 1e-5, f"a limit point lies {off_surface} off the cube"
    assert edge_midpoint_gap(points) < 1e-5


def test_crease_sharpness_makes_edges_sharper_than_uncreased_per_crease_and_per_edge():
    gaps = {}
    for name, sharpness in (("smooth", None), ("2 per crease", 2.0), ("2 per edge", [2.0] * 12), ("10", 10.0)):
        stage = new_stage()
        mesh = cube(stage)
        if sharpness is not None:
            crease_all_edges(mesh, sharpness)
        gaps[name] = edge_midpoint_gap(limit_points(stage))
    assert gaps["smooth"] > 0.3, gaps
    assert gaps["2 per crease"] < 0.5 * gaps["smooth"], gaps
    assert gaps["2 per edge"] == pytest.approx(gaps["2 per crease"], abs=1e-6), gaps
    assert gaps["10"] < 1e-5, gaps


def test_sharp_corner_keeps_its_control_point():
    stage = new_stage()
    mesh = cube(stage)
    nearest = np.linalg.norm(limit_points(stage) - (1, 1, 1), axis=1).min()
    mesh.CreateCornerIndicesAttr([6])
    mesh.CreateCornerSharpnessesAttr([10.0])
    nearest_tagged = np.linalg.norm(limit_points(stage) - (1, 1, 1), axis=1).min()
    assert nearest > 0.5 and nearest_tagged < 1e-5, (nearest, nearest_tagged)


@pytest.mark.parametrize("scheme, level, triangles", [("catmullClark", 2, 5 * 16 * 2), ("none", 0, 5 * 2)])
def test_hole_faces_are_not_rendered(scheme, level, triangles):
    stage = new_stage()
    cube(stage, scheme=scheme).CreateHoleIndicesAttr([1])
    stats = synced(stage, refine_level=2).index.mesh_stats("/World/cube")
    assert stats["triangles"] == triangles and stats["refine_level"] == level


def grid(stage, n=3):
    mesh = UsdGeom.Mesh.Define(stage, "/World/grid")
    mesh.CreatePointsAttr([(i, j, 0) for j in range(n + 1) for i in range(n + 1)])
    mesh.CreateFaceVertexCountsAttr([4] * n * n)
    mesh.CreateFaceVertexIndicesAttr([k for j in range(n) for i in range(n) for k in
                                      (j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
                                       (j + 1) * (n + 1) + i)])
    return mesh


def test_interpolate_boundary_none_drops_boundary_faces_edge_and_corner_pins_corners():
    stage = new_stage()
    mesh = grid(stage)
    s = synced(stage, refine_level=2)
    corner_gap = np.linalg.norm(np.asarray(s.index.mesh_points("/World/grid")), axis=1).min()
    assert s.index.mesh_stats("/World/grid")["triangles"] == 9 * 16 * 2
    assert corner_gap < 1e-6
    mesh.CreateInterpolateBoundaryAttr(UsdGeom.Tokens.none)
    assert synced(stage, refine_level=2).index.mesh_stats("/World/grid")["triangles"] == 16 * 2
    mesh.GetInterpolateBoundaryAttr().Set(UsdGeom.Tokens.edgeOnly)
    s = synced(stage, refine_level=2)
    assert np.linalg.norm(np.asarray(s.index.mesh_points("/World/grid")), axis=1).min() > 0.1


def test_loop_and_bilinear_schemes_refine_and_loop_on_quads_warns():
    stage = new_stage()
    octahedron = UsdGeom.Mesh.Define(stage, "/World/octahedron")
    octahedron.CreatePointsAttr([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)])
    octahedron.CreateFaceVertexCountsAttr([3] * 8)
    octahedron.CreateFaceVertexIndicesAttr([0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5])
    octahedron.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.loop)
    cube(stage, scheme="bilinear")
    cube(stage, "/World/loop_cube", scheme="loop")
    s = synced(stage, refine_level=2)
    assert s.index.mesh_stats("/World/octahedron")["triangles"] == 8 * 16  # loop: triangles into 4 each level
    bilinear = np.asarray(s.index.mesh_points("/World/cube"))
    assert np.abs(np.abs(bilinear).max(axis=1) - 1).max() < 1e-6  # bilinear keeps the cube's faces flat
    assert s.index.mesh_stats("/World/loop_cube")["triangles"] == 6 * 16 * 2
    assert [w for w in s.scene.warnings if "/World/loop_cube" in w] == [
        "/World/loop_cube: subdivisionScheme 'loop' needs triangles, face 0 has 4 vertices; rendered as catmullClark"]


def test_malformed_tags_are_dropped_with_one_warning_and_the_mesh_renders():
    stage = new_stage()
    mesh = cube(stage)
    mesh.CreateCreaseIndicesAttr([0, 1, 2])
    mesh.CreateCreaseLengthsAttr([2])
    mesh.CreateCreaseSharpnessesAttr([10.0])
    mesh.CreateCornerIndicesAttr([99])
    mesh.CreateCornerSharpnessesAttr([1.0])
    mesh.CreateHoleIndicesAttr([0, 6])
    mesh.CreateInterpolateBoundaryAttr("sometimes")
    s = synced(stage)
    warnings = [w for w in s.scene.warnings if w.startswith("/World/cube")]
    assert warnings == [
        "/World/cube: interpolateBoundary 'sometimes' is not one of none, edgeOnly, edgeAndCorner; using "
        "'edgeAndCorner'",
        "/World/cube: creases ignored: creaseLengths add up to 2, creaseIndices has 3",
        "/World/cube: corners ignored: cornerIndices refer to points outside [0, 8)",
        "/World/cube: holeIndices: 1 outside the 6 faces ignored"], warnings
    assert s.index.mesh_stats("/World/cube")["triangles"] == 5 * 64 * 2  # the valid hole is kept
    assert all(len(w) < 200 for w in warnings)


def test_crease_over_a_missing_edge_is_warned_and_the_rest_applied():
    stage = new_stage()
    mesh = cube(stage)
    mesh.CreateCreaseIndicesAttr([0, 1, 0, 6])  # 0-6 is a diagonal of the cube, no edge
    mesh.CreateCreaseLengthsAttr([2, 2])
    mesh.CreateCreaseSharpnessesAttr([10.0, 10.0])
    s = synced(stage)
    assert "/World/cube: 1 of the 2 crease edges are not edges of the mesh; ignored" in s.scene.warnings
    points = np.asarray(s.index.mesh_points("/World/cube"))
    mesh.GetCreaseIndicesAttr().Set([0, 1])
    mesh.GetCreaseLengthsAttr().Set([2])
    mesh.GetCreaseSharpnessesAttr().Set([10.0])
    only_edge = np.asarray(synced(stage).index.mesh_points("/World/cube"))
    uncreased = np.asarray(synced(cube_stage()).index.mesh_points("/World/cube"))
    assert np.array_equal(points, only_edge)  # the crease along edge 0-1 applied alone
    assert np.abs(points - uncreased).max() > 0.05


def cube_stage():
    stage = new_stage()
    cube(stage)
    return stage


def face_pixels(stage, session, faces):
    """The albedo-AOV pixel (x, y) at the middle of each cube face as rendered (the rendered point furthest along the
    face's normal, or the mean of those tied: the limit surface of a subdivided cube lies inside the cage) seen by
    main_cam."""
    frustum = UsdGeom.Camera(stage.GetPrimAtPath("/World/main_cam")).GetCamera(Usd.TimeCode.Default()).frustum
    to_ndc = frustum.ComputeViewMatrix() * frustum.ComputeProjectionMatrix()
    points = np.asarray(session.index.mesh_points("/World/cube"), dtype=np.float64)
    pixels = []
    for f in faces:
        normal = np.mean([CUBE_POINTS[i] for i in CUBE_FACES[f]], axis=0)
        along = points @ normal
        ndc = to_ndc.Transform(Gf.Vec3d(*points[along > along.max() - 1e-4].mean(axis=0)))
        pixels.append((int((ndc[0] + 1) / 2 * session.width), int((1 - ndc[1]) / 2 * session.height)))
    return pixels


@pytest.mark.parametrize("scheme", ["none", "catmullClark"])
def test_geom_subset_cube_renders_each_face_in_its_material(scheme):
    stage = new_stage()
    mesh = cube(stage, scheme=scheme)
    red = preview_material(stage, "/World/red", (0.8, 0.1, 0.1))
    green = preview_material(stage, "/World/green", (0.1, 0.7, 0.2))
    blue = preview_material(stage, "/World/blue", (0.1, 0.2, 0.9))
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(blue)
    binding = UsdShade.MaterialBindingAPI(mesh.GetPrim())
    for name, faces, mat in (("top", [3], red), ("right", [5], green)):  # +y red, +x green, +z the mesh's blue
        subset = binding.CreateMaterialBindSubset(name, faces)
        UsdShade.MaterialBindingAPI.Apply(subset.GetPrim()).Bind(mat)
    s = RenderSession(stage, width=48, height=48, aovs=["albedo"])
    s.render(spp=1)
    albedo = s.image("albedo")
    expected = {3: (0.8, 0.1, 0.1), 5: (0.1, 0.7, 0.2), 1: (0.1, 0.2, 0.9)}
    for face, (x, y) in zip(expected, face_pixels(stage, s, expected)):
        assert albedo[y, x] == pytest.approx(expected[face], abs=1e-6), (face, x, y, albedo[y, x])
    assert not [w for w in s.scene.warnings if "subset" in w.lower()]


def test_geom_subset_problems_are_warned_once():
    stage = new_stage()
    mesh = cube(stage)
    binding = UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim())
    binding.CreateMaterialBindSubset("a", [0, 1, 9])
    binding.CreateMaterialBindSubset("b", [1, 2])
    binding.SetMaterialBindSubsetsFamilyType(UsdGeom.Tokens.partition)
    s = synced(stage)
    warnings = [w for w in s.scene.warnings if "subset" in w.lower() or "/World/cube/" in w]
    assert len(warnings) == 2, warnings
    assert warnings[0].startswith("/World/cube: materialBind subsets (partition): ")
    assert warnings[1] == "/World/cube/a: 1 indices outside the 6 faces ignored"
