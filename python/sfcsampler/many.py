"""Many models in one call: sfcsampler.sample_many() and what `sfcsampler
sample-many` and sfcsampler.dask share with it.

Each model's seed is derived from the base seed and the model's content hash
(the SHA-256 of its file bytes, or of the canonical PLY of a mesh given as
arrays), so a model's samples do not depend on the order of the models, on
which worker sampled it or on how many workers there were: model_seed(), the
CLI's own function (request/model_spec.h ModelSeed). A model's result is then
exactly sfcsampler.sample(surface="FORMAT:FILE", seed=model_seed(base,
sha256), ...) on it alone.
"""

import concurrent.futures
import glob as globlib
import os
import shutil
import sys
import threading
import time

import numpy as np

from sfcsampler import _core, meshes
from sfcsampler._request import make_request
from sfcsampler.errors import Error
from sfcsampler.samples import (Samples, column_dtype, column_names, kept_columns, select,
                                warn_depth_cap)

# File extensions of the model formats (lower case, with the dot) and their formats, the
# CLI's table (request/model_files.h).
EXTENSIONS = dict(_core.MODEL_EXTENSIONS)


def model_seed(base_seed, sha256_hex):
    """The seed a model gets from the base seed and its content hash (64 hex digits): the
    first 8 bytes, big-endian, of SHA-256("sfcsampler.model-seed\\0" + base seed as 8 bytes
    little-endian + the hash's 32 bytes), top bit cleared; computed by C++ as the CLI does."""
    return _core.model_seed(int(base_seed), sha256_hex)


def model_format(path):
    """"step", "obj", ... from a file name's extension, or None."""
    return EXTENSIONS.get(os.path.splitext(str(path))[1].lower())


def _list_name(entry):
    """A list entry's name: normalised, without a leading "/" or "../" (outputs stay inside
    out_dir)."""
    name = os.path.normpath(entry)
    while name.startswith("/") or name.startswith("../"):
        name = name[1:] if name.startswith("/") else name[3:]
    return name


def expand_paths(source):
    """[(path, name)] of the model files a folder (subfolders too), a glob, a list file or a
    model file names; `name` is the path relative to the folder, the pattern's folder or the
    list file's folder (as `sfcsampler sample-many` names them). Folders and patterns are
    sorted by name, a list file keeps its order (one path a line, relative to its folder;
    blank lines and # comments skipped). FileNotFoundError when nothing matches."""
    source = os.fspath(source)
    if os.path.isdir(source):
        found = []
        for top, _, files in os.walk(source):
            for n in files:
                path = os.path.join(top, n)
                if model_format(n) and os.path.isfile(path):
                    found.append((path, os.path.relpath(path, source)))
        if not found:
            raise FileNotFoundError(f"the folder {source} has no model files "
                                    f"({', '.join(sorted(EXTENSIONS))})")
        return sorted(found, key=lambda item: item[1])
    wild = min((source.find(c) for c in "*?[" if c in source), default=-1)
    if wild >= 0:
        slash = source.rfind("/", 0, wild)
        root = "." if slash < 0 else source[:slash + 1]
        found = [(p, os.path.relpath(p, root)) for p in globlib.glob(source) if os.path.isfile(p)]
        if not found:
            raise FileNotFoundError(f"the pattern {source} matches no files")
        return sorted(found, key=lambda item: item[1])
    if model_format(source):
        return [(source, os.path.basename(source))]
    if os.path.isfile(source):  # a list file
        base = os.path.dirname(source)
        with open(source) as f:
            lines = [line.strip() for line in f]
        return [(os.path.join(base, line), _list_name(line)) for line in lines
                if line and not line.startswith("#")]
    raise FileNotFoundError(f"{source} is not a folder, a pattern, a list file or a model file")


class Model:
    """One model to sample: its name (for messages and the output file's stem) and either a
    file (path) or a mesh in memory (mesh arrays or object, optional per-vertex weights)."""

    def __init__(self, name, path=None, mesh=None, weights=None):
        self.name, self.path, self.mesh, self.weights = name, path, mesh, weights

    def load(self):
        """(format, bytes) of the model: the file's bytes, or a mesh's canonical PLY."""
        if self.path is not None:
            fmt = model_format(self.path)
            if fmt is None:
                raise meshes.InvalidArgumentError(
                    3, "unknown model format (extension); use one of "
                    f"{', '.join(sorted(EXTENSIONS))}")
            with open(self.path, "rb") as f:
                return fmt, f.read()
        return "ply", meshes.mesh_ply(self.mesh, self.weights)


def as_models(models):
    """A list of Model from sample_many's `models` argument: a folder, glob, list file or
    model path; a list of paths and meshes; or a dict name -> path or mesh."""
    if isinstance(models, (str, os.PathLike)):
        return [Model(name, path=p) for p, name in expand_paths(models)]
    if isinstance(models, dict):
        items = list(models.items())
    else:
        items = [(None, m) for m in models]
    out = []
    for k, (name, m) in enumerate(items):
        if isinstance(m, (str, os.PathLike)) and name is None:
            out += [Model(n, path=p) for p, n in expand_paths(m)]  # a folder, a pattern, ...
        elif isinstance(m, (str, os.PathLike)):
            out.append(Model(name, path=os.fspath(m)))
        elif isinstance(m, Model):
            out.append(m)
        else:
            out.append(Model(name or f"mesh{k}", mesh=m))
    return out


def output_name(name, fmt, keep_extension=False):
    """The output file of a model: its name without the model extension (kept when
    keep_extension: two models of one stem), plus .FORMAT."""
    stem, ext = os.path.splitext(name)
    return (stem if ext.lower() in EXTENSIONS and not keep_extension else name) + "." + fmt


def output_names(names, fmt="npy"):
    """output_name() of each name, keeping the extensions of names that share a stem;
    InvalidArgumentError for a name given twice."""
    stems = {}
    for n in names:
        stems[output_name(n, fmt)] = stems.get(output_name(n, fmt), 0) + 1
    out, seen = [], {}
    for n in names:
        o = output_name(n, fmt, stems[output_name(n, fmt)] > 1)
        if o in seen:
            raise meshes.InvalidArgumentError(
                3, f"models {seen[o]!r} and {n!r} would both write {o}; name each model once")
        seen[o] = n
        out.append(o)
    return out


def structured(samples):
    """Samples as one structured array with the CLI's NPY fields (numpy.load of its .npy)."""
    cols = samples.columns()
    dtype = [(k, v.dtype.newbyteorder("<")) for k, v in cols.items()]
    out = np.empty(len(samples), dtype=dtype)
    for k, v in cols.items():
        out[k] = v
    return out


class Result:
    """One model's outcome: name, sha256, seed, samples (when kept), path (when written),
    count, seconds, error (None when it worked)."""

    def __init__(self, name, sha256=None, seed=None, samples=None, path=None, count=0,
                 seconds=0.0, error=None):
        self.name, self.sha256, self.seed = name, sha256, seed
        self.samples, self.path = samples, path
        self.count, self.seconds, self.error = count, seconds, error

    @property
    def ok(self):
        return self.error is None

    def __repr__(self):
        state = "ok" if self.ok else f"failed: {self.error}"
        return f"Result({self.name!r}, {self.count} samples, seed {self.seed}, {state})"


class Results(list):
    """sample_many()'s results, in the order of the models."""

    @property
    def failed(self):
        return [r for r in self if not r.ok]

    def summary(self):
        ok = len(self) - len(self.failed)
        lines = [f"{len(self)} models: {ok} sampled, {len(self.failed)} failed, "
                 f"{sum(r.count for r in self)} samples"]
        lines += [f"  FAILED {r.name}: {r.error}" for r in self.failed]
        return "\n".join(lines)


# CPU seconds one model's parse may take in a many-model run (sample-many's
# --model-parse-seconds default, request/model_files.h).
MODEL_PARSE_SECONDS = _core.MODEL_PARSE_SECONDS


def find_model_check_program():
    """sfcsampler-model-check, which reads a CAD file in a process of its own, or "" when it is
    not installed: $SFCSAMPLER_MODEL_CHECK, else on PATH, else in a build tree beside this
    package (build/server/ for build/python/sfcsampler/)."""
    named = os.environ.get("SFCSAMPLER_MODEL_CHECK")
    if named:
        return named
    found = shutil.which("sfcsampler-model-check")
    if found:
        return found
    beside = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir,
                          "server", "sfcsampler-model-check")
    return os.path.normpath(beside) if os.access(beside, os.X_OK) else ""


def columns_list(request):
    """Turns request["columns"] into a list once (samples.column_names), for every model of a
    run to use."""
    if request.get("columns") is not None:
        request["columns"] = column_names(request["columns"])


class MeshArrays:
    """sample_one()'s path for a mesh given as (vertices, faces) NumPy arrays, in this
    process: one C++ call makes its canonical PLY, hashes it, derives its seed and samples it
    with the GIL released (Engine.sample_mesh_arrays), the same bytes as holding
    mesh_ply(mesh) and sampling it. Made once per run; None from make() when the request
    cannot take it (sample_one's other path then reports what is wrong)."""

    def __init__(self, sampler, request, base_seed):
        self.engine, self.base_seed = sampler._engine, base_seed
        rest = dict(request)
        self.precision = rest.pop("precision", "float64")
        columns = rest.pop("columns", None)
        rest["face"], rest["triangle"] = False, bool(rest.get("triangle"))
        if columns is not None:
            columns = [c for c in columns if c != "face"]
            if not columns:
                raise ValueError("no column")
        self.kept = kept_columns(columns, rest)
        column_dtype(self.precision)
        # Any mesh and seed: each call replaces them.
        self.request = make_request(dict(rest, surface="ply:sha256=" + "0" * 64, seed=0))

    @classmethod
    def make(cls, sampler, request, base_seed):
        try:
            return cls(sampler, request, base_seed)
        except (Error, TypeError, ValueError):
            return None

    def sample(self, model):
        """(sha256, seed, Samples) of the Model, or None when it is not (vertices, faces)
        arrays this path takes as they are or fails a check of canonical_ply()."""
        mesh = model.mesh
        if (model.path is not None or model.weights is not None or type(mesh) not in (tuple, list)
                or len(mesh) != 2 or type(mesh[0]) is not np.ndarray
                or type(mesh[1]) is not np.ndarray):
            return None
        out = self.engine.sample_mesh_arrays(mesh[0], mesh[1], self.request,
                                             base_seed=self.base_seed, precision=self.precision,
                                             name=model.name)
        if out is None:
            return None
        sha256, seed, columns, tree, begin, end = out
        warn_depth_cap(tree, stacklevel=4)
        return sha256, seed, Samples(select(columns, self.kept), tree, begin, end, seed,
                                     _core.ALGORITHM_VERSION, column_dtype(self.precision),
                                     self.kept)


def sample_one(model, request, base_seed, sampler=None, out_path=None, keep=True, client=None,
               mesh_arrays=None):
    """Samples one Model with its derived seed; never raises for the model's own errors
    (they go into Result.error). `client` samples on a server instead of `sampler`;
    `mesh_arrays` (a MeshArrays) takes meshes given as arrays in this process."""
    start = time.perf_counter()
    result = Result(model.name)
    try:
        fast = None
        if mesh_arrays is not None:
            try:
                fast = mesh_arrays.sample(model)
            except Error:
                fast = None  # the other path reports it, with the model's hash and seed
        if fast is not None:
            result.sha256, result.seed, samples = fast
            _finish(result, samples, out_path, keep)
            result.seconds = time.perf_counter() - start
            return result
        fmt, data = model.load()
        request = dict(request)
        mesh = fmt in ("obj", "ply")  # the model columns apply to the models that have them
        request["face"] = bool(request.get("face")) and not mesh
        request["triangle"] = bool(request.get("triangle")) and mesh
        if request.get("columns") is not None:  # a list (sample_many made it one)
            other = "face" if mesh else "triangle"  # the other kind's column
            request["columns"] = [c for c in request["columns"] if c != other]
            if not request["columns"]:
                raise meshes.InvalidArgumentError(
                    3, f"columns: this model has no {other!r} column ({other} is for "
                       f"{'CAD models' if mesh else 'meshes'}); name a column it has")
        if client is not None:
            # The server's spec carries the bytes' SHA-256 (hashed once, in C++).
            spec = client.upload_bytes(fmt, data, model.name)
            result.sha256 = spec.rsplit("sha256=", 1)[1]
            result.seed = model_seed(base_seed, result.sha256)
            samples = client.sample(surface=spec, seed=result.seed, **request)
        else:
            from sfcsampler.embedded import Sampler
            sampler = sampler or Sampler(max_trees=0, threads=1)
            # The held model's spec carries the bytes' SHA-256 (hashed once, in C++).
            with sampler.holding(fmt, data, model.name) as spec:
                result.sha256 = spec.rsplit("sha256=", 1)[1]
                result.seed = model_seed(base_seed, result.sha256)
                samples = sampler.sample(surface=spec, seed=result.seed, **request)
        _finish(result, samples, out_path, keep)
    except (Error, OSError, ValueError, TypeError, MemoryError) as e:
        result.error = str(e)
    result.seconds = time.perf_counter() - start
    return result


def _finish(result, samples, out_path, keep):
    """Counts, writes (out_path) and keeps (keep) one model's samples."""
    result.count = len(samples)
    if out_path is not None:
        result.path = out_path
        os.makedirs(os.path.dirname(out_path) or ".", exist_ok=True)
        write_npy(result.path, samples)
    if keep:
        result.samples = samples


def npy_bytes(samples):
    """The samples as the bytes of the CLI's NPY file (client/sample_writer.cc: format 1.0,
    the header padded to 64 bytes), so Python and the CLI write identical files."""
    array = structured(samples)
    descr = "[" + ", ".join(f"('{name}', '{array.dtype[name].str}')"
                            for name in array.dtype.names) + "]"
    header = f"{{'descr': {descr}, 'fortran_order': False, 'shape': ({len(array)},), }}"
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    return (b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode()
            + array.tobytes())


def write_npy(path, samples):
    """Writes samples as the CLI's NPY (a structured array), through a temporary name."""
    tmp = path + ".part"
    with open(tmp, "wb") as f:
        f.write(npy_bytes(samples))
    os.replace(tmp, path)


class _Bar:
    """"k/N models (f failed)" redrawn on stderr when it is a terminal."""

    def __init__(self, total, enabled):
        self.total, self.done, self.failed = total, 0, 0
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.lock = threading.Lock()

    def step(self, result):
        with self.lock:
            self.done += 1
            self.failed += not result.ok
            if self.enabled:
                width = 30
                filled = width * self.done // max(self.total, 1)
                sys.stderr.write(
                    f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} "
                    f"models, {self.failed} failed ")
                sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


def sample_many(models, *, seed=1, out_dir=None, keep=None, workers=0, progress=None,
                server=None, model_check_program="auto", model_parse_seconds=MODEL_PARSE_SECONDS,
                **request):
    """Samples many models, each with its own seed derived from `seed` and its content hash.

    models: a folder, a glob ("data/**/*.obj"), a list file, or a model file; or a list of
      paths and meshes (anything sample(mesh=...) takes); or a dict name -> path or mesh.
    out_dir: write each model's samples to OUT_DIR/NAME.npy, NAME the model's path relative
      to the folder it came from, without its extension (the CLI's file, byte for byte:
      numpy.load gives a structured array); keep: also keep them in the results (default:
      only when out_dir is None). workers: models sampled at once (0 = the CPU count, at
      most 8); each model then uses one thread. progress: a progress bar on stderr (None =
      when it is a terminal).
    server: "host:port" or a Client: sample on a server instead of in this process.
    model_check_program: in this process, read each CAD file in this program, a process of its
      own, so a file that crashes or loops the CAD kernel, or leaves it broken for the next,
      fails alone ("auto": find_model_check_program(), in this process when not installed;
      "" = in this process); model_parse_seconds: CPU seconds one model's parse may take.
    The other keywords are sample()'s (count, density, normals, columns, ...), the same for
    every model; face=True applies to the CAD models and triangle=True to the meshes.
    columns=("x", "y", "z") keeps (and writes) only those columns: the others' memory goes
    back to the next model at once (written files then hold only those fields). Returns
    Results (a list of Result, in the models' order); a model that fails has its error in
    Result.error and the others go on. Results.failed, Results.summary().
    """
    from sfcsampler.embedded import Sampler
    for bad in ("surface", "mesh"):
        if bad in request:
            raise TypeError(f"sample_many takes the models as its first argument, not {bad}=")
    items = as_models(models)
    columns_list(request)
    paths = [None] * len(items)
    if out_dir is not None:
        os.makedirs(out_dir, exist_ok=True)
        paths = [os.path.join(out_dir, o) for o in output_names([m.name for m in items])]
    keep = out_dir is None if keep is None else keep
    workers = workers or min(8, os.cpu_count() or 1)
    own_client = isinstance(server, str)
    if own_client:
        from sfcsampler.client import Client  # loads gRPC: only for a server
        client = Client(server)
    else:
        client = server
    if model_check_program == "auto":
        model_check_program = find_model_check_program()
    # Each model is parsed and sampled once: the engine keeps no parsed model (their
    # memory goes back to the next parse), and each worker parses its own models.
    sampler = None if client is not None else Sampler(
        max_trees=0, threads=1 if workers > 1 else 0, model_check_program=model_check_program,
        model_parse_seconds=model_parse_seconds, parsed_model_bytes=0, parse_threads=0)
    mesh_arrays = None if sampler is None else MeshArrays.make(sampler, request, seed)
    bar = _Bar(len(items), progress)
    results = Results([None] * len(items))

    def run(k):
        # On a worker thread: this thread waits for all at once, not woken per model
        # (a wake-up per model costs GIL hand-overs the workers would wait for).
        results[k] = sample_one(items[k], request, seed, sampler, paths[k], keep, client,
                                mesh_arrays)
        bar.step(results[k])

    try:
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(run, k) for k in range(len(items))]
            concurrent.futures.wait(futures)  # one wake-up, when all are done
            for future in futures:
                future.result()  # re-raises what sample_one does not catch
    finally:
        bar.close()
        if own_client:
            client.close()
    return results
