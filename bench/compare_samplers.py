#!/usr/bin/python3
"""sfcsampler against the samplers users would otherwise take, side by side in one run
(issue 9's comparison; not in CI).

Usage: python3 bench/compare_samplers.py [BUILD_DIR=build] [COUNT=4000000]

Prints one Markdown table of wall-clock medians (3 runs each) and ratios:
  - the cold CLI, `sfcsampler sample --surface sphere --count COUNT --format ply
    -o FILE`, against a ten-line numpy script that draws COUNT i.i.d. points
    on the sphere and writes the same binary PLY (x y z double, u v double,
    index uint32), both as fresh processes;
  - samples per second on the unit sphere: ours in process (the Python
    package: tree built, then drawn), scipy's scrambled Sobol mapped to the
    sphere (area-preserving: z = 1 - 2 u, phi = 2 pi v), numpy i.i.d., and
    Open3D's sample_points_uniformly and sample_points_poisson_disk on an
    81 920-triangle icosphere.
Installs python3-numpy, python3-scipy and python3-open3d from Debian when
missing (apt-get, as root or with sudo).
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

DEBIAN_PYTHON = "/usr/bin/python3"

NUMPY_SCRIPT = r'''
import sys, numpy as np
n, path = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(1)
z = rng.uniform(-1, 1, n); phi = rng.uniform(0, 2 * np.pi, n); r = np.sqrt(1 - z * z)
rec = np.empty(n, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("u", "<f8"), ("v", "<f8"),
                         ("index", "<u4")])
rec["x"], rec["y"], rec["z"] = r * np.cos(phi), r * np.sin(phi), z
rec["u"], rec["v"], rec["index"] = (z + 1) / 2, phi / (2 * np.pi), np.arange(n, dtype=np.uint32)
header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\n"
          "property double y\nproperty double z\nproperty double u\nproperty double v\n"
          "property uint index\nend_header\n" % n)
with open(path, "wb") as f: f.write(header.encode()); f.write(rec.tobytes())
'''


def ensure(module, package):
    try:
        __import__(module)
        return
    except ImportError:
        pass
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    print(f"installing {package} from Debian ...", file=sys.stderr)
    subprocess.run(sudo + ["apt-get", "update", "-qq"], check=True)
    subprocess.run(sudo + ["apt-get", "install", "-y", "-qq", package], check=True)


def median_time(fn, repeats=3):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def icosphere(subdivisions):
    import numpy as np
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
             (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [np.array(v, float) / np.linalg.norm(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache, out = {}, []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                cache[key] = len(verts) - 1
            return cache[key]
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = out
    return np.array(verts), np.array(faces, dtype=np.int32)


def main():
    if os.path.realpath(sys.executable) != os.path.realpath(DEBIAN_PYTHON):
        os.execv(DEBIAN_PYTHON, [DEBIAN_PYTHON] + sys.argv)  # Debian's modules belong to it
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "build")
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 4000000
    for module, package in (("numpy", "python3-numpy"), ("scipy", "python3-scipy"),
                            ("open3d", "python3-open3d")):
        ensure(module, package)
    import numpy as np
    import open3d as o3d
    from scipy.stats import qmc
    sys.path.insert(0, os.path.join(build, "python"))
    import sfcsampler

    cli = os.path.join(build, "client", "sfcsampler")
    with tempfile.TemporaryDirectory(prefix="sfc_compare_") as tmp:
        script = os.path.join(tmp, "numpy_sphere.py")
        with open(script, "w") as f:
            f.write(NUMPY_SCRIPT)
        ours_cli = median_time(lambda: subprocess.run(
            [cli, "sample", "--surface", "sphere", "--count", str(count), "--format", "ply", "-q",
             "-o", os.path.join(tmp, "ours.ply")], check=True))
        numpy_cli = median_time(lambda: subprocess.run(
            [DEBIAN_PYTHON, script, str(count), os.path.join(tmp, "numpy.ply")], check=True))

        # Samplers in process, samples per second on the unit sphere.
        ours_cold = median_time(lambda: sfcsampler.sample(surface="sphere", count=count, seed=1))
        engine = sfcsampler.Sampler()
        engine.sample(surface="sphere", count=count, seed=1)  # builds and keeps the tree
        ours_warm = median_time(lambda: engine.sample(surface="sphere", count=count, seed=2))

        def sobol():
            p = qmc.Sobol(d=2, scramble=True, seed=1).random(count)
            z = 1 - 2 * p[:, 0]
            phi = 2 * np.pi * p[:, 1]
            r = np.sqrt(1 - z * z)
            return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)

        def iid():
            rng = np.random.default_rng(1)
            z = rng.uniform(-1, 1, count)
            phi = rng.uniform(0, 2 * np.pi, count)
            r = np.sqrt(1 - z * z)
            return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)

        sobol_t = median_time(sobol)
        iid_t = median_time(iid)
        verts, faces = icosphere(6)
        mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(verts),
                                         o3d.utility.Vector3iVector(faces))
        o3d_t = median_time(lambda: mesh.sample_points_uniformly(number_of_points=count))
        poisson_n = 2000
        poisson_t = median_time(lambda: mesh.sample_points_poisson_disk(number_of_points=poisson_n),
                                repeats=1)

    rate = lambda seconds, n=count: n / seconds / 1e6
    print(f"# {count} points on the unit sphere; wall-clock medians of 3 runs, one run of this "
          "script\n")
    print("| what | seconds | M points/s | ratio to ours |")
    print("|---|---:|---:|---:|")
    print(f"| our CLI, cold (new process: tree + samples + binary PLY) | {ours_cli:.3f} | "
          f"{rate(ours_cli):.2f} | 1 |")
    print(f"| numpy script, cold (new process: i.i.d. + the same binary PLY) | {numpy_cli:.3f} | "
          f"{rate(numpy_cli):.2f} | {numpy_cli / ours_cli:.2f} |")
    print(f"| **our CLI / numpy script** (target <= 1.0) | **{ours_cli / numpy_cli:.2f}** | | |")
    print(f"| ours in process, cold (tree + samples, Python package) | {ours_cold:.3f} | "
          f"{rate(ours_cold):.2f} | 1 |")
    print(f"| ours in process, warm (cached tree) | {ours_warm:.3f} | {rate(ours_warm):.2f} | "
          f"{ours_warm / ours_cold:.2f} |")
    print(f"| scipy scrambled Sobol mapped to the sphere | {sobol_t:.3f} | {rate(sobol_t):.2f} | "
          f"{sobol_t / ours_cold:.2f} |")
    print(f"| numpy i.i.d. on the sphere | {iid_t:.3f} | {rate(iid_t):.2f} | "
          f"{iid_t / ours_cold:.2f} |")
    print(f"| Open3D sample_points_uniformly, 81 920-triangle icosphere | {o3d_t:.3f} | "
          f"{rate(o3d_t):.2f} | {o3d_t / ours_cold:.2f} |")
    print(f"| Open3D sample_points_poisson_disk, {poisson_n} points | {poisson_t:.3f} | "
          f"{rate(poisson_t, poisson_n):.4f} | |")


if __name__ == "__main__":
    main()
