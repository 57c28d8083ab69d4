"""Meshes from memory: NumPy arrays (or trimesh / Open3D objects) as the
canonical PLY bytes the engine and the server read.

sample(mesh=(vertices, faces), ...) does not write a file: the arrays are
checked here, then packed into one binary little-endian PLY in memory
(float64 x y z [nx ny nz] [weight], faces as `list uchar int`), which the
embedded engine reads from memory and a Client uploads once, keyed by its
SHA-256. Because it is an ordinary PLY file, the same arrays give the same
samples as that file written to disk and sampled from it, in process and over
the wire; and any PLY with the same vertex values and faces (float or double,
ASCII or binary) gives the same samples too, since the engine samples the
parsed mesh, not the bytes. float32 vertices are widened exactly to float64,
so float32 and float64 arrays of the same values are the same model (same
bytes, same hash, same tree key).
"""

import hashlib

import numpy as np

from sfcsampler import _core
from sfcsampler.errors import InvalidArgumentError

WEIGHT_PROPERTY = _core.MESH_WEIGHT_PROPERTY  # the PLY vertex property per-vertex weights travel in
_MAX_INDEX = 2**31 - 1      # faces are written as PLY int


def _fail(message):
    return InvalidArgumentError(3, message)


def _real_array(value, what, float_only):
    try:
        array = np.asarray(value)
    except Exception as e:  # e.g. ragged nested lists
        raise _fail(f"{what} must be a NumPy array: {e}") from None
    kinds = "f" if float_only else "fiu"
    if array.dtype.kind not in kinds:
        wanted = "float32 or float64" if float_only else "a real number type"
        raise TypeError(f"{what} must be {wanted}, not {array.dtype}")
    return array


def _rows_of_three(array, what, rows):
    if array.ndim != 2 or array.shape[1] != 3:
        raise _fail(f"{what} must have shape (n, 3), not {array.shape}")
    if rows is not None and array.shape[0] != rows:
        raise _fail(f"{what} has {array.shape[0]} rows; the mesh has {rows} vertices")


def _finite(array, what):
    bad = ~np.isfinite(array)
    if bad.any():
        row = int(np.argwhere(bad)[0][0])
        raise _fail(f"{what} row {row} is not finite: {array[row].tolist()}")


def check_vertices(vertices):
    v = _real_array(vertices, "mesh vertices", float_only=True)
    if v.dtype not in (np.float32, np.float64):
        raise TypeError(f"mesh vertices must be float32 or float64, not {v.dtype}")
    _rows_of_three(v, "mesh vertices", None)
    if v.shape[0] < 3:
        raise _fail(f"mesh vertices has {v.shape[0]} rows; a mesh needs at least 3 vertices")
    _finite(v, "mesh vertices")
    return np.ascontiguousarray(v, dtype="<f8")


def check_faces(faces, vertex_count):
    f = _real_array(faces, "mesh faces", float_only=False)
    if f.dtype.kind not in "iu":
        raise TypeError(f"mesh faces must be int32 or int64, not {f.dtype}")
    _rows_of_three(f, "mesh faces", None)
    if f.shape[0] == 0:
        raise _fail("mesh faces is empty; a mesh needs at least one triangle")
    low, high = f.min(), f.max()
    if low < 0 or high >= vertex_count:
        bad = int(np.argwhere((f < 0) | (f >= vertex_count))[0][0])
        raise _fail(f"mesh faces row {bad} is {f[bad].tolist()}: vertex indices must lie in "
                    f"[0, {vertex_count}) (the mesh has {vertex_count} vertices)")
    if vertex_count - 1 > _MAX_INDEX:
        raise _fail(f"the mesh has {vertex_count} vertices; at most {_MAX_INDEX + 1} are supported")
    return np.ascontiguousarray(f, dtype="<i4")


def check_normals(normals, vertex_count):
    n = _real_array(normals, "mesh normals", float_only=True)
    _rows_of_three(n, "mesh normals", vertex_count)
    _finite(n, "mesh normals")
    return np.ascontiguousarray(n, dtype="<f8")


def check_weights(weights, vertex_count):
    w = _real_array(weights, "density weights", float_only=False)
    if w.ndim != 1 or w.shape[0] != vertex_count:
        raise _fail(
            f"density weights must have shape ({vertex_count},), one per vertex, not {w.shape}")
    w = np.ascontiguousarray(w, dtype="<f8")
    _finite(w[:, None], "density weights")
    if (w < 0).any():
        i = int(np.argmax(w < 0))
        raise _fail(f"density weights row {i} is {w[i]!r}; weights must be >= 0")
    if not (w > 0).any():
        raise _fail("density weights are all zero; at least one vertex needs a positive weight")
    return w


def mesh_arrays(mesh):
    """(vertices, faces, normals or None) from a mesh argument, unchecked.

    Takes a tuple (vertices, faces) or (vertices, faces, vertex_normals); a
    dict with "vertices" and "faces" (or "triangles"), optionally
    "vertex_normals"; an object with `vertices` and `faces` (trimesh: its
    lazily computed normals are not used) or `vertices` and `triangles`
    (Open3D: its vertex normals when it has them, as Open3D writes them to
    PLY).
    """
    if isinstance(mesh, (tuple, list)):
        if len(mesh) not in (2, 3):
            raise _fail(f"mesh must be (vertices, faces) or (vertices, faces, vertex_normals), "
                        f"not a sequence of {len(mesh)}")
        return mesh[0], mesh[1], (mesh[2] if len(mesh) == 3 else None)
    if isinstance(mesh, dict):
        faces = mesh.get("faces", mesh.get("triangles"))
        if "vertices" not in mesh or faces is None:
            raise _fail("a mesh dict needs 'vertices' and 'faces' (or 'triangles')")
        return mesh["vertices"], faces, mesh.get("vertex_normals")
    if hasattr(mesh, "vertices") and hasattr(mesh, "triangles"):  # Open3D TriangleMesh
        normals = None
        has_normals = getattr(mesh, "has_vertex_normals", None)
        if callable(has_normals) and has_normals():
            normals = np.asarray(mesh.vertex_normals)
        return np.asarray(mesh.vertices), np.asarray(mesh.triangles), normals
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):  # trimesh.Trimesh and the like
        return np.asarray(mesh.vertices), np.asarray(mesh.faces), None
    raise TypeError(
        "mesh must be (vertices, faces) arrays, a dict, or an object with vertices and "
        f"faces (trimesh) or vertices and triangles (Open3D), not {type(mesh).__name__}")


def canonical_ply(vertices, faces, normals=None, weights=None):
    """The canonical binary PLY bytes of a mesh after checking every argument.

    Raises TypeError (wrong dtype) or sfcsampler.InvalidArgumentError (a
    ValueError: empty arrays, wrong shapes, non-finite values, face indices
    out of range, negative weights), each naming the argument. The bytes are
    written by C++ (python/bindings/mesh_arrays.h), as sample_many writes them.
    """
    v = check_vertices(vertices)
    f = check_faces(faces, v.shape[0])
    n = None if normals is None else check_normals(normals, v.shape[0])
    w = None if weights is None else check_weights(weights, v.shape[0])
    return _core.canonical_ply(v, f, n, w)


def mesh_ply(mesh, weights=None):
    """canonical_ply() of a mesh argument (see mesh_arrays)."""
    vertices, faces, normals = mesh_arrays(mesh)
    return canonical_ply(vertices, faces, normals, weights)


def write_ply(path, mesh, weights=None):
    """Writes a mesh argument's canonical PLY to `path` (what sample(mesh=...) samples)."""
    data = mesh_ply(mesh, weights)
    with open(path, "wb") as out:
        out.write(data)
    return hashlib.sha256(data).hexdigest()


def resolve(request):
    """Splits a request's mesh=... (and density=weights) off: returns
    (request without them, (ply bytes, name) or None). A weights array
    becomes density "vertex:weight"."""
    mesh = request.get("mesh")
    density = request.get("density")
    weights = density if density is not None and not isinstance(density, str) else None
    if mesh is None:
        if weights is not None:
            raise TypeError("density must be a str; an array of per-vertex weights needs mesh=...")
        return request, None
    if "surface" in request:
        raise TypeError("give either surface=... or mesh=..., not both")
    rest = {k: v for k, v in request.items() if k != "mesh"}
    if weights is not None:
        rest["density"] = "vertex:" + WEIGHT_PROPERTY
    return rest, mesh_ply(mesh, weights)
