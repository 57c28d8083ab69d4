"""Samples: one request's points as NumPy columns (structure of arrays)."""

import warnings

import numpy as np

from sfcsampler.errors import DepthCapWarning, InvalidArgumentError

COLUMNS = ("index", "u", "v", "x", "y", "z", "nx", "ny", "nz", "density", "curve_position", "face",
           "triangle")
# The request flag that adds each optional column.
_COLUMN_FLAGS = {"nx": "normals", "ny": "normals", "nz": "normals", "density": "density_column",
                 "curve_position": "curve_position", "face": "face", "triangle": "triangle"}


def column_names(columns):
    """A `columns=` argument (a name or an iterable of names) as a list, read once;
    InvalidArgumentError for an unknown name or none."""
    names = [columns] if isinstance(columns, str) else list(columns)
    for name in names:
        if name not in COLUMNS:
            raise InvalidArgumentError(3, f"columns: unknown column {name!r}; the columns are "
                                          f"{', '.join(COLUMNS)}")
    if not names:
        raise InvalidArgumentError(3, "columns: name at least one column")
    return names


def column_dtype(precision):
    """The NumPy type of the value columns at `precision` ("float32" or "float64")."""
    return np.float32 if precision == "float32" else np.float64


def kept_columns(columns, request):
    """The set of column names a `columns=` argument keeps (None: every column the request
    makes). InvalidArgumentError for an unknown name, or one the request does not make
    (it names the flag that would)."""
    if columns is None:
        return None
    names = column_names(columns)
    for name in names:
        flag = _COLUMN_FLAGS.get(name)
        if flag and not request.get(flag):
            raise InvalidArgumentError(3, f"columns: {name!r} needs {flag}=True in the request")
    return frozenset(names)


def select(columns, kept):
    """The column dict without the columns `kept` (from kept_columns) leaves out; the arrays
    dropped are freed at once, so the next request reuses their memory."""
    if kept is None:
        return columns
    return {name: value for name, value in columns.items() if name in kept}


class Samples:
    """Samples in curve order, as NumPy arrays.

    index (uint64): each sample's index k in the set; u, v: unit-square
    parameters; x, y, z: the surface point; nx, ny, nz, density,
    curve_position when asked for, else None; face (CAD models) and triangle
    (meshes; u, v are then barycentric) as uint32 when asked for. Float columns are float64, or
    float32 with precision="float32". A column that columns=[...] left out is None. `tree` is
    the curve tree's summary (the wire's TreeInfo fields as a dict); `begin`, `end` the
    resolved index range; `seed` and `algorithm_version` identify the set.
    """

    def __init__(self, columns, tree, begin, end, seed, algorithm_version, dtype=np.float64,
                 kept=None):
        for name in COLUMNS:
            value = columns.get(name)
            if value is None and name in ("index", "u", "v", "x", "y", "z") and (
                    kept is None or name in kept):
                value = np.empty(0, dtype=np.uint64 if name == "index" else dtype)
            setattr(self, name, value)
        self.tree = tree
        self.begin = begin
        self.end = end
        self.seed = seed
        self.algorithm_version = algorithm_version

    def __len__(self):
        for name in COLUMNS:  # index, unless columns= left it out
            value = getattr(self, name)
            if value is not None:
                return len(value)
        return 0

    def __repr__(self):
        present = [c for c in COLUMNS if getattr(self, c) is not None]
        return (f"Samples({len(self)} samples, indices [{self.begin}, {self.end}), "
                f"tree {self.tree.get('key_with_grade')}, columns {', '.join(present)})")

    @property
    def points(self):
        """An (N, 3) array of x, y, z (a copy: the columns are stored separately)."""
        return np.column_stack((self.x, self.y, self.z))

    @property
    def normals(self):
        """An (N, 3) array of nx, ny, nz (a copy), or None without normals=True."""
        if self.nx is None:
            return None
        return np.column_stack((self.nx, self.ny, self.nz))

    @property
    def uv(self):
        """An (N, 2) array of u, v (a copy)."""
        return np.column_stack((self.u, self.v))

    def columns(self):
        """The present columns as a dict name -> array, in output order."""
        return {c: getattr(self, c) for c in COLUMNS if getattr(self, c) is not None}


def concatenate(parts, tree, begin, end, seed, algorithm_version, dtype, kept=None):
    """One Samples from batches of column dicts (copies each column once); `kept` as
    kept_columns() gives it, the parts already holding only those columns."""
    parts = [p for p in parts if p]
    if len(parts) == 1:
        columns = parts[0]
    else:
        columns = {}
        for name in COLUMNS:
            pieces = [p[name] for p in parts if name in p]
            if pieces:
                columns[name] = np.concatenate(pieces)
    return Samples(columns, tree, begin, end, seed, algorithm_version, dtype, kept)


def warn_depth_cap(tree, stacklevel=3):
    """Warns (DepthCapWarning) when the depth cap stopped splits; the CLI prints the same."""
    flat = tree.get("flatness_capped_leaves", 0)
    mass = tree.get("mass_capped_leaves", 0)
    if flat or mass:
        worst = tree.get("warnings") or []
        where = ""
        if worst:
            w = worst[0]
            where = (
                f"; worst: {w['test']} test at u in [{w['u0']:.9g}, {w['u0'] + w['size']:.9g}],"
                f" v in [{w['v0']:.9g}, {w['v0'] + w['size']:.9g}]:"
                f" {w['measured']:.6g} vs limit {w['limit']:.6g}")
        warnings.warn(DepthCapWarning(
            f"the depth cap stopped splits the tests still wanted (paper Sect. 5.3): {flat} leaves"
            f" for flatness, {mass} for mass{where}"), stacklevel=stacklevel)
