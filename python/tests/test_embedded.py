"""sfcsampler.sample() (pybind11, in-process) against the CLI: the same
request gives the same numbers; bad input raises clear exceptions."""

import subprocess
import sys
import threading
import warnings

import numpy as np
import pytest

import sfcsampler
from conftest import CLI, assert_same, cli_columns, run_cli

# (Python keywords, the same request as CLI flags)
CASES = [
    (dict(surface="torus", density="gaussian:floor=0.1", count=20000, seed=4),
     ["--surface", "torus", "--density", "gaussian:floor=0.1", "--count", "20000", "--seed", "4"]),
    (dict(surface="sphere", count=20000, region="box:0,0,0,1,1,1", normals=True,
          curve_position=True),
     ["--surface", "sphere", "--count", "20000", "--region", "box:0,0,0,1,1,1", "--normals",
      "--curve-position"]),
    (dict(surface="plane", density="expr:u+v", count=5000, sequence="progressive", shard=(1, 3),
          density_column=True),
     ["--surface", "plane", "--density", "expr:u+v", "--count", "5000", "--sequence",
      "progressive", "--shard", "1/3", "--density-column"]),
    (dict(surface="eight", curve="peano", count=3000, begin=1000, end=2500, sequence="random"),
     ["--surface", "eight", "--curve", "peano", "--count", "3000", "--begin", "1000", "--end",
      "2500", "--sequence", "random"]),
    (dict(surface="torus", count=6000, sequence="blue", shard="2/5", normals=True),
     ["--surface", "torus", "--count", "6000", "--sequence", "blue", "--shard", "2/5",
      "--normals"]),
    (dict(surface="monkey_saddle", density="gaussian:floor=0.05", count=6000, seed=3,
          sequence="sobol", shard=(2, 4), curve_position=True),
     ["--surface", "monkey_saddle", "--density", "gaussian:floor=0.05", "--count", "6000",
      "--seed", "3", "--sequence", "sobol", "--shard", "2/4", "--curve-position"]),
]


@pytest.mark.parametrize("kwargs,flags", CASES)
def test_same_numbers_as_cli(kwargs, flags):
    assert_same(sfcsampler.sample(**kwargs), cli_columns(*flags))


def test_batches_concatenate_to_the_whole_set():
    whole = sfcsampler.sample(surface="torus", count=50000, normals=True)
    parts = list(sfcsampler.batches(surface="torus", count=50000, normals=True, batch_size=7000))
    assert [len(p) for p in parts] == [7000] * 7 + [1000]
    for name in ("index", "x", "nz"):
        assert np.array_equal(np.concatenate([getattr(p, name) for p in parts]),
                              getattr(whole, name))


def test_float32_is_the_float64_set_rounded():
    full = sfcsampler.sample(surface="torus", count=10000)
    half = sfcsampler.sample(surface="torus", count=10000, precision="float32")
    assert half.x.dtype == np.float32 and half.index.dtype == np.uint64
    assert np.array_equal(half.x, full.x.astype(np.float32))
    assert np.array_equal(half.index, full.index)


def test_columns_keeps_only_the_named_columns_with_the_same_values():
    full = sfcsampler.sample(surface="torus", count=5000, normals=True)
    points = sfcsampler.sample(surface="torus", count=5000, normals=True,
                               columns=("x", "y", "z", "nz"))
    assert len(points) == 5000
    for name in ("x", "y", "z", "nz"):
        assert np.array_equal(getattr(points, name), getattr(full, name)), name
    for name in ("index", "u", "v", "nx", "ny"):
        assert getattr(points, name) is None, name
    assert np.array_equal(points.points, full.points)
    assert list(points.columns()) == ["x", "y", "z", "nz"]
    parts = list(sfcsampler.batches(surface="torus", count=5000, batch_size=2000, columns="index"))
    assert [len(p) for p in parts] == [2000, 2000, 1000] and parts[0].x is None
    assert np.array_equal(np.concatenate([p.index for p in parts]), full.index)
    with pytest.raises(sfcsampler.InvalidArgumentError, match="unknown column 'w'"):
        sfcsampler.sample(count=10, columns=["x", "w"])
    with pytest.raises(sfcsampler.InvalidArgumentError, match="normals=True"):
        sfcsampler.sample(count=10, columns=["nx"])


def test_cli_columns_writes_only_those_columns(tmp_path):
    full = cli_columns("--surface", "torus", "--count", "3000", "--normals")
    some = cli_columns("--surface", "torus", "--count", "3000", "--normals", "--columns",
                       "nz,x,index")
    assert list(some) == ["index", "x", "nz"]  # the file's own order, whatever the flag's
    for name in some:
        assert np.array_equal(some[name], full[name]), name
    run_cli("sample", "--surface", "torus", "--count", "3000", "--format", "npy", "--columns",
            "x,y,z", "-q", "-o", str(tmp_path / "p.npy"))
    points = np.load(tmp_path / "p.npy")
    assert points.dtype.names == ("x", "y", "z")
    assert np.array_equal(points["y"], sfcsampler.sample(surface="torus", count=3000).y)
    for flags, words in ((["--columns", "x,w"], "unknown column"),
                         (["--columns", "nx"], "--normals"),
                         (["--columns", "u,v", "--format", "ply"], "x, y and z")):
        done = subprocess.run([CLI, "sample", "--count", "10", *flags, "-q", "-o", "-"],
                              capture_output=True, text=True)
        assert done.returncode != 0 and words in done.stderr, (flags, done.stderr)


def test_arrays_own_their_buffers_without_a_copy():
    s = sfcsampler.sample(count=1000)
    # The buffer belongs to a capsule (the C++ vector), not to a NumPy copy.
    assert not s.x.flags.owndata and type(s.x.base).__name__ == "PyCapsule"
    s.x[0] = 42.0  # writable, and it outlives the call
    assert s.x[0] == 42.0


def test_deterministic_and_independent_of_threads():
    a = sfcsampler.sample(surface="eight", count=100000, threads=1)
    b = sfcsampler.sample(surface="eight", count=100000, threads=3)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.index, b.index)


def test_sampler_reuses_its_tree():
    sampler = sfcsampler.Sampler(max_trees=2)
    first = sampler.sample(surface="torus", count=10000)
    second = sampler.sample(surface="torus", count=10000, seed=2)
    assert not first.tree["cache_hit"] and second.tree["cache_hit"]
    assert second.tree["key"] == first.tree["key"]
    assert np.array_equal(second.x, sfcsampler.sample(surface="torus", count=10000, seed=2).x)


def test_a_sampler_refills_freed_buffers_and_never_one_still_held():
    n = 200000  # 1.6 MB columns: pooled
    sampler = sfcsampler.Sampler(max_trees=1)
    held = sampler.sample(surface="torus", count=n)
    held_copy = {c: getattr(held, c).copy() for c in ("index", "u", "v", "x", "y", "z")}
    freed = sampler.sample(surface="torus", count=n, seed=2)
    freed_buffers = {getattr(freed, c).ctypes.data for c in ("index", "u", "v", "x", "y", "z")}
    del freed
    third = sampler.sample(surface="torus", count=n, seed=3, precision="float32")  # fills doubles
    again = sampler.sample(surface="torus", count=n, seed=2)
    # Buffers come back: the freed float64 set's memory holds the next float64 set.
    assert {getattr(again, c).ctypes.data for c in ("x", "y", "z")} <= freed_buffers
    # Never one a live array still owns, and the values are a fresh call's.
    for c, values in held_copy.items():
        assert np.array_equal(getattr(held, c), values)
        assert not np.shares_memory(getattr(held, c), getattr(again, c))
        assert not np.shares_memory(getattr(third, c), getattr(again, c))
    fresh = sfcsampler.sample(surface="torus", count=n, seed=2)
    for c in held_copy:
        assert np.array_equal(getattr(again, c), getattr(fresh, c))
    assert np.array_equal(third.x, sfcsampler.sample(surface="torus", count=n, seed=3,
                                                     precision="float32").x)


def test_gil_is_released_while_sampling():
    # Another Python thread keeps running while a large request fills.
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.001)

    t = threading.Thread(target=tick)
    t.start()
    before = len(ticks)
    sfcsampler.sample(surface="torus", count=2_000_000, threads=1)
    during = len(ticks) - before
    stop.set()
    t.join()
    assert during > 10


@pytest.mark.parametrize("kwargs,code,words", [
    (dict(surface="nope"), "INVALID_ARGUMENT", "unknown surface"),
    (dict(count=0), "INVALID_ARGUMENT", "count must be >= 1"),
    (dict(curve="zigzag"), "INVALID_ARGUMENT", "--curve must be"),
    (dict(shard="3/2"), "INVALID_ARGUMENT", "shard index 3"),
    (dict(region="disc:1"), "INVALID_ARGUMENT", "--region takes"),
    (dict(begin=10, end=5), "INVALID_ARGUMENT", "index range"),
    (dict(surface="expr:x=u;y=v;z=log(u-1)"), "INVALID_ARGUMENT", ""),
    (dict(precision="float16"), "INVALID_ARGUMENT", "precision"),
])
def test_bad_input_raises_a_clear_error(kwargs, code, words):
    with pytest.raises(sfcsampler.InvalidArgumentError) as info:
        sfcsampler.sample(**kwargs)
    assert info.value.code == code and info.value.code_value == 3
    assert words in info.value.message
    assert isinstance(info.value, ValueError)


def test_unknown_keyword_or_wrong_type_is_a_type_error():
    with pytest.raises(TypeError, match="unknown request keyword surfce"):
        sfcsampler.sample(surfce="sphere")
    with pytest.raises(TypeError, match="count must be a non-negative int"):
        sfcsampler.sample(count=-5)
    with pytest.raises(TypeError, match="surface must be a str"):
        sfcsampler.sample(surface=3)


def test_depth_cap_warns():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sfcsampler.sample(surface="sphere", count=100000, depth_cap=4)
    assert any(issubclass(w.category, sfcsampler.DepthCapWarning) for w in caught)


def test_catalog_lists_the_builtin_surfaces():
    names = {s["name"] for s in sfcsampler.surfaces()}
    assert {"sphere", "torus", "expr"} <= names
    assert "gaussian" in {d["name"] for d in sfcsampler.densities()}


# The CLI details: --format npy, --precision float32, -q and --no-warnings.

def test_cli_npy_loads_as_the_same_samples(tmp_path):
    path = tmp_path / "t.npy"
    run_cli("sample", "--surface", "torus", "--count", "20000", "--normals", "--density-column",
            "--format", "npy", "-q", "-o", str(path))
    loaded = np.load(path)
    s = sfcsampler.sample(surface="torus", count=20000, normals=True, density_column=True)
    assert loaded.dtype.names == tuple(s.columns())
    for name in loaded.dtype.names:
        assert np.array_equal(loaded[name], getattr(s, name)), name


def test_cli_npy_of_a_region_counts_its_samples(tmp_path):
    path = tmp_path / "r.npy"
    run_cli("sample", "--surface", "sphere", "--count", "20000", "--region", "uv:0,0.3,0,1",
            "--format", "npy", "-q", "-o", str(path))
    s = sfcsampler.sample(surface="sphere", count=20000, region="uv:0,0.3,0,1")
    assert np.array_equal(np.load(path)["u"], s.u) and 0 < len(s) < 20000


def test_cli_float32_is_the_embedded_float32(tmp_path):
    path = tmp_path / "f.npy"
    run_cli("sample", "--surface", "eight", "--count", "5000", "--precision", "float32", "--format",
            "npy", "-q", "-o", str(path))
    loaded = np.load(path)
    s = sfcsampler.sample(surface="eight", count=5000, precision="float32")
    assert loaded["x"].dtype == np.float32 and np.array_equal(loaded["x"], s.x)
    # CSV in float32 prints the shortest text of each float.
    text = run_cli("sample", "--surface", "eight", "--count", "5000", "--precision", "float32",
                   "-q")
    first = text.decode().splitlines()[1].split(",")
    assert np.float32(first[3]) == s.x[0] and len(first[3]) <= 12


def test_quiet_keeps_warnings_and_no_warnings_drops_them():
    args = [CLI, "sample", "--surface", "sphere", "--count", "100000", "--depth-cap", "4",
            "-o", "/dev/null"]
    quiet = subprocess.run(args + ["-q"], capture_output=True, text=True, check=True).stderr
    assert "warning: the depth cap" in quiet and "tree " not in quiet
    silent = subprocess.run(args + ["-q", "--no-warnings"], capture_output=True, text=True,
                            check=True).stderr
    assert silent == ""
    # Not a terminal: no progress lines ('\r'), whatever the size.
    loud = subprocess.run([CLI, "sample", "--count", "1000000", "-o", "/dev/null"],
                          capture_output=True, text=True, check=True).stderr
    assert "\r" not in loud and "samples written" in loud


def test_one_sampler_from_several_threads():
    sampler = sfcsampler.Sampler(max_trees=2)
    requests = [dict(surface="torus", count=200000, seed=seed) for seed in (1, 2, 3, 4)]
    results = [None] * len(requests)

    def work(i):
        results[i] = sampler.sample(**requests[i])

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(requests))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for request, result in zip(requests, results):
        assert np.array_equal(result.x, sfcsampler.sample(**request).x)


def test_import_and_embedded_sampling_load_no_grpc_until_a_client_is_used():
    # A fresh interpreter: this test process may already hold the client.
    program = ("import sys, sfcsampler\n"
               "def grpc():\n"
               "    return [line.split()[-1] for line in open('/proc/self/maps')\n"
               "            if 'libgrpc' in line or 'libprotobuf' in line]\n"
               "sfcsampler.sample(surface='sphere', count=100)\n"
               "import numpy as np\n"
               "mesh = (np.eye(3), np.array([[0, 1, 2]]))\n"
               "assert not sfcsampler.sample_many([mesh], count=10).failed\n"
               "assert not grpc(), grpc()\n"
               "assert 'sfcsampler._client' not in sys.modules\n"
               "assert sfcsampler.Client.__module__ == 'sfcsampler.client'\n"
               "assert 'sfcsampler._client' in sys.modules and grpc()\n")
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


# float32 columns that cannot hold the values (engine/float32_range.h): refused
# by the engine Python shares with the CLI, naming the column; float64 serves them.
FLOAT32_REFUSED = [
    (dict(surface="sphere:r=1e70"), "the x, y, z columns reach"),
    (dict(surface="sphere:r=1e-50"), "the x, y, z columns span"),
    (dict(surface="expr:x=u;y=v;z=0", density="expr:1e300*u", density_column=True),
     "the density column reaches"),
    # A spike between the points measured upfront: found as the samples are made.
    (dict(surface="expr:x=u;y=v;z=1e40*exp(-1e4*(u-0.53)^2)"), "the z column's value"),
]


@pytest.mark.parametrize("kwargs,names", FLOAT32_REFUSED)
def test_float32_that_cannot_hold_the_values_is_refused(kwargs, names):
    with pytest.raises(sfcsampler.InvalidArgumentError) as info:
        sfcsampler.sample(count=500, precision="float32", **kwargs)
    assert info.value.code == "INVALID_ARGUMENT"
    assert names in info.value.message and "float64" in info.value.message
    with pytest.raises(sfcsampler.InvalidArgumentError, match="float32"):
        list(sfcsampler.batches(count=500, precision="float32", batch_size=100, **kwargs))
    assert len(sfcsampler.sample(count=500, **kwargs)) == 500
