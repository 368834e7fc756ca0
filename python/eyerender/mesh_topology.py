"""A UsdGeom.Mesh's subdivision (scheme, tags, holes) and its materialBind GeomSubsets, read for the delegate.

What the delegate refines through OpenSubdiv's topology descriptor (docs/geometry.md): catmullClark, loop and
bilinear; creases (creaseIndices / creaseLengths, one sharpness per crease or per edge; 10 is infinitely sharp),
corners, holes, interpolateBoundary, faceVaryingLinearInterpolation and triangleSubdivisionRule. Malformed tags are
dropped with one warning naming the prim and the tag; they never fail the mesh.
"""
import numpy as np
from pxr import UsdGeom, UsdShade

SCHEMES = ("catmullClark", "loop", "bilinear", "none")
BOUNDARIES = ("none", "edgeOnly", "edgeAndCorner")
FACE_VARYING_RULES = ("none", "cornersOnly", "cornersPlus1", "cornersPlus2", "boundaries", "all")
TRIANGLE_RULES = ("catmullClark", "smooth")


def _ints(attr, time):
    value = attr.Get(time) if attr else None
    return np.asarray(value if value is not None else [], dtype=np.int32).ravel()


def _floats(attr, time):
    value = attr.Get(time) if attr else None
    return np.asarray(value if value is not None else [], dtype=np.float32).ravel()


def _token(attr, time, choices, default, path, warnings):
    """An authored token among `choices`, else `default` (with a warning when it is unknown)."""
    value = attr.Get(time) if attr else None
    if value is None:
        return default
    if str(value) not in choices:
        warnings.append(f"{path}: {attr.GetName()} '{value}' is not one of {', '.join(choices)}; using '{default}'")
        return default
    return str(value)


def _mesh_edges(counts, indices):
    """The mesh's edges as a set of (low, high) point pairs."""
    starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
    offsets = np.arange(len(indices)) - np.repeat(starts, counts)
    following = np.repeat(starts, counts) + (offsets + 1) % np.repeat(counts, counts)
    a, b = indices, indices[following]
    return set(zip(np.minimum(a, b).tolist(), np.maximum(a, b).tolist()))


class Subdivision:
    """A mesh's subdivision as the delegate takes it: `scheme` (a SCHEMES token the delegate refines, or "none"),
    the tags and holes, and `warnings` (one line each, naming the prim)."""

    def __init__(self, mesh, counts, indices, point_count, time):
        path = mesh.GetPath()
        self.warnings = []
        scheme = _token(mesh.GetSubdivisionSchemeAttr(), time, SCHEMES, "catmullClark", path, self.warnings)
        if scheme == "loop" and (counts != 3).any():
            face = int(np.argmax(counts != 3))
            self.warnings.append(f"{path}: subdivisionScheme 'loop' needs triangles, face {face} has "
                                 f"{int(counts[face])} vertices; rendered as catmullClark")
            scheme = "catmullClark"
        self.scheme = scheme
        self.interpolate_boundary = _token(mesh.GetInterpolateBoundaryAttr(), time, BOUNDARIES, "edgeAndCorner",
                                           path, self.warnings)
        self.face_varying = _token(mesh.GetFaceVaryingLinearInterpolationAttr(), time, FACE_VARYING_RULES,
                                   "cornersPlus1", path, self.warnings)
        self.triangle_rule = _token(mesh.GetTriangleSubdivisionRuleAttr(), time, TRIANGLE_RULES, "catmullClark",
                                    path, self.warnings)
        self._read_creases(mesh, counts, indices, point_count, time)
        self._read_corners(mesh, point_count, time)
        holes = _ints(mesh.GetHoleIndicesAttr(), time)
        bad = (holes < 0) | (holes >= len(counts))
        if bad.any():
            self.warnings.append(f"{path}: holeIndices: {int(bad.sum())} outside the {len(counts)} faces ignored")
        self.holes = np.ascontiguousarray(holes[~bad])

    @property
    def refines(self):
        return self.scheme != "none"

    def _read_creases(self, mesh, counts, indices, point_count, time):
        path = mesh.GetPath()
        crease_indices = _ints(mesh.GetCreaseIndicesAttr(), time)
        lengths = _ints(mesh.GetCreaseLengthsAttr(), time)
        sharpnesses = _floats(mesh.GetCreaseSharpnessesAttr(), time)
        self.crease_indices = self.crease_lengths = np.zeros(0, np.int32)
        self.crease_sharpnesses = np.zeros(0, np.float32)
        if not len(crease_indices) and not len(lengths):
            return
        edges = int(np.maximum(lengths - 1, 0).sum())
        problem = None
        if (lengths < 2).any():
            problem = "a creaseLengths entry is below 2"
        elif int(lengths.sum()) != len(crease_indices):
            problem = f"creaseLengths add up to {int(lengths.sum())}, creaseIndices has {len(crease_indices)}"
        elif ((crease_indices < 0) | (crease_indices >= point_count)).any():
            problem = f"creaseIndices refer to points outside [0, {point_count})"
        elif len(sharpnesses) not in (len(lengths), edges):
            problem = (f"creaseSharpnesses has {len(sharpnesses)} values, need one per crease ({len(lengths)}) "
                       f"or per edge ({edges})")
        elif not np.isfinite(sharpnesses).all():
            problem = "creaseSharpnesses holds NaN or infinite values"
        if problem:
            self.warnings.append(f"{path}: creases ignored: {problem}")
            return
        mesh_edges = _mesh_edges(counts, indices)
        starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
        missing = sum((min(a, b), max(a, b)) not in mesh_edges
                      for s, n in zip(starts.tolist(), lengths.tolist())
                      for a, b in zip(crease_indices[s:s + n - 1].tolist(), crease_indices[s + 1:s + n].tolist()))
        if missing:
            self.warnings.append(f"{path}: {missing} of the {edges} crease edges are not edges of the mesh; ignored")
        self.crease_indices, self.crease_lengths, self.crease_sharpnesses = crease_indices, lengths, sharpnesses

    def _read_corners(self, mesh, point_count, time):
        path = mesh.GetPath()
        corners = _ints(mesh.GetCornerIndicesAttr(), time)
        sharpnesses = _floats(mesh.GetCornerSharpnessesAttr(), time)
        self.corner_indices, self.corner_sharpnesses = np.zeros(0, np.int32), np.zeros(0, np.float32)
        if not len(corners) and not len(sharpnesses):
            return
        if len(corners) != len(sharpnesses):
            problem = f"cornerIndices has {len(corners)} entries, cornerSharpnesses {len(sharpnesses)}"
        elif ((corners < 0) | (corners >= point_count)).any():
            problem = f"cornerIndices refer to points outside [0, {point_count})"
        elif not np.isfinite(sharpnesses).all():
            problem = "cornerSharpnesses holds NaN or infinite values"
        else:
            self.corner_indices, self.corner_sharpnesses = corners, sharpnesses
            return
        self.warnings.append(f"{path}: corners ignored: {problem}")

    def push(self, store, prim_id):
        """Sends the scheme, tags and holes to the scene store (marks the mesh's topology dirty)."""
        store.set_subdivision(prim_id, "catmullClark" if self.scheme == "none" else self.scheme,
                              self.interpolate_boundary, self.face_varying, self.triangle_rule,
                              self.crease_indices, self.crease_lengths, self.crease_sharpnesses,
                              self.corner_indices, self.corner_sharpnesses, self.holes)

    def authored(self):
        """Whether anything differs from a plain mesh of the scheme (so a store call is needed)."""
        return bool(len(self.holes) or len(self.crease_indices) or len(self.corner_indices) or
                    self.scheme not in ("catmullClark", "none") or self.interpolate_boundary != "edgeAndCorner" or
                    self.face_varying != "cornersPlus1" or self.triangle_rule != "catmullClark")


def material_subsets(prim, face_count, time, bind):
    """The materialBind GeomSubsets of a mesh prim as [(material id, face indices)] for the store, and warnings.

    `bind(subset_prim)` returns the material id bound to a subset (as the mesh's own binding is resolved: "" for
    none, which renders the mesh's material). Subsets of other element types, indices outside the faces and a
    family that breaks its familyType are warned about; overlapping faces take the first subset."""
    warnings = []
    binding = UsdShade.MaterialBindingAPI(prim)
    subsets = binding.GetMaterialBindSubsets()
    if not subsets:
        return [], warnings
    family = binding.GetMaterialBindSubsetsFamilyType()
    valid, reason = UsdGeom.Subset.ValidateSubsets(subsets, face_count, family)
    if not valid:
        warnings.append(f"{prim.GetPath()}: materialBind subsets ({family}): {reason.strip().splitlines()[0]}; "
                        f"overlapping faces take the first subset")
    out = []
    for subset in subsets:
        if subset.GetElementTypeAttr().Get() != UsdGeom.Tokens.face:
            warnings.append(f"{subset.GetPath()}: elementType '{subset.GetElementTypeAttr().Get()}' is not face; "
                            f"subset ignored")
            continue
        faces = _ints(subset.GetIndicesAttr(), time)
        bad = (faces < 0) | (faces >= face_count)
        if bad.any():
            warnings.append(f"{subset.GetPath()}: {int(bad.sum())} indices outside the {face_count} faces ignored")
        out.append((bind(subset.GetPrim()), faces[~bad].tolist()))
    return out, warnings
