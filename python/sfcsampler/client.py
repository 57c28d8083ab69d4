"""sfcsampler.Client: the same samples as sfcsampler.sample(), from a server.

Speaks sfcsampler.v1 (proto/sfcsampler/v1/sampler.proto) through Debian's
python3-grpcio with stubs generated from our proto at build time. Like the
C++ client (client/sampler_client.h) it sends x-surface-key (request/routing_key.h)
for consistent-hash proxies and the bearer token; it resumes a stream broken
by UNAVAILABLE (or a proxy's RST_STREAM) from the first index not yet
received, checks that a resumed stream comes from the same tree and
algorithm version as the first, and that no sample went missing.

A Client may be used from several threads at once (grpc channels are
thread-safe); each batches() iterator belongs to one thread.
"""

import hashlib
import os
import time

import grpc
import numpy as np

from sfcsampler import _core, _wire, meshes
from sfcsampler._request import make_request
from sfcsampler.errors import DataLossError, InvalidArgumentError, from_status
from sfcsampler.samples import Samples, concatenate, kept_columns, select, warn_depth_cap
from sfcsampler.v1 import sampler_pb2 as pb
from sfcsampler.v1 import sampler_pb2_grpc

_CURVES = {"hilbert": pb.CURVE_HILBERT, "hilbert2": pb.CURVE_HILBERT2, "peano": pb.CURVE_PEANO}
_ESTIMATORS = {"fff": pb.AREA_ESTIMATOR_FFF, "triangle": pb.AREA_ESTIMATOR_TRIANGLE,
               "square": pb.AREA_ESTIMATOR_SQUARE, "quadrature": pb.AREA_ESTIMATOR_QUADRATURE}
_SEQUENCES = {"jittered": pb.SEQUENCE_JITTERED, "equal": pb.SEQUENCE_EQUAL,
              "random": pb.SEQUENCE_RANDOM, "vandercorput": pb.SEQUENCE_VAN_DER_CORPUT,
              "progressive": pb.SEQUENCE_PROGRESSIVE, "blue": pb.SEQUENCE_BLUE}
_PRECISIONS = {"float64": pb.PRECISION_FLOAT64, "float32": pb.PRECISION_FLOAT32}
_ENCODINGS = {"raw": pb.COLUMN_ENCODING_RAW, "packed": pb.COLUMN_ENCODING_PACKED}
_MODEL_FORMATS = ("step", "iges", "nurbs", "obj", "ply")
_UPLOAD_CHUNK = 1 << 20  # the server takes chunks of up to 1 MiB


def _model_key(fmt, digest):
    """x-surface-key of every request about a model (FindModel, UploadModel,
    and the Sample/Prepare naming it): "FORMAT:sha256=<hex>", as the C++
    client's ModelRoutingKey (engine/model_source.h), so that behind a
    consistent-hash proxy all of them reach the replica storing the model."""
    return f"{fmt}:sha256={digest.lower()}"


def _routing_key(request):
    """The key for a request: its model's, or its tree key."""
    fmt, colon, reference = request.surface.strip().partition(":")
    if colon and fmt in _MODEL_FORMATS and reference.strip().startswith("sha256="):
        return _model_key(fmt, reference.strip()[len("sha256="):])
    return request.surface_key


def _tree_spec(request, spec):
    spec.surface = request.surface
    spec.density = request.density
    spec.curve = _CURVES[request.curve]
    spec.estimator = _ESTIMATORS[request.estimator]
    spec.tolerance = request.tolerance
    spec.depth_cap = request.depth_cap
    spec.rho = request.rho


def _error(rpc_error, suffix=""):
    code = rpc_error.code() if hasattr(rpc_error, "code") else grpc.StatusCode.UNKNOWN
    return from_status(code.value[0], (rpc_error.details() or str(code)) + suffix)


def _wire_columns(req, kept):
    """The columns to ask the server for: those the request makes, less the float columns
    `kept` (kept_columns()) leaves out; u and v stay when no other float column would (the
    wire needs one)."""
    made = [name for name, on in (("u", 1), ("v", 1), ("x", 1), ("y", 1), ("z", 1),
                                  ("nx", req.normals), ("ny", req.normals), ("nz", req.normals),
                                  ("density", req.density_column),
                                  ("curve_position", req.curve_position),
                                  ("face", req.face), ("triangle", req.triangle)) if on]
    if kept is None:
        return made
    # face and triangle stay as asked: the server refuses them on a surface without faces or
    # triangles, as sfcsampler.sample() does, whatever columns= keeps.
    model = ("face", "triangle")
    sent = [name for name in made if name in kept or name in model]
    if all(name in model for name in sent):
        sent = ["u", "v"] + sent
    return sent


class Client:
    """A connection to an sfcsampler-server.

    Client("host:port", token=None, tls=False, tls_roots=None, timeout=None,
           precision="float64", batch_size=0, max_resumes=5, resume_backoff=0.2,
           encoding="raw")

    token: bearer token (the server's --token-file contents). tls: connect
    with TLS (system roots); tls_roots: a PEM file of roots to trust (implies
    TLS). timeout: seconds per call (None = none). precision: "float64" or
    "float32" on the wire (float32 halves the bytes; the values are the
    float64 ones rounded). batch_size: samples per message (0: as many as fit
    the server's max_message_bytes with the requested columns). A stream broken
    by UNAVAILABLE is resumed up to max_resumes times, waiting resume_backoff
    seconds first and doubling. encoding: how columns travel, "raw"
    (little-endian bytes columns) or "packed" (repeated fields); both decode
    with one numpy.frombuffer a column, and a server that predates raw
    columns sends packed ones whatever is asked.
    """

    def __init__(self, target, token=None, tls=False, tls_roots=None, timeout=None,
                 precision="float64", batch_size=0, max_resumes=5, resume_backoff=0.2,
                 encoding="raw"):
        if precision not in _PRECISIONS:
            raise InvalidArgumentError(3, "precision must be float64 or float32")
        if encoding not in _ENCODINGS:
            raise InvalidArgumentError(3, "encoding must be raw or packed")
        self._encoding = _ENCODINGS[encoding]
        options = [("grpc.max_receive_message_length", -1)]
        if tls or tls_roots:
            roots = None
            if tls_roots:
                try:
                    with open(tls_roots, "rb") as f:
                        roots = f.read()
                except OSError as e:
                    raise InvalidArgumentError(
                        3, f'cannot read TLS roots "{tls_roots}": {e}') from e
            self._channel = grpc.secure_channel(target, grpc.ssl_channel_credentials(roots),
                                                options)
        else:
            self._channel = grpc.insecure_channel(target, options)
        self._stub = sampler_pb2_grpc.SamplerStub(self._channel)
        # Raw bytes, decoded by _wire into arrays without per-value objects.
        self._sample_rpc = self._channel.unary_stream(
            "/sfcsampler.v1.Sampler/Sample", request_serializer=pb.SampleRequest.SerializeToString,
            response_deserializer=None)
        self._token = token
        self._timeout = timeout
        self._precision = precision
        self._batch_size = batch_size
        self._max_resumes = max_resumes
        self._resume_backoff = resume_backoff
        self.resumes = 0  # streams resumed so far, over all calls

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _metadata(self, surface_key):
        metadata = [("x-surface-key", surface_key)]
        if self._token:
            metadata.append(("authorization", "Bearer " + self._token))
        return metadata

    def upload(self, spec):
        """Makes sure the server holds the model FORMAT:PATH (step, iges, nurbs, obj, ply).

        Hashes the file, asks the server whether it has those bytes, uploads
        them only if not, and returns "FORMAT:sha256=<hex>", the spec the
        server knows the model by. Other specs are returned unchanged.
        """
        fmt, colon, reference = spec.partition(":")
        if not colon or fmt not in _MODEL_FORMATS:
            return spec
        local = None
        if reference.startswith("sha256="):
            digest = reference[len("sha256="):]
        else:
            try:
                with open(reference, "rb") as f:
                    local = f.read()
            except OSError as e:
                raise InvalidArgumentError(3, f'cannot read the model "{reference}": {e}') from e
            digest = hashlib.sha256(local).hexdigest()
        return self._upload_bytes(fmt, local, digest, os.path.basename(reference))

    def upload_mesh(self, mesh, weights=None):
        """Makes sure the server holds a mesh given as arrays (see sfcsampler.sample's mesh=);
        uploads its canonical PLY bytes only if the server lacks them, and returns
        "ply:sha256=<hex>"."""
        data = meshes.mesh_ply(mesh, weights)
        return self._upload_bytes("ply", data, hashlib.sha256(data).hexdigest(), "mesh (arrays)")

    def _upload_bytes(self, fmt, local, digest, name):
        """FindModel, then UploadModel of `local` (None: only look) when the server lacks it."""
        metadata = self._metadata(_model_key(fmt, digest))
        try:
            return self._stub.FindModel(pb.FindModelRequest(sha256=digest, format=fmt),
                                        timeout=self._timeout, metadata=metadata).spec
        except grpc.RpcError as e:
            if e.code() != grpc.StatusCode.NOT_FOUND or local is None:
                raise _error(e) from None

        def chunks():
            for offset in range(0, max(len(local), 1), _UPLOAD_CHUNK):
                first = offset == 0
                yield pb.ModelChunk(format=fmt if first else "", name=name if first else "",
                                    total_bytes=len(local) if first else 0,
                                    data=local[offset:offset + _UPLOAD_CHUNK])
        try:
            return self._stub.UploadModel(chunks(), timeout=self._timeout, metadata=metadata).spec
        except grpc.RpcError as e:
            raise _error(e, _core.upload_cut_hint(e.details() or "", len(local))) from None

    def _with_model(self, request):
        """`request` with a model file's surface, or a mesh=... in memory, replaced by the spec
        the server knows it by."""
        request, ply = meshes.resolve(request)
        if ply is not None:
            spec = self._upload_bytes("ply", ply, hashlib.sha256(ply).hexdigest(), "mesh (arrays)")
            return dict(request, surface=spec)
        surface = request.get("surface")
        if isinstance(surface, str):
            uploaded = self.upload(surface)
            if uploaded != surface:
                request = dict(request, surface=uploaded)
        return request

    def _wire_request(self, request, precision, batch_size, begin_end, sent):
        w = pb.SampleRequest()
        _tree_spec(request, w.tree)
        w.sequence = _SEQUENCES[request.sequence]
        w.count = request.count
        w.seed = request.seed
        w.tree_count = request.tree_count
        if begin_end is None:
            w.begin, w.end = request.begin, request.end
            w.shard_index, w.shard_count = request.shard_index, request.shard_count
        else:  # a resume: the rest of the resolved range
            w.begin, w.end = begin_end
        region = request.region
        if region is not None and region[0] == "uv":
            r = w.parameter_rect
            r.u0, r.u1, r.v0, r.v1 = region[1:]
        elif region is not None:
            b = w.box
            b.min_x, b.min_y, b.min_z, b.max_x, b.max_y, b.max_z = region[1:]
        w.normals = any(c in sent for c in ("nx", "ny", "nz"))
        w.density = "density" in sent
        w.curve_position = "curve_position" in sent
        w.face = "face" in sent
        w.triangle = "triangle" in sent
        w.omit_uv = "u" not in sent and "v" not in sent
        w.omit_xyz = not any(c in sent for c in ("x", "y", "z"))
        w.precision = _PRECISIONS[precision]
        w.batch_size = batch_size
        w.column_encoding = self._encoding
        return w

    def batches(self, *, precision=None, batch_size=None, columns=None, **request):
        """Yields the requested samples as Samples, one per message, in curve order.

        The keywords are sfcsampler.sample()'s. Resumes after UNAVAILABLE
        (each sample is yielded once); raises sfcsampler.Error subclasses with
        the server's status code and message.
        """
        kept = kept_columns(columns, request)
        for part in self._stream(precision, batch_size, request, kept):
            if len(part):
                yield part

    def _stream(self, precision, batch_size, request, kept=None):
        """batches(), plus one empty Samples (with the tree) at the end when nothing arrived.
        Columns `kept` (kept_columns()) leaves out are not sent."""
        precision = precision or self._precision
        if precision not in _PRECISIONS:
            raise InvalidArgumentError(3, "precision must be float64 or float32")
        batch_size = batch_size or self._batch_size
        req = make_request(self._with_model(request))
        requested = _wire_columns(req, kept)
        range_end = req.index_range[1]
        metadata = self._metadata(_routing_key(req))
        first = None          # the first stream's header
        tree = None
        received = 0
        last_index = None
        skip = 0              # non-monotone resumes re-read the set and skip what arrived
        resume_range = None   # monotone resumes ask for the rest of the range
        backoff = self._resume_backoff
        for attempt in range(self._max_resumes + 1):
            wire = self._wire_request(req, precision, batch_size, resume_range, requested)
            call = self._sample_rpc(wire, timeout=self._timeout, metadata=metadata)
            this_stream = 0
            try:
                for raw in call:
                    header, columns = _wire.decode_response(raw, requested)
                    if header is not None:
                        if first is None:
                            first = header
                            tree = _wire.message_dict(header.tree)
                            warn_depth_cap(tree, stacklevel=3)
                        elif (header.tree.key != first.tree.key or
                              header.algorithm_version != first.algorithm_version):
                            raise DataLossError(15, (
                                f"the resumed stream comes from tree {header.tree.key} "
                                f"({header.algorithm_version}), the first from {first.tree.key} "
                                f"({first.algorithm_version}); the samples would not continue "
                                "the set"))
                    n = len(columns["index"])
                    if n and first is None:
                        raise DataLossError(15, "samples arrived before the stream's header")
                    this_stream += n
                    if skip:
                        drop = min(skip, n)
                        skip -= drop
                        columns = {k: v[drop:] for k, v in columns.items()}
                        n -= drop
                    if n == 0:
                        continue
                    received += n
                    last_index = int(columns["index"][-1])
                    yield Samples(select(columns, kept), tree, first.begin, first.end, first.seed,
                                  first.algorithm_version,
                                  np.float32 if precision == "float32" else np.float64, kept)
            except grpc.RpcError as e:
                details = e.details() or ""
                # Behind a proxy, the replica after a dead one lacks the model:
                # upload it there again (a local file) and resume.
                model_moved = (e.code() == grpc.StatusCode.NOT_FOUND and attempt > 0 and
                               isinstance(request.get("surface"), str) and
                               request["surface"] != req.surface)
                resumable = (e.code() == grpc.StatusCode.UNAVAILABLE or model_moved or
                             (e.code() == grpc.StatusCode.INTERNAL and "RST_STREAM" in details))
                if not resumable or attempt == self._max_resumes:
                    where = f", last index {last_index}" if received else ""
                    raise _error(e, f" (received {received} samples{where})") from None
                self.resumes += 1
                time.sleep(backoff)
                backoff *= 2
                if model_moved:
                    self.upload(request["surface"])
                if req.monotone and received:
                    resume_range = (last_index + 1, range_end)
                elif not req.monotone:
                    skip = received
                continue
            finally:
                call.cancel()  # a no-op after the end; stops the stream if the caller left early
            sent = dict(call.trailing_metadata() or ()).get("x-samples-sent")
            if sent is not None and int(sent) != this_stream:
                raise DataLossError(15, f"the server sent {sent} samples but {this_stream} arrived")
            if (first is not None and first.expected_samples >= 0
                    and received != first.expected_samples):
                raise DataLossError(
                    15, f"expected {first.expected_samples} samples, received {received}")
            if received == 0 and first is not None:  # e.g. a region with no samples
                yield Samples({}, tree, first.begin, first.end, first.seed, first.algorithm_version,
                              np.float32 if precision == "float32" else np.float64, kept)
            return

    def sample(self, *, precision=None, batch_size=None, columns=None, **request):
        """All the requested samples as one Samples: the same values as sfcsampler.sample()."""
        kept = kept_columns(columns, request)
        precision = precision or self._precision
        parts = list(self._stream(precision, batch_size, request, kept))
        if not parts:
            raise DataLossError(15, "the stream ended without a header or samples")
        last = parts[-1]
        filled = [p.columns() for p in parts if len(p)]
        return concatenate(filled, last.tree, last.begin, last.end, last.seed,
                           last.algorithm_version,
                           np.float32 if precision == "float32" else np.float64, kept)

    def prepare(self, **request):
        """Builds (or finds in the server's cache) the request's tree; returns its summary."""
        req = make_request(self._with_model(request))
        w = pb.PrepareRequest(count=req.tree_count or req.count)
        _tree_spec(req, w.tree)
        try:
            response = self._stub.Prepare(w, timeout=self._timeout,
                                          metadata=self._metadata(_routing_key(req)))
        except grpc.RpcError as e:
            raise _error(e) from None
        tree = _wire.message_dict(response.tree)
        warn_depth_cap(tree, stacklevel=3)
        return tree

    def health(self, service="", timeout=5.0):
        """True when the server reports SERVING (grpc.health.v1 Check; needs no token).

        The two small messages are encoded here by hand (HealthCheckRequest:
        field 1 the service name; HealthCheckResponse: field 1 the status, 1 =
        SERVING) since grpcio's health package is not in Debian.
        """
        name = service.encode()
        request = (b"\x0a" + _wire.encode_varint(len(name)) + name) if name else b""
        check = self._channel.unary_unary("/grpc.health.v1.Health/Check", request_serializer=None,
                                          response_deserializer=None)
        try:
            response = check(request, timeout=timeout)
        except grpc.RpcError as e:
            raise _error(e) from None
        status = dict((number, value) for number, _, value in _wire.fields(memoryview(response)))
        return status.get(1, 0) == 1

    def cache_stats(self):
        """The server's tree-cache counters and limits, as a dict."""
        try:
            stats = self._stub.GetCacheStats(pb.GetCacheStatsRequest(), timeout=self._timeout,
                                             metadata=self._metadata(""))
        except grpc.RpcError as e:
            raise _error(e) from None
        return _wire.message_dict(stats)

    def catalog(self):
        """The server's surfaces and densities, as a dict."""
        try:
            response = self._stub.ListCatalog(pb.ListCatalogRequest(), timeout=self._timeout,
                                              metadata=self._metadata(""))
        except grpc.RpcError as e:
            raise _error(e) from None
        return _wire.message_dict(response)
