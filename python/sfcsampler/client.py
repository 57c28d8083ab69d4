"""sfcsampler.Client: the same samples as sfcsampler.sample(), from a server.

The protocol is the C++ client library's (client/sampler_client.h), bound as
the extension sfcsampler._client (python/bindings/client.cc), which this module
loads: the same request encoding, the x-surface-key routing header and bearer
token, resumes of a stream broken by UNAVAILABLE (or a proxy's RST_STREAM)
from the first index not yet received, the checks that a resumed stream comes
from the same tree, algorithm version and seed as the first and that no
sample went missing, and model uploads, as the CLI's --server. Each batch's
columns reach NumPy without a copy beyond the one out of the message.

A Client may be used from several threads at once; each batches() iterator
belongs to one thread.
"""

from sfcsampler import _client, meshes
from sfcsampler._request import make_request
from sfcsampler.samples import (Samples, column_dtype, concatenate, kept_columns, select,
                                warn_depth_cap)


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
    (little-endian bytes columns) or "packed" (repeated fields); a server that
    predates raw columns sends packed ones whatever is asked.

    resumes and wire_bytes count, over the calls that finished, the streams
    resumed and the bytes of the messages received.
    """

    def __init__(self, target, token=None, tls=False, tls_roots=None, timeout=None,
                 precision="float64", batch_size=0, max_resumes=5, resume_backoff=0.2,
                 encoding="raw"):
        self._client = _client.Client(target, token=token or "", tls=tls,
                                      tls_roots=tls_roots or "", timeout=timeout or 0,
                                      precision=precision, batch_size=batch_size,
                                      max_resumes=max_resumes, resume_backoff=resume_backoff,
                                      encoding=encoding)
        self._precision = precision
        self.resumes = 0
        self.wire_bytes = 0

    def close(self):
        self._client.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def upload(self, spec):
        """Makes sure the server holds the model FORMAT:PATH (step, iges, nurbs, obj, ply).

        Hashes the file, asks the server whether it has those bytes, uploads
        them only if not, and returns "FORMAT:sha256=<hex>", the spec the
        server knows the model by. Other specs are returned unchanged.
        """
        return self._client.upload(spec)

    def upload_bytes(self, fmt, data, name=""):
        """Makes sure the server holds a model given as its file's bytes (fmt: step, iges,
        nurbs, obj, ply; name for messages): uploads them only if the server lacks them, and
        returns "FORMAT:sha256=<hex>"."""
        return self._client.upload_bytes(fmt, data, name)

    def upload_mesh(self, mesh, weights=None):
        """Makes sure the server holds a mesh given as arrays (see sfcsampler.sample's mesh=);
        uploads its canonical PLY bytes only if the server lacks them, and returns
        "ply:sha256=<hex>"."""
        return self.upload_bytes("ply", meshes.mesh_ply(mesh, weights), "mesh (arrays)")

    def _parsed(self, request):
        """The parsed request, a mesh=... in memory replaced by the spec the server knows it
        by (a model file is uploaded by the C++ client, which can then upload it again to
        another replica on a resume)."""
        request, ply = meshes.resolve(request)
        if ply is not None:
            request = dict(request, surface=self.upload_bytes("ply", ply, "mesh (arrays)"))
        return make_request(request)

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
        stream = self._client.stream(self._parsed(request), precision=precision,
                                     batch_size=batch_size or 0,
                                     columns=sorted(kept) if kept is not None else [])
        header = None
        try:
            for columns in stream:
                if header is None:
                    header = stream.header
                    warn_depth_cap(header["tree"], stacklevel=3)
                yield self._samples(select(columns, kept), header, precision, kept)
        finally:
            stream.close()
            self.resumes += stream.resumes
            self.wire_bytes += stream.wire_bytes
        if header is None:  # e.g. a region with no samples
            header = stream.header
            warn_depth_cap(header["tree"], stacklevel=3)
            yield self._samples({}, header, precision, kept)

    @staticmethod
    def _samples(columns, header, precision, kept):
        return Samples(columns, header["tree"], header["begin"], header["end"], header["seed"],
                       header["algorithm_version"], column_dtype(precision), kept)

    def sample(self, *, precision=None, batch_size=None, columns=None, **request):
        """All the requested samples as one Samples: the same values as sfcsampler.sample()."""
        kept = kept_columns(columns, request)
        precision = precision or self._precision
        parts = list(self._stream(precision, batch_size, request, kept))
        last = parts[-1]  # a stream gives at least its header
        filled = [p.columns() for p in parts if len(p)]
        return concatenate(filled, last.tree, last.begin, last.end, last.seed,
                           last.algorithm_version, column_dtype(precision), kept)

    def prepare(self, **request):
        """Builds (or finds in the server's cache) the request's tree; returns its summary."""
        tree = self._client.prepare(self._parsed(request))
        warn_depth_cap(tree, stacklevel=3)
        return tree

    def health(self, service="", timeout=0):
        """True when the server reports SERVING (grpc.health.v1 Check; needs no token).
        timeout: seconds (0 = the client's deadline, or the client library's default without
        one)."""
        return self._client.health(service, timeout)

    def cache_stats(self):
        """The server's tree-cache counters and limits, as a dict."""
        return self._client.cache_stats()

    def catalog(self):
        """The server's surfaces and densities, as a dict."""
        return self._client.catalog()
