"""The request keywords shared by sample(), Sampler, and Client, checked
before the C++ parser (which reads them exactly as the CLI reads its flags)."""

from sfcsampler import _core

# The CLI's sample flags without dashes, '-' as '_' (request/request_flags.h).
KEYWORDS = ("surface", "density", "curve", "estimator", "tolerance", "depth_cap", "rho", "count",
            "seed", "sequence", "tree_count", "begin", "end", "shard", "region", "normals",
            "density_column", "curve_position", "face", "triangle")
_TEXT = {"surface", "density", "curve", "estimator", "sequence", "region"}
_UNSIGNED = {"count", "seed", "tree_count", "begin", "end"}


def make_request(request):
    """A _core.Request from keywords; TypeError names an unknown keyword or a wrong type,
    sfcsampler.InvalidArgumentError a bad value."""
    unknown = sorted(set(request) - set(KEYWORDS))
    if unknown:
        raise TypeError(
            f"unknown request keyword{'s' if len(unknown) > 1 else ''} {', '.join(unknown)};"
            f" the keywords are {', '.join(KEYWORDS)} (the CLI's flags)")
    try:
        return _core.Request(**request)
    except TypeError:
        for name, value in request.items():
            if name in _TEXT and not isinstance(value, str):
                raise TypeError(f"{name} must be a str, not {type(value).__name__}") from None
            if name in _UNSIGNED and (isinstance(value, bool) or not isinstance(value, int)
                                      or value < 0):
                raise TypeError(f"{name} must be a non-negative int, got {value!r}") from None
        raise
