"""The examples in examples/ run as users run them, and show what they claim."""

import os
import re
import subprocess
import sys

import numpy as np


EXAMPLES = os.path.join(os.environ.get("SFC_SOURCE_DIR", "."), "examples")


def run_example(name, *args):
    done = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_monte_carlo_error_falls_faster_than_iid(tmp_path):
    out = run_example("monte_carlo.py", "--min-exp", "6", "--max-exp", "14", "--seeds", "8",
                      "--out", str(tmp_path / "mc.png"))
    iid, ours = map(float, re.search(r"i\.i\.d\. (-?[\d.]+), sfcsampler (-?[\d.]+)", out).groups())
    assert -0.8 < iid < -0.3, out          # the N^-1/2 of independent points
    assert ours < iid - 0.25 and ours < -0.75, out
    assert (tmp_path / "mc.png").read_bytes()[:4] == b"\x89PNG"


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    count = int(re.search(rb"element vertex (\d+)", data[:end]).group(1))
    dtype = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4"),
             ("index", "<u4")]
    return np.frombuffer(data[end:], dtype=dtype, count=count)


def test_torus_curvature_writes_ply_and_picture(tmp_path, server):
    out = run_example("torus_curvature.py", "--count", "30000", "--out", str(tmp_path / "t"))
    vertices = read_ply(tmp_path / "t.ply")
    assert len(vertices) == 30000 and np.array_equal(vertices["index"], np.arange(30000))
    normals = np.column_stack((vertices["nx"], vertices["ny"], vertices["nz"]))
    assert np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-5)
    # Curvature density: far more than the area share (about half) lands where |K| is large.
    share = float(re.search(r"([\d.]+)% where", out).group(1)) / 100
    assert share > 0.6, out
    assert (tmp_path / "t.png").read_bytes()[:4] == b"\x89PNG"
    # The same file through a server.
    run_example("torus_curvature.py", "--count", "30000", "--out", str(tmp_path / "w"), "--server",
                server)
    assert (tmp_path / "w.ply").read_bytes() == (tmp_path / "t.ply").read_bytes()
