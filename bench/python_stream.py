"""Python client streaming speed: sfcsampler.Client.sample() with raw and
packed columns, float32 and float64, against a running server; prints a
Markdown table. Not in CI.

    ./build/server/sfcsampler-server --address 127.0.0.1:50051 &
    PYTHONPATH=build/python /usr/bin/python3 bench/python_stream.py 127.0.0.1:50051 [samples]
"""

import sys
import time

import sfcsampler


def best_seconds(client, precision, count, runs=2):
    best = None
    for _ in range(runs):
        start = time.perf_counter()
        s = client.sample(surface="sphere", count=count, precision=precision)
        seconds = time.perf_counter() - start
        assert len(s) == count
        best = seconds if best is None else min(best, seconds)
    return best


def main():
    target = sys.argv[1]
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 4_000_000
    print("| Python client, sphere (cached tree) | M samples/s |")
    print("|---|---:|")
    for precision in ("float32", "float64"):
        for encoding in ("packed", "raw"):
            with sfcsampler.Client(target, encoding=encoding) as client:
                client.sample(surface="sphere", count=count, precision=precision)  # warm the tree
                seconds = best_seconds(client, precision, count)
            print(f"| {precision}, {encoding} columns, {count} samples | "
                  f"{count / seconds / 1e6:.2f} |")


if __name__ == "__main__":
    main()
