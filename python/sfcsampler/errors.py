"""Exceptions raised by sfcsampler, embedded or over gRPC.

Every failure is an `Error` carrying the canonical status code (the same
numbering as gRPC and absl::Status) and the engine's or server's message,
which says what to fix. Common codes have their own subclasses, which also
derive from the matching built-in exception (an InvalidArgumentError is a
ValueError), so ordinary `except ValueError` code works too.
"""

_CODE_NAMES = {
    0: "OK", 1: "CANCELLED", 2: "UNKNOWN", 3: "INVALID_ARGUMENT", 4: "DEADLINE_EXCEEDED",
    5: "NOT_FOUND", 6: "ALREADY_EXISTS", 7: "PERMISSION_DENIED", 8: "RESOURCE_EXHAUSTED",
    9: "FAILED_PRECONDITION", 10: "ABORTED", 11: "OUT_OF_RANGE", 12: "UNIMPLEMENTED",
    13: "INTERNAL", 14: "UNAVAILABLE", 15: "DATA_LOSS", 16: "UNAUTHENTICATED",
}


class Error(Exception):
    """A failed request: `code` (e.g. "INVALID_ARGUMENT"), `code_value` (3) and `message`."""

    def __init__(self, code_value, message):
        self.code_value = int(code_value)
        self.code = _CODE_NAMES.get(self.code_value, str(self.code_value))
        self.message = message
        super().__init__(f"{self.code}: {message}")


class InvalidArgumentError(Error, ValueError):
    """The request is malformed or outside a limit; the message names the argument."""


class ResourceExhaustedError(Error, MemoryError):
    """A budget was reached (tree leaves, stream slots)."""


class UnavailableError(Error, ConnectionError):
    """The server could not be reached (after the client's resumes)."""


class UnauthenticatedError(Error, PermissionError):
    """The server wants a (different) bearer token."""


class DeadlineExceededError(Error, TimeoutError):
    """The request took longer than its deadline."""


class DataLossError(Error):
    """Samples went missing or a resumed stream did not continue the first."""


_CLASSES = {3: InvalidArgumentError, 4: DeadlineExceededError, 8: ResourceExhaustedError,
            11: InvalidArgumentError, 14: UnavailableError, 15: DataLossError,
            16: UnauthenticatedError}


def from_status(code_value, message):
    """The exception for a canonical status code and message."""
    return _CLASSES.get(int(code_value), Error)(code_value, message)


class DepthCapWarning(UserWarning):
    """The depth cap stopped splits the tree's tests still wanted (paper Sect. 5.3):
    near a singularity the density there is only approximate."""
