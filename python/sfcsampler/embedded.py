"""The embedded sampler: the CLI's engine in this process, through pybind11."""

import contextlib

from sfcsampler import _core, meshes
from sfcsampler._request import make_request
from sfcsampler.samples import Samples, column_dtype, kept_columns, select, warn_depth_cap

_ALL = 1 << 62  # "every remaining sample"


class Sampler:
    """An embedded sampler that keeps recent curve trees.

    Sampler(max_trees=4, threads=0): `max_trees` trees (by surface, density,
    options and grade) stay built between calls, so a second request on the
    same surface and count skips the build; `threads` fill one request (0 =
    as the CLI: up to 4; the samples never depend on it). Thread-safe.
    model_check_program: sfcsampler-model-check's path, to read each CAD file in
    a process of its own (many.find_model_check_program() finds it); "" = in this
    process. model_parse_seconds: CPU seconds one model's parse may take (0 = no limit).
    parsed_model_bytes: parsed models (meshes, CAD shapes) kept for later calls
    (default 256 MiB; 0 = none, for models each sampled once); parse_threads: 0 =
    each call parses its model on its own thread (calls on several threads parse
    at once), N = on N threads of the engine's own. output_pool_bytes: the buffers
    of freed result arrays kept to hold later results (default 256 MiB; 0 = none), so a
    warm loop reuses its memory instead of faulting in fresh pages.

    The request keywords are `sfcsampler sample`'s flags (see sample()).
    """

    def __init__(self, max_trees=4, threads=0, *, model_check_program="", model_parse_seconds=0,
                 parsed_model_bytes=256 << 20, parse_threads=0, output_pool_bytes=256 << 20):
        self._engine = _core.Engine(max_trees=max_trees, threads=threads,
                                    model_check_program=model_check_program,
                                    model_parse_seconds=model_parse_seconds,
                                    parsed_model_bytes=parsed_model_bytes,
                                    parse_threads=parse_threads,
                                    output_pool_bytes=output_pool_bytes)

    def _held(self, request, call):
        """call(parsed request) with a mesh=... argument held in memory as its PLY bytes."""
        request, ply = meshes.resolve(request)
        if ply is None:
            return call(make_request(request))
        spec = self._engine.hold_model("ply", ply, "mesh (arrays)")
        try:
            return call(make_request(dict(request, surface=spec)))
        finally:
            self._engine.release_model(spec)

    def _start(self, precision, request):
        job = self._held(request, lambda r: self._engine.start(r, precision=precision))
        warn_depth_cap(job.tree, stacklevel=4)
        return job

    def sample(self, *, precision="float64", columns=None, **request):
        """All the requested samples as one Samples (no copy of the filled buffers); only
        the named columns when `columns` is given (sample())."""
        kept = kept_columns(columns, request)
        job = self._start(precision, request)
        filled = select(job.next(_ALL) or {}, kept)
        return Samples(filled, job.tree, job.begin, job.end, job.seed, _core.ALGORITHM_VERSION,
                       column_dtype(precision), kept)

    def sample_bytes(self, fmt, data, name="", *, precision="float64", columns=None, **request):
        """sample() of a model given as its file's bytes (fmt: step, iges, nurbs, obj, ply):
        the same samples as surface="FORMAT:FILE" on a file holding them, with no file."""
        if "surface" in request or "mesh" in request:
            raise TypeError("sample_bytes takes the model as fmt and data, not surface= or mesh=")
        with self.holding(fmt, data, name) as spec:
            return self.sample(precision=precision, columns=columns, surface=spec, **request)

    @contextlib.contextmanager
    def holding(self, fmt, data, name=""):
        """Holds a model given as its file's bytes while the block runs; yields its spec
        "FORMAT:sha256=HEX", which requests name it by (HEX: the bytes' SHA-256)."""
        spec = self._engine.hold_model(fmt, data, name)
        try:
            yield spec
        finally:
            self._engine.release_model(spec)

    def batches(self, *, batch_size=65536, precision="float64", columns=None, **request):
        """Yields the requested samples as Samples of at most batch_size each, in curve order."""
        kept = kept_columns(columns, request)
        job = self._start(precision, request)
        while True:
            filled = job.next(batch_size)
            if filled is None:
                return
            yield Samples(select(filled, kept), job.tree, job.begin, job.end, job.seed,
                          _core.ALGORITHM_VERSION, column_dtype(precision), kept)

    def prepare(self, **request):
        """Builds (or finds) the request's tree, sized for tree_count or count; returns its
        summary."""
        tree = self._held(request, self._engine.prepare)
        warn_depth_cap(tree, stacklevel=3)
        return tree


def sample(*, precision="float64", threads=0, **request):
    """Samples a surface in this process and returns NumPy arrays.

    The keywords are `sfcsampler sample`'s flags without the dashes ('-' as
    '_') and with the same defaults, and the same request gives the same
    numbers as the CLI, the server and Client.sample():

      surface="sphere", density="uniform"   catalogue specs ("torus:R=2;r=0.5",
                                            "gaussian:floor=0.05", "expr:u+v"),
                                            or a model file ("ply:scan.ply")
      mesh=(vertices, faces)                instead of surface: a triangle mesh in
                                            memory (float32/float64 (n, 3) and
                                            int32/int64 (m, 3) arrays; or a trimesh
                                            or Open3D mesh), sampled as the same
                                            mesh in a PLY file would be; then
                                            density may be per-vertex weights
                                            (an array of n values >= 0)
      count=10000, seed=1                   N, the size of the whole set
      curve="hilbert"                       hilbert | hilbert2 | peano
      sequence="jittered"                   jittered | equal | random |
                                            vandercorput | progressive |
                                            blue (evenly spaced; not for
                                            integration) | sobol
      estimator="fff", tolerance=0, depth_cap=0, rho=1.0, tree_count=0
      begin=0, end=0                        the index range [begin, end) (0 = count)
      shard=None                            "i/K" or (i, K)
      region=""                             "uv:U0,U1,V0,V1" or "box:X0,Y0,Z0,X1,Y1,Z1"
      normals=False, density_column=False, curve_position=False
      face=False, triangle=False            model columns: CAD face, mesh triangle
      precision="float64"                   or "float32" (half the memory; values float32
                                            cannot hold raise InvalidArgumentError)
      columns=None                          keep only these columns, e.g. ("x", "y", "z"):
                                            the others are freed at once (the rest of
                                            Samples' columns are None); default all
      threads=0                             threads filling the arrays (0 = up to 4)

    Returns a sfcsampler.Samples (columns index, u, v, x, y, z, ...). Raises
    sfcsampler.InvalidArgumentError (a ValueError) for bad input and warns
    (DepthCapWarning) when the depth cap limited the tree. The GIL is released
    while the tree is built and the arrays are filled. Builds the tree every
    call; use a Sampler to keep it.
    """
    return _one_call(threads).sample(precision=precision, **request)


def batches(*, batch_size=65536, precision="float64", threads=0, **request):
    """Like sample(), but yields Samples of at most batch_size samples each."""
    return _one_call(threads).batches(batch_size=batch_size, precision=precision, **request)


def prepare(**request):
    """The summary (dict) of the curve tree a request would use, after building it."""
    return _one_call(0).prepare(**request)


def _one_call(threads):
    """A Sampler for one call: no trees kept, and no pool (its buffers would outlive the
    call's arrays for nothing)."""
    return Sampler(max_trees=0, threads=threads, output_pool_bytes=0)
