"""Page faults and CPU of sample_many's kept results, round after round, in one process.

    PYTHONPATH=build/python /usr/bin/python3 bench/many_faults.py [all|xyz] [WORKERS=2]

1 000 tori of bench/many_meshes.py (2 052 triangles), 10^4 samples each, every column (all)
or the points only (xyz), 3 rounds; each round's results are kept until the next round starts.
Prints each round's wall, user and system seconds and minor page faults a mesh (getrusage).
"""

import os
import resource
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import sfcsampler  # noqa: E402
from many_meshes import torus  # noqa: E402


def main():
    columns = None if len(sys.argv) < 2 or sys.argv[1] == "all" else ("x", "y", "z")
    workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    meshes = [torus(57, 18, seed) for seed in range(1000)]
    sfcsampler.sample_many(meshes[:4], count=10000, workers=workers, progress=False)
    for _ in range(3):
        before, start = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
        results = sfcsampler.sample_many(meshes, count=10000, workers=workers, progress=False,
                                         columns=columns)
        wall, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_SELF)
        print(f"wall {wall:.3f} s, user {after.ru_utime - before.ru_utime:.3f} s, "
              f"sys {after.ru_stime - before.ru_stime:.3f} s, "
              f"{(after.ru_minflt - before.ru_minflt) / len(meshes):.0f} faults a mesh")
        del results


if __name__ == "__main__":
    main()
