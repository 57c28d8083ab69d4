"""Figures over seeds, as the benchmark scripts report them: the mean with its standard
error, and the least-squares slope of log D against log N."""

import math

import numpy as np


def mean_se(values):
    """(mean, standard error of the mean) of the values; the error is NaN for one value."""
    a = np.asarray(values, dtype=float)
    if a.size < 2:
        return float(a.mean()), float("nan")
    return float(a.mean()), float(a.std(ddof=1) / math.sqrt(a.size))


def slope(ns, ds):
    """The least-squares slope of log ds against log ns."""
    return float(np.polyfit(np.log(ns), np.log(ds), 1)[0])
