"""Meshes from memory: sample(mesh=(V, F)) gives the same samples as the same
mesh written to a PLY file and sampled from it, in process and over the wire;
bad arrays raise errors that name the argument."""

import os
import types

import numpy as np
import pytest

import sfcsampler
from sfcsampler import meshes
from conftest import assert_same

COLUMNS = ("index", "u", "v", "x", "y", "z", "nx", "ny", "nz", "triangle", "density")


def torus_mesh(n=24, m=16, R=1.0, r=0.35, wobble=0.0, seed=0):
    """A closed torus grid: n*m vertices, 2*n*m triangles (float64, int64)."""
    a, b = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(m) * 2 * np.pi / m, indexing="ij")
    rr = r * (1 + wobble * np.random.default_rng(seed).standard_normal(a.shape))
    v = np.stack([(R + rr * np.cos(b)) * np.cos(a),
                  (R + rr * np.cos(b)) * np.sin(a), rr * np.sin(b)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    p00, p10 = i * m + j, ((i + 1) % n) * m + j
    p01, p11 = i * m + (j + 1) % m, ((i + 1) % n) * m + (j + 1) % m
    f = np.concatenate([np.stack([p00, p10, p11], -1).reshape(-1, 3),
                        np.stack([p00, p11, p01], -1).reshape(-1, 3)]).astype(np.int64)
    return v, f


def same_samples(a, b):
    for name in COLUMNS:
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and np.array_equal(x.view(np.uint8), y.view(np.uint8)), name


def ascii_ply(path, v, f, weights=None):
    """A different PLY of the same mesh: ASCII, repr() of each double, 'vertex_index'."""
    with open(path, "w") as out:
        out.write(f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty double x\n"
                  "property double y\nproperty double z\n")
        if weights is not None:
            out.write("property double quality\n")
        out.write(f"element face {len(f)}\nproperty list uchar int vertex_index\nend_header\n")
        for k, row in enumerate(v):
            extra = f" {weights[k]!r}" if weights is not None else ""
            out.write(" ".join(repr(float(c)) for c in row) + extra + "\n")
        for row in f:
            out.write("3 " + " ".join(str(int(c)) for c in row) + "\n")


KW = dict(count=20000, seed=7, triangle=True, normals=True)


def test_arrays_equal_the_ply_file(tmp_path):
    v, f = torus_mesh(wobble=0.05)
    path = tmp_path / "torus.ply"
    meshes.write_ply(path, (v, f))
    from_file = sfcsampler.sample(surface=f"ply:{path}", **KW)
    from_arrays = sfcsampler.sample(mesh=(v, f), **KW)
    assert len(from_arrays) == 20000
    same_samples(from_arrays, from_file)
    assert from_arrays.tree["key"] == from_file.tree["key"]
    # Another writer's PLY of the same values: different bytes, same samples.
    ascii_ply(tmp_path / "ascii.ply", v, f)
    same_samples(from_arrays, sfcsampler.sample(surface=f"ply:{tmp_path / 'ascii.ply'}", **KW))


def test_dtypes_and_objects_are_the_same_model():
    v, f = torus_mesh(wobble=0.05)
    v32 = v.astype(np.float32)
    base = sfcsampler.sample(mesh=(v32.astype(np.float64), f), **KW)
    for mesh in [(v32, f), (v32, f.astype(np.int32)), (v32.astype(np.float64), f.astype(np.int32)),
                 {"vertices": v32, "faces": f}, {"vertices": v32, "triangles": f},
                 types.SimpleNamespace(vertices=v32, faces=f)]:       # trimesh's attributes
        same_samples(sfcsampler.sample(mesh=mesh, **KW), base)
    assert meshes.mesh_ply((v32, f)) == meshes.mesh_ply(
        (v32.astype(np.float64), f.astype(np.int32)))


def test_open3d_mesh():
    o3d = pytest.importorskip("open3d")
    v, f = torus_mesh(wobble=0.05)
    m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
    same_samples(sfcsampler.sample(mesh=m, **KW), sfcsampler.sample(mesh=(v, f), **KW))
    m.compute_vertex_normals()  # Open3D's normals are used, as in the PLY Open3D writes
    n = np.asarray(m.vertex_normals)
    same_samples(sfcsampler.sample(mesh=m, **KW), sfcsampler.sample(mesh=(v, f, n), **KW))


def test_vertex_weights_equal_a_ply_property(tmp_path):
    v, f = torus_mesh()
    w = 0.1 + (v[:, 2] > 0)  # the upper half weighs 11 times the lower
    from_arrays = sfcsampler.sample(mesh=(v, f), density=w, count=30000, density_column=True)
    ascii_ply(tmp_path / "w.ply", v, f, weights=w)
    from_file = sfcsampler.sample(surface=f"ply:{tmp_path / 'w.ply'}", density="vertex:quality",
                                  count=30000, density_column=True)
    same_samples(from_arrays, from_file)
    assert len(from_arrays) == 30000
    upper = np.mean(from_arrays.z > 0)
    assert upper > 0.8, upper  # most of the mass is above z = 0


def reference_ply(v, f, n=None, w=None):
    """The canonical PLY as documented (meshes.py), written with NumPy's structured arrays."""
    fields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    columns = [v[:, 0], v[:, 1], v[:, 2]]
    if n is not None:
        fields += [("nx", "<f8"), ("ny", "<f8"), ("nz", "<f8")]
        columns += [n[:, 0], n[:, 1], n[:, 2]]
    if w is not None:
        fields.append(("weight", "<f8"))
        columns.append(w)
    vertex = np.empty(len(v), dtype=fields)
    for (name, _), column in zip(fields, columns):
        vertex[name] = column
    face = np.empty(len(f), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face["n"], face["i"] = 3, f
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(v)}"]
    header += [f"property double {name}" for name, _ in fields]
    header += [f"element face {len(f)}", "property list uchar int vertex_indices", "end_header", ""]
    return "\n".join(header).encode() + vertex.tobytes() + face.tobytes()


def test_canonical_ply_and_model_seed_are_the_documented_ones():
    # Both are C++ (python/bindings/mesh_arrays.h, request/model_spec.h), bound into Python:
    # checked here against the formats written out independently.
    import hashlib
    from sfcsampler import many
    v, f = torus_mesh(7, 5, wobble=0.1)
    n = v / np.linalg.norm(v, axis=1)[:, None]
    w = 0.5 + v[:, 0] ** 2
    for normals, weights in [(None, None), (n, None), (None, w), (n, w)]:
        for faces in (f, f.astype(np.int32)):
            for vertices in (v, v.astype(np.float32)):
                got = meshes.canonical_ply(vertices, faces, normals, weights)
                assert got == reference_ply(vertices.astype(np.float64), faces, normals, weights)
    for base in (0, 1, 11, 2**63 + 5, 2**64 - 1):
        for digest in (hashlib.sha256(b"").hexdigest(), hashlib.sha256(b"mesh").hexdigest()):
            expected = hashlib.sha256(b"sfcsampler.model-seed\0" + base.to_bytes(8, "little") +
                                      bytes.fromhex(digest)).digest()
            assert many.model_seed(base, digest) == (
                int.from_bytes(expected[:8], "big") & ((1 << 63) - 1))
    with pytest.raises(OverflowError):
        many.model_seed(-1, digest)
    with pytest.raises(ValueError):
        many.model_seed(1, "not hex")


def test_mesh_sampler_keeps_the_tree():
    v, f = torus_mesh()
    s = sfcsampler.Sampler(max_trees=2)
    a = s.sample(mesh=(v, f), count=5000)
    b = s.sample(mesh=(v, f), count=5000)
    assert not a.tree["cache_hit"] and b.tree["cache_hit"]
    same_samples(a, b)


def test_over_the_wire(server):
    v, f = torus_mesh(wobble=0.05)
    w = np.linspace(0.5, 2.0, len(v))
    local = sfcsampler.sample(mesh=(v.astype(np.float32), f), density=w, **KW)
    with sfcsampler.Client(server) as c:
        spec = c.upload_mesh((v.astype(np.float32), f), weights=w)
        remote = c.sample(mesh=(v.astype(np.float32), f), density=w, **KW)
        assert c.upload(spec) == spec  # held by the server under the canonical bytes' hash
        again = c.sample(mesh=(v.astype(np.float32), f), density=w, **KW)
    same_samples(remote, local)
    same_samples(again, local)
    assert again.tree["cache_hit"]
    assert spec == "ply:sha256=" + __import__("hashlib").sha256(
        meshes.mesh_ply((v.astype(np.float32), f), w)).hexdigest()


V, F = torus_mesh(6, 5)
BAD = [
    (dict(mesh=(np.zeros((0, 3)), F)), ValueError, "mesh vertices"),
    (dict(mesh=(V, np.zeros((0, 3), np.int64))), ValueError, "mesh faces is empty"),
    (dict(mesh=(V, F + 1)), ValueError, "mesh faces row"),
    (dict(mesh=(V, -F)), ValueError, "mesh faces row"),
    (dict(mesh=(np.where(np.arange(30)[:, None] == 4, np.nan, V), F)), ValueError,
     "mesh vertices row 4"),
    (dict(mesh=(np.where(np.arange(30)[:, None] == 2, np.inf, V), F)), ValueError,
     "mesh vertices row 2"),
    (dict(mesh=(V.astype(np.int64), F)), TypeError, "mesh vertices must be float32 or float64"),
    (dict(mesh=(V.astype(np.float16), F)), TypeError, "mesh vertices must be float32 or float64"),
    (dict(mesh=(V, F.astype(np.float64))), TypeError, "mesh faces must be int32 or int64"),
    (dict(mesh=(V[:, :2], F)), ValueError, "mesh vertices must have shape (n, 3)"),
    (dict(mesh=(V, np.concatenate([F, F[:, :1]], 1))), ValueError,
     "mesh faces must have shape (n, 3)"),
    (dict(mesh=(V.ravel(), F)), ValueError, "mesh vertices must have shape (n, 3)"),
    (dict(mesh=(V, F, V[:3])), ValueError, "mesh normals has 3 rows"),
    (dict(mesh=(V, F), density=np.ones(3)), ValueError, "density weights must have shape (30,)"),
    (dict(mesh=(V, F), density=-np.ones(30)), ValueError, "density weights row 0"),
    (dict(mesh=(V, F), density=np.full(30,
                                       np.nan)), ValueError, "density weights row 0 is not finite"),
    (dict(mesh=(V, F), density=np.zeros(30)), ValueError, "density weights are all zero"),
    (dict(mesh=(V, F), surface="sphere"), TypeError, "either surface"),
    (dict(density=np.ones(30)), TypeError, "needs mesh="),
    (dict(mesh=(V, )), ValueError, "mesh must be (vertices, faces)"),
    (dict(mesh=42), TypeError, "mesh must be"),
    (dict(mesh=([[0, 0, 0], [1, 0], [0, 1, 0]], [[0, 1, 2]])), ValueError, "mesh vertices"),
    # Every triangle without area: the engine's own check, naming the mesh.
    (dict(mesh=(np.zeros((3, 3)), np.array([[0, 1, 2]]))), ValueError, "mesh (arrays)"),
]


@pytest.mark.parametrize("kwargs,error,words", BAD)
def test_bad_input_names_the_argument(kwargs, error, words):
    with pytest.raises(error) as caught:
        sfcsampler.sample(count=100, **kwargs)
    assert words in str(caught.value), str(caught.value)


@pytest.mark.parametrize("kwargs,error,words", BAD[:6])
def test_bad_input_over_the_wire_fails_before_sending(server, kwargs, error, words):
    with sfcsampler.Client(server) as c, pytest.raises(error) as caught:
        c.sample(count=100, **kwargs)
    assert words in str(caught.value)
