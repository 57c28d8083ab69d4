"""Nearest-neighbour spacing relative to hexagonal packing, shared by the blue-noise scripts.

The hexagonal packing of n points on a surface of area A has spacing
sqrt(2 A / (sqrt(3) n)); blue-noise figures (issue 35) are a point set's minimum and
mean nearest-neighbour distances divided by it.
"""
import numpy as np
from scipy.spatial import cKDTree


def hex_spacing(n, area):
    """The nearest-neighbour distance of n points in hexagonal packing on area `area`."""
    return np.sqrt(2 * area / (np.sqrt(3) * n))


def nn(points, area, n_norm=None):
    """(min, mean) nearest-neighbour distance of `points` (rows, any dimension:
    chords on a curved surface) over hex_spacing(n_norm or len(points), area)."""
    d, _ = cKDTree(points).query(points, k=2)
    s = hex_spacing(n_norm or len(points), area)
    return d[:, 1].min() / s, d[:, 1].mean() / s
