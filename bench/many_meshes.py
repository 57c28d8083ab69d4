"""Many small meshes from memory: sfcsampler against a Python loop over Open3D,
and 1 against 2 Dask workers. Not part of the test suite.

    PYTHONPATH=build/python python3 bench/many_meshes.py            # 1000 meshes, 10^4 samples each
    PYTHONPATH=build/python python3 bench/many_meshes.py --meshes 200 --rounds 2 --no-dask

The meshes are tori of about 2 000 triangles (a 40 x 25 grid, --triangles), each
with its own random radial wobble, as (float64 vertices, int64 faces) arrays.
Every side samples every mesh with --count uniform points and keeps the points:

  open3d loop     for V, F: TriangleMesh(Vector3dVector(V), Vector3iVector(F))
                  .sample_points_uniformly(count), then numpy.asarray(points)
                  (python3-open3d 0.16, Debian; one thread)
  ours, loop      for V, F: Sampler.sample(mesh=(V, F), count=count) (one thread)
  ours, many      sfcsampler.sample_many(meshes, count=count, workers=W): on W
                  threads of this process, each mesh one C++ call with the GIL
                  released (its canonical PLY, hash, seed and samples:
                  Engine.sample_mesh_arrays); every column (index, u, v, x, y,
                  z: 480 KB a mesh)
  --python-path   adds the same two through sample_many's per-mesh Python path
                  (the canonical PLY in NumPy, then hold and sample, as before
                  the one C++ call), for a before/after in one run
  ours, many,     the same with columns=("x", "y", "z"): the points only, as
  points only     Open3D keeps (240 KB a mesh); the other columns' memory goes
                  to the next mesh at once instead of being faulted in afresh

Sides alternate in --rounds rounds (the machine's load changes; alternating keeps
it from favouring one side); the table gives each side's best and median wall
seconds, the ratios of the medians, and the CPU seconds this process used (all
threads), which a busy machine disturbs less than the wall time. Then
sfcsampler.dask.sample_many over the same meshes on a LocalCluster of 1 and of 2
worker processes (one thread each; the samples stay on the workers, each task
returns its count and seed), best of --rounds each, and the scaling ratio. Checks on
the way: every result has exactly --count samples, and the loop and sample_many give
the same bytes.
"""

import argparse
import os
import statistics
import sys
import time

import numpy as np

import sfcsampler


def torus(n, m, seed):
    rng = np.random.default_rng(seed)
    a, b = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(m) * 2 * np.pi / m, indexing="ij")
    r = 0.35 * (1 + 0.08 * rng.standard_normal(a.shape))
    v = np.stack([(1 + r * np.cos(b)) * np.cos(a), (1 + r * np.cos(b)) * np.sin(a), r * np.sin(b)],
                 axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    p00, p10 = i * m + j, ((i + 1) % n) * m + j
    p01, p11 = i * m + (j + 1) % m, ((i + 1) % n) * m + (j + 1) % m
    f = np.concatenate([np.stack([p00, p10, p11], -1).reshape(-1, 3),
                        np.stack([p00, p11, p01], -1).reshape(-1, 3)])
    return v, f.astype(np.int64)


def open3d_loop(o3d, meshes, count):
    out = []
    for v, f in meshes:
        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
        out.append(np.asarray(m.sample_points_uniformly(count).points))
    return out


def ours_loop(meshes, count):
    sampler = sfcsampler.Sampler(max_trees=0, threads=1)
    return [sampler.sample(mesh=mesh, count=count) for mesh in meshes]


def ours_many(meshes, count, workers, columns=None):
    results = sfcsampler.sample_many(meshes, count=count, workers=workers, progress=False,
                                     columns=columns)
    assert not results.failed, results.summary()
    return [r.samples for r in results]


def python_path(fn):
    """fn run with sample_many's per-mesh Python path instead of Engine.sample_mesh_arrays."""
    def run():
        make = sfcsampler.many.MeshArrays.make
        sfcsampler.many.MeshArrays.make = classmethod(lambda cls, *args: None)
        try:
            return fn()
        finally:
            sfcsampler.many.MeshArrays.make = make
    return run


def timed(fn):
    start = time.perf_counter()
    out = fn()
    return time.perf_counter() - start, out


def timed_cpu(fn):
    """(wall seconds, CPU seconds of this process, result)."""
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - wall, time.process_time() - cpu, out


def dask_run(meshes, count, workers, rounds):
    import distributed
    import sfcsampler.dask
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None)
    client = distributed.Client(cluster)
    try:
        # Warm: the workers import sfcsampler and build their samplers.
        sfcsampler.dask.sample_many(client, meshes[:2 * workers], count=count, keep=False,
                                    progress=False)
        best = None
        for _ in range(rounds):
            seconds, results = timed(lambda: sfcsampler.dask.sample_many(
                client, meshes, count=count, keep=False, progress=False))
            assert not results.failed and all(r.count == count for r in results)
            best = seconds if best is None else min(best, seconds)
        return best
    finally:
        client.close()
        cluster.close()


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--meshes", type=int, default=1000)
    p.add_argument("--triangles", type=int, default=2000, help="about this many per mesh")
    p.add_argument("--count", type=int, default=10000, help="samples per mesh")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--workers", type=int, default=2, help="threads of sample_many")
    p.add_argument("--no-dask", action="store_true")
    p.add_argument("--python-path", action="store_true",
                   help="also sample_many through its per-mesh Python path (before/after)")
    args = p.parse_args()
    import open3d as o3d  # python3-open3d (tools/setup-debian.sh)

    n = max(3, int(round((args.triangles / 2 / 0.625) ** 0.5)))
    m = max(3, int(round(args.triangles / 2 / n)))
    meshes = [torus(n, m, seed) for seed in range(args.meshes)]
    print(f"{args.meshes} meshes of {2 * n * m} triangles ({n * m} vertices), {args.count} "
          f"samples each; {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}",
          flush=True)

    # Same bytes, exact counts (a few meshes).
    a, b = ours_loop(meshes[:8], args.count), ours_many(meshes[:8], args.count, args.workers)
    for x in a:
        assert len(x) == args.count
    sides = {
        "open3d loop": lambda: open3d_loop(o3d, meshes, args.count),
        "ours, loop (1 thread)": lambda: ours_loop(meshes, args.count),
        f"ours, sample_many ({args.workers} threads)":
            lambda: ours_many(meshes, args.count, args.workers),
        f"ours, sample_many ({args.workers} threads), points only": lambda: ours_many(
            meshes, args.count, args.workers, columns=("x", "y", "z")),
    }
    if args.python_path:
        w = args.workers
        sides[f"ours, sample_many ({w} threads), Python path"] = python_path(
            lambda: ours_many(meshes, args.count, w))
        sides[f"ours, sample_many ({w} threads), points only, Python path"] = python_path(
            lambda: ours_many(meshes, args.count, w, columns=("x", "y", "z")))
    times = {k: [] for k in sides}
    cpu = {k: [] for k in sides}
    for r in range(args.rounds):
        for name, fn in sides.items():
            seconds, cpu_seconds, out = timed_cpu(fn)
            assert len(out) == args.meshes and all(len(x) == args.count for x in out), name
            times[name].append(seconds)
            cpu[name].append(cpu_seconds)
            del out
        print(f"round {r + 1}: " + ", ".join(f"{k} {v[-1]:.2f} s" for k, v in times.items()),
              flush=True)
    # sample_many's seeds are derived per mesh; check it against the loop with those seeds.
    for mesh, many_result in zip(meshes[:8], b):
        seed = sfcsampler.model_seed(1, __import__("hashlib").sha256(
            sfcsampler.meshes.mesh_ply(mesh)).hexdigest())
        alone = sfcsampler.sample(mesh=mesh, count=args.count, seed=seed)
        assert alone.x.tobytes() == many_result.x.tobytes()

    o3d_median = statistics.median(times["open3d loop"])
    o3d_cpu = statistics.median(cpu["open3d loop"])
    print()
    print(f"| {args.meshes} meshes x {args.count} samples | best s | median s | ms a mesh (median) "
          f"| open3d / this, wall (medians) | CPU s (median) | open3d / this, CPU |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, ts in times.items():
        med, cpu_med = statistics.median(ts), statistics.median(cpu[name])
        print(f"| {name} | {min(ts):.2f} | {med:.2f} | {1000 * med / args.meshes:.2f} | "
              f"{o3d_median / med:.2f}x | {cpu_med:.2f} | {o3d_cpu / cpu_med:.2f}x |")

    if not args.no_dask:
        one = dask_run(meshes, args.count, 1, args.rounds)
        two = dask_run(meshes, args.count, 2, args.rounds)
        print()
        print("| sfcsampler.dask.sample_many, LocalCluster | best s | meshes/s |")
        print("|---|---:|---:|")
        print(f"| 1 worker process | {one:.2f} | {args.meshes / one:.0f} |")
        print(f"| 2 worker processes | {two:.2f} | {args.meshes / two:.0f} |")
        print(f"\nscaling 1 -> 2 workers: {one / two:.2f}x (load average now "
              f"{os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    sys.exit(main())
