"""sfcsampler: density-controlled, low-discrepancy samples on parametric surfaces.

The method of Quinn, Langbein, Martin and Elber (GMP 2006): a jittered 1D
sequence placed along an adaptive space-filling curve. Two ways in, one
result:

    import sfcsampler
    s = sfcsampler.sample(surface="torus", density="gaussian:floor=0.05", count=10**6)
    s.x, s.y, s.z, s.u, s.v, s.index          # NumPy arrays, in curve order

    with sfcsampler.Client("127.0.0.1:50051") as c:
        t = c.sample(surface="torus", density="gaussian:floor=0.05", count=10**6)
    # the same values as s

The keywords are `sfcsampler sample`'s flags; the same request gives the same
numbers as the CLI, embedded or from a server. Errors are sfcsampler.Error
subclasses carrying the status code and message.
"""

from sfcsampler._core import ALGORITHM_VERSION, densities, surfaces
from sfcsampler.embedded import Sampler, batches, prepare, sample
from sfcsampler.many import Result, Results, model_seed, sample_many
from sfcsampler.meshes import write_ply
from sfcsampler.errors import (DataLossError, DeadlineExceededError, DepthCapWarning, Error,
                               InvalidArgumentError, ResourceExhaustedError, UnauthenticatedError,
                               UnavailableError)
from sfcsampler.samples import Samples


def __getattr__(name):
    """Client on first use: the client extension (_client, with gRPC) loads only when a
    server is used (PEP 562)."""
    if name == "Client":
        from sfcsampler.client import Client
        globals()["Client"] = Client
        return Client
    raise AttributeError(f"module 'sfcsampler' has no attribute {name!r}")


__all__ = [
    "ALGORITHM_VERSION", "Client", "Result", "Results", "model_seed", "sample_many", "write_ply",
    "DataLossError", "DeadlineExceededError", "DepthCapWarning",
    "Error", "InvalidArgumentError", "ResourceExhaustedError", "Samples", "Sampler",
    "UnauthenticatedError", "UnavailableError", "batches", "densities", "prepare", "sample",
    "surfaces",
]
