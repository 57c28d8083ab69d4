#!/usr/bin/env python3
"""Sample a torus with density proportional to |Gaussian curvature|, write the
samples to a binary PLY (MeshLab, CloudCompare, Open3D and trimesh read it)
and draw them as a picture with matplotlib.

On the torus f = ((R + r cos b) cos a, (R + r cos b) sin a, r sin b) the
Gaussian curvature is K = cos b / (r (R + r cos b)): largest in magnitude on
the inner and outer equators (b = pi, 0), zero on the top and bottom circles
(b = +-pi/2). The density max(|K|, floor) puts samples where the surface
bends most; the floor keeps the flat circles sampled.

  PYTHONPATH=build/python python3 examples/torus_curvature.py --count 200000 --out torus
  (writes torus.ply and torus.png)
"""

import argparse
import sys

import numpy as np

import sfcsampler


def write_ply(path, samples):
    """Binary little-endian PLY with x y z, nx ny nz (float32) and the sample index."""
    vertex = np.empty(len(samples), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"),
                                           ("ny", "<f4"), ("nz", "<f4"), ("index", "<u4")])
    for name in ("x", "y", "z", "nx", "ny", "nz"):
        vertex[name] = getattr(samples, name)
    vertex["index"] = samples.index
    header = (f"ply\nformat binary_little_endian 1.0\ncomment sfcsampler torus, density |K|\n"
              f"element vertex {len(samples)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              "property uint index\nend_header\n")
    with open(path, "wb") as out:
        out.write(header.encode("ascii"))
        vertex.tofile(out)


def draw(path, samples, curvature, shown=60000):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    step = max(1, len(samples) // shown)  # a picture needs no more points than it has pixels
    x, y, z, k = samples.x[::step], samples.y[::step], samples.z[::step], curvature[::step]
    fig = plt.figure(figsize=(8, 5), dpi=120)
    ax = fig.add_subplot(projection="3d")
    ax.scatter(x, y, z, s=0.6, c=k, cmap="coolwarm", vmin=-np.abs(k).max(), vmax=np.abs(k).max(),
               linewidths=0)
    reach = float(np.abs(samples.x).max())
    ax.set_xlim(-reach, reach), ax.set_ylim(-reach, reach), ax.set_zlim(-0.4 * reach, 0.4 * reach)
    ax.set_box_aspect((1, 1, 0.4), zoom=1.5)
    ax.view_init(elev=35, azim=30)
    ax.set_axis_off()
    ax.set_title(f"{len(samples)} samples, density max(|K|, floor) (colour: K; 1 in {step} drawn)")
    fig.tight_layout()
    fig.savefig(path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=200000, help="number of samples")
    parser.add_argument("--major", type=float, default=1.0, help="R, the major radius")
    parser.add_argument("--minor", type=float, default=0.4, help="r, the tube radius")
    parser.add_argument("--floor", type=float, default=0.05, help="density floor")
    parser.add_argument("--out", default="torus", help="writes OUT.ply and OUT.png")
    parser.add_argument("--server",
                        help="HOST:PORT: sample through sfcsampler.Client instead of in-process")
    args = parser.parse_args(argv)

    request = dict(surface=f"torus:R={args.major};r={args.minor}",
                   density=f"gaussian:floor={args.floor}", count=args.count, normals=True)
    if args.server:
        with sfcsampler.Client(args.server) as client:
            s = client.sample(**request)
    else:
        s = sfcsampler.sample(**request)
    # b from the unit-square parameter v: b = 2 pi v.
    cos_b = np.cos(2 * np.pi * s.v)
    curvature = cos_b / (args.minor * (args.major + args.minor * cos_b))
    write_ply(args.out + ".ply", s)
    draw(args.out + ".png", s, curvature)
    # Where the samples went: the share in the most-curved half of the tube.
    curved = np.mean(np.abs(cos_b) > np.sqrt(0.5))
    print(f"{len(s)} samples (tree {s.tree['key_with_grade']}, {s.tree['leaves']} leaves); "
          f"{curved:.1%} where |cos b| > 0.71 (half the parameter square)")
    print(f"wrote {args.out}.ply and {args.out}.png")
    return s, curvature


if __name__ == "__main__":
    main(sys.argv[1:])
