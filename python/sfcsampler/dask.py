"""sfcsampler on a Dask cluster (Debian's python3-distributed), for jobs that
outgrow one machine.

    from distributed import Client
    import sfcsampler.dask
    client = Client("tcp://scheduler:8786")
    results = sfcsampler.dask.sample_many(client, "/data/shapenet", count=10000,
                                          out_dir="/data/clouds")
    shards = sfcsampler.dask.sample_shards(client, "torus", 10**9, shards=64,
                                           out_dir="/data/torus")

Each task is an ordinary sfcsampler call on a worker: the embedded sampler in
the worker's process (one per process, kept between tasks), or a server when
`service="host:port"` is given (then the workers need only the package's
client side; the server, or a Kubernetes Service of servers, holds the trees).
The results are those of one process: a model's seed comes from the base seed
and its content hash (sfcsampler.many.model_seed), and a shard is a fixed
index range of the one set, so neither depends on which worker ran what or how
many workers there were.

Paths are read where the task runs, so out_dir and file models must be on a
filesystem every worker sees; send_bytes=True ships model files' bytes from
the client instead (meshes given as arrays always travel as their canonical
PLY bytes).
"""

import os
import threading
import uuid

import numpy as np

from sfcsampler import many, meshes
from sfcsampler.errors import InvalidArgumentError

_local = threading.local()
_lock = threading.Lock()
_samplers = {}


def _sampler():
    """This worker process's embedded sampler (built once; trees of the last two requests kept,
    so the shards of one surface on one worker build its tree once)."""
    with _lock:
        if "embedded" not in _samplers:
            from sfcsampler.embedded import Sampler
            # A worker reads many files: each CAD file in a process of its own.
            _samplers["embedded"] = Sampler(max_trees=2, threads=1,
                                            model_check_program=many.find_model_check_program(),
                                            model_parse_seconds=many.MODEL_PARSE_SECONDS)
        return _samplers["embedded"]


def _client(service):
    """A Client to `service`, one per worker thread (a Client is thread-safe, but one per
    thread keeps the streams apart)."""
    clients = getattr(_local, "clients", None)
    if clients is None:
        clients = _local.clients = {}
    if service not in clients:
        from sfcsampler.client import Client
        clients[service] = Client(service)
    return clients[service]


class _Bytes(many.Model):
    """A model that travels as (format, bytes)."""

    def __init__(self, name, fmt, data):
        super().__init__(name)
        self.fmt, self.data = fmt, data

    def load(self):
        return self.fmt, self.data


def _many_task(models, request, seed, out_paths, keep, service):
    """A list of Result, one per model of this task's chunk."""
    if service:
        return [many.sample_one(m, request, seed, out_path=p, keep=keep, client=_client(service))
                for m, p in zip(models, out_paths)]
    return [many.sample_one(m, request, seed, sampler=_sampler(), out_path=p, keep=keep)
            for m, p in zip(models, out_paths)]


def _progress(futures, total, enabled):
    import distributed
    bar = many._Bar(total, enabled)
    try:
        for future in distributed.as_completed(futures):
            for result in future.result():
                bar.step(result)
    finally:
        bar.close()


def sample_many(client, models, *, seed=1, out_dir=None, keep=None, service=None, send_bytes=False,
                models_per_task=0, progress=None, **request):
    """sfcsampler.sample_many() with one Dask task per model, on `client`'s cluster.

    client: a distributed.Client. models, seed, out_dir, keep and the request keywords are
    sfcsampler.sample_many()'s, with the same results: each model's samples depend only on it,
    the request and the base seed. service: "host:port" of an sfcsampler-server for the
    workers to sample on (default: the embedded sampler in each worker). send_bytes: ship
    model files' bytes from here (default: workers read the paths). models_per_task: models
    in one task (0 = about a quarter of an even share per worker, at most 64: a task then
    takes long enough for Dask's few milliseconds of overhead a task not to matter, and the
    workers still balance); the results do not depend on it. progress: a bar on stderr (None
    = when it is a terminal). Returns sfcsampler.Results in the models' order.
    """
    for bad in ("surface", "mesh"):
        if bad in request:
            raise TypeError(f"sample_many takes the models as its second argument, not {bad}=")
    items = many.as_models(models)
    many.columns_list(request)
    paths = [None] * len(items)
    if out_dir is not None:
        os.makedirs(out_dir, exist_ok=True)
        paths = [os.path.join(out_dir, o) for o in many.output_names([m.name for m in items])]
    keep = out_dir is None if keep is None else keep
    shipped = []
    for m in items:
        if m.path is None or send_bytes:
            try:
                fmt, data = m.load()  # meshes: their canonical PLY, checked here
                m = _Bytes(m.name, fmt, data)
            except (OSError, ValueError, TypeError):
                pass  # the task reports the error by the model's name
        shipped.append(m)
    if not models_per_task:
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        models_per_task = max(1, min(64, len(shipped) // (4 * workers)))
    futures = []
    call = uuid.uuid4().hex[:12]  # keys unique to this call: Dask would reuse a live key's result
    chunks = [slice(start, start + models_per_task)
              for start in range(0, len(shipped), models_per_task)]
    # Each chunk's models go to the workers as data (a few MB of mesh bytes), not in the graph.
    data = client.scatter([shipped[chunk] for chunk in chunks], hash=False)
    for chunk, models_data in zip(chunks, data):
        start = chunk.start
        futures.append(client.submit(_many_task, models_data, request, seed, paths[chunk], keep,
                                     service, pure=False, key=f"sfcsampler-models-{call}-{start}"))
    _progress(futures, len(shipped), progress)
    return many.Results([r for chunk in client.gather(futures) for r in chunk])


def _shard_task(model, surface, count, index, shards, out_path, request, service):
    """Shard `index` of `shards`: its samples, or (path, count) once written."""
    if service:
        c = _client(service)
        if model is not None:
            surface = c.upload_bytes(model[0], model[1], "shard model")
        samples = c.sample(surface=surface, count=count, shard=(index, shards), **request)
    elif model is not None:
        samples = _sampler().sample_bytes(model[0], model[1], "shard model", count=count,
                                          shard=(index, shards), **request)
    else:
        samples = _sampler().sample(surface=surface, count=count, shard=(index, shards), **request)
    if out_path is None:
        return samples
    os.makedirs(os.path.dirname(out_path) or ".", exist_ok=True)
    many.write_npy(out_path, samples)
    return out_path, len(samples), int(samples.begin), int(samples.end)


def shard_path(out_dir, index, shards):
    """OUT_DIR/shard-IIIII-of-KKKKK.npy: the file of shard `index`."""
    return os.path.join(out_dir, f"shard-{index:05d}-of-{shards:05d}.npy")


def sample_shards(client, surface=None, count=10000, *, shards, out_dir=None, mesh=None,
                  service=None, **request):
    """One large set split into `shards` curve-order shards, one Dask task each.

    Shard i holds the samples of indices [i*count/K, (i+1)*count/K) (the CLI's --shard i/K),
    a contiguous stretch of the curve, so the shards concatenated in order are byte for byte
    the set one process makes. surface: a catalogue spec or a model file "FORMAT:PATH" (its
    bytes are read here and sent to the workers once); or mesh=(vertices, faces) as in
    sample(). out_dir: write OUT_DIR/shard-IIIII-of-KKKKK.npy (the CLI's NPY) and return
    [(path, samples, begin, end)]; else return the shards' Samples. service: sample on an
    sfcsampler-server instead of in the workers. Other keywords as sample() (seed, density,
    normals, sequence, ...; not begin, end, shard or region).
    """
    for bad in ("begin", "end", "shard", "region"):
        if request.get(bad):
            raise TypeError(f"sample_shards makes the shards itself; {bad}= is not taken")
    if not isinstance(shards, int) or shards < 1:
        raise InvalidArgumentError(3, f"shards must be an int >= 1, not {shards!r}")
    if (surface is None) == (mesh is None):
        raise TypeError("give either surface=... or mesh=...")
    model = None
    if mesh is not None:
        request, ply = meshes.resolve(dict(request, mesh=mesh))
        model = ("ply", ply)
    else:
        fmt, colon, reference = surface.partition(":")
        if colon and fmt in many.EXTENSIONS.values() and not reference.startswith("sha256="):
            with open(reference, "rb") as f:
                model = (fmt, f.read())
    if model is not None:
        # Once to each worker, not per task; hash=False: a fresh key (a scatter of the same bytes
        # would share the key of an earlier call's future, which Dask may be releasing).
        [model] = client.scatter([model], broadcast=True, hash=False)
    call = uuid.uuid4().hex[:12]
    futures = [client.submit(_shard_task, model, surface, count, i, shards,
                             None if out_dir is None else shard_path(out_dir, i, shards), request,
                             service, pure=False, key=f"sfcsampler-shard-{call}-{i}-of-{shards}")
               for i in range(shards)]
    return client.gather(futures)


def load_shards(paths):
    """The shard files concatenated in order: one structured array (what one run's NPY holds)."""
    return np.concatenate([np.load(p) for p in paths])
