#!/usr/bin/python3
"""sfcsampler's mesh sampling against Open3D's, side by side on one mesh.

Usage: python3 bench/mesh_vs_open3d.py [BUILD_DIR=build] [COUNT=1000000] [POISSON_COUNT=2000]
                                       [THREADS=1]

Makes the 81 920-triangle icosphere (a subdivided icosahedron pushed to the
unit sphere, built the same way as mesh/icosphere.cc, which mesh_benchmark
uses) and writes it as binary PLY with Open3D, then times:
  - Open3D read_triangle_mesh + sample_points_uniformly(COUNT): i.i.d. points;
  - Open3D sample_points_poisson_disk(POISSON_COUNT) (slow: run with fewer
    points and reported per point);
  - build/bench/mesh_benchmark COUNT 3 THREADS: our cold (read + parse + tree +
    samples) and warm times (THREADS: the cursor's and the triangle order's; the
    same samples for any count; Open3D's calls use one).
and prints the ratios. Installs python3-open3d from Debian when missing
(apt-get, as root or with sudo). Timings are wall-clock medians of 3 runs.
"""
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time


DEBIAN_PYTHON = "/usr/bin/python3"  # Debian's python3-open3d installs for this interpreter


def ensure_open3d():
    try:
        import open3d  # noqa: F401
        return
    except ImportError:
        pass
    if os.path.realpath(sys.executable) != os.path.realpath(DEBIAN_PYTHON) and \
            subprocess.run([DEBIAN_PYTHON, "-c", "import open3d"],
                           capture_output=True).returncode == 0:
        os.execv(DEBIAN_PYTHON, [DEBIAN_PYTHON] + sys.argv)  # another python3 is first on PATH
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    print("installing python3-open3d from Debian ...", file=sys.stderr)
    subprocess.run(sudo + ["apt-get", "update", "-qq"], check=True)
    subprocess.run(sudo + ["apt-get", "install", "-y", "-qq", "--no-install-recommends",
                           "python3-open3d", "python3-numpy"], check=True,
                   env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"))
    if os.path.realpath(sys.executable) != os.path.realpath(DEBIAN_PYTHON):
        os.execv(DEBIAN_PYTHON, [DEBIAN_PYTHON] + sys.argv)


def icosphere(subdivisions):
    import numpy as np
    g = (1 + 5 ** 0.5) / 2
    v = [[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g],
         [0, -1, -g], [0, 1, -g], [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]]
    v = [list(np.array(p) / np.linalg.norm(p)) for p in v]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    for _ in range(subdivisions):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = np.array(v[a]) + np.array(v[b])
                v.append(list(m / np.linalg.norm(m)))
                cache[key] = len(v) - 1
            return cache[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        f = nf
    return np.array(v), np.array(f, dtype=np.int32)


def median_time(fn, repeats=3):
    """Median wall-clock and process-CPU seconds of `repeats` calls."""
    wall, cpu = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return statistics.median(wall), statistics.median(cpu)


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 1000000
    poisson_count = int(sys.argv[3]) if len(sys.argv) > 3 else 2000
    threads = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    ensure_open3d()
    import open3d as o3d
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    tmp = tempfile.mkdtemp(prefix="sfc_o3d_")
    try:
        verts, faces = icosphere(6)
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                         o3d.utility.Vector3iVector(faces))
        path = os.path.join(tmp, "icosphere80k.ply")
        o3d.io.write_triangle_mesh(path, mesh, write_ascii=False)

        def o3d_uniform_cold():
            m = o3d.io.read_triangle_mesh(path)
            m.sample_points_uniformly(number_of_points=count)

        loaded = o3d.io.read_triangle_mesh(path)
        uniform_cold = median_time(o3d_uniform_cold)
        uniform_warm = median_time(lambda: loaded.sample_points_uniformly(number_of_points=count))
        poisson = median_time(
            lambda: loaded.sample_points_poisson_disk(number_of_points=poisson_count), repeats=1)

        out = subprocess.run([os.path.join(build, "bench", "mesh_benchmark"), str(count), "3",
                              str(threads)],
                             check=True, capture_output=True, text=True).stdout
        row = next(l for l in out.splitlines() if l.startswith("| uniform"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        ours = {"cold": (float(cells[5]), float(cells[7])),
                "warm": (float(cells[6]), float(cells[8]))}

        print(f"# {count} samples on the icosphere ({len(faces)} triangles); medians of 3 runs; "
              f"our cursor and triangle order on {threads} thread(s)")
        print("| method | wall s | cpu s | ours / it, wall | ours / it, cpu |")
        print("|---|---:|---:|---:|---:|")
        print(f"| sfcsampler cold (read + parse + tree + samples) | {ours['cold'][0]:.3f} | "
              f"{ours['cold'][1]:.3f} | | |")
        print(f"| sfcsampler warm (samples from the built tree) | {ours['warm'][0]:.3f} | "
              f"{ours['warm'][1]:.3f} | | |")
        for name, (w, c), key in (
                ("Open3D read + sample_points_uniformly (cold)", uniform_cold, "cold"),
                ("Open3D sample_points_uniformly (warm)", uniform_warm, "warm")):
            print(f"| {name} | {w:.3f} | {c:.3f} | {ours[key][0] / w:.2f} | "
                  f"{ours[key][1] / c:.2f} |")
        est_wall, est_cpu = poisson[0] / poisson_count * count, poisson[1] / poisson_count * count
        print(f"| Open3D sample_points_poisson_disk, {poisson_count} points "
              f"({poisson_count / poisson[0]:.0f} points/s) | {poisson[0]:.3f} | "
              f"{poisson[1]:.3f} | | |")
        print(f"\nPoisson disk for {count} points, extrapolated linearly: {est_wall:.0f} s wall; "
              f"our cold run is {est_wall / ours['cold'][0]:.0f}x faster (wall), "
              f"{est_cpu / ours['cold'][1]:.0f}x (cpu)")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
