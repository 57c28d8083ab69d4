#!/usr/bin/python3
"""Old against new on the float32 stream row of issue 34, in alternating rounds.

    /usr/bin/python3 bench/stream_rounds.py N ROUNDS 'NAME=BINARY [FLAG ...] [VAR=VALUE ...]' ...
    /usr/bin/python3 bench/stream_rounds.py --cpu N ROUNDS REPEAT 'NAME=...' ...

Each side is a bench/stream_benchmark binary (e.g. one built from another worktree) with its
flags (--glibc-malloc, --raw) and environment variables (MALLOC_MMAP_THRESHOLD_=...). Sides run
in the order A B C, then C B A, and so on, so a drift in the machine's load meets them alike.

Without --cpu: `stream_benchmark N float32` per side and round; the table gives the median and
range of its pipelined raw-columns rows: stream / raw bytes, the stream's and the raw bytes'
speed, generation alone, stream / generation.
With --cpu: `perf stat` (/usr/bin/perf) of `stream_benchmark N float32 --repeat=REPEAT` minus
`--repeat=1`, over REPEAT - 1: the CPU seconds (all threads) and page faults of one stream (or,
with --raw, of one raw bytes stream), and the wall seconds of each repeat. CPU time is what a
busy machine disturbs least.
"""

import os
import re
import statistics
import subprocess
import sys


def sides(specs):
    out = []
    for spec in specs:
        name, _, rest = spec.partition("=")
        words = rest.split()
        env = dict(os.environ)
        env.update(dict(w.split("=", 1) for w in words if "=" in w))
        words = [w for w in words if "=" not in w]
        out.append((name, words[0], words[1:], env))
    return out


def spread(values, digits=2):
    return (f"{statistics.median(values):.{digits}f} "
            f"({min(values):.{digits}f}-{max(values):.{digits}f})")


def alternating(configs, rounds):
    for r in range(rounds):
        yield from (configs if r % 2 == 0 else configs[::-1])


def table_rounds(n, rounds, configs):
    keys = ("ratio", "stream", "raw", "generation", "of_generation")
    got = {c[0]: {k: [] for k in keys} for c in configs}
    for name, binary, flags, env in alternating(configs, rounds):
        out = subprocess.run([binary, n, "float32"] + flags, capture_output=True, text=True,
                             env=env, check=True).stdout
        ratio = re.search(r"pipelined, raw columns: ratio stream / raw bytes; stream / "
                          r"generation alone \| ([\d.]+); ([\d.]+)", out)
        stream = re.search(r"pipelined, raw columns: \d+ samples streamed \(cached tree\) \| "
                           r"([\d.]+) M samples/s", out)
        raw = re.search(r"raw bytes stream of the same \d+ MB \| (\d+) MB/s", out)
        generation = re.search(r"generation alone.*\| ([\d.]+) M samples/s", out)
        values = (ratio.group(1), stream.group(1), raw.group(1), generation.group(1),
                  ratio.group(2))
        for key, value in zip(keys, values):
            got[name][key].append(float(value))
    print(f"| {n} float32 samples | stream / raw bytes | stream, M samples/s | raw bytes, MB/s "
          "| generation alone, M samples/s | stream / generation |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, d in got.items():
        print(f"| {name} | {spread(d['ratio'])} | {spread(d['stream'], 1)} | "
              f"{spread(d['raw'], 0)} | {spread(d['generation'], 1)} | "
              f"{spread(d['of_generation'])} |")


def perf_stat(binary, n, flags, env, repeat):
    r = subprocess.run(["/usr/bin/perf", "stat", "-x,", "-e", "task-clock,page-faults", binary,
                        n, "float32", f"--repeat={repeat}"] + flags,
                       capture_output=True, text=True, env=env, check=True)
    counters = {}
    for line in r.stderr.splitlines():
        f = line.split(",")
        if len(f) > 3 and f[2] in ("task-clock", "page-faults"):
            counters[f[2]] = float(f[0])
    walls = [float(w) for w in re.findall(r": ([\d.]+) s$", r.stdout, re.M)]
    return counters["task-clock"] / 1000, counters["page-faults"], walls


def cpu_rounds(n, rounds, repeat, configs):
    cpu = {c[0]: [] for c in configs}
    faults = {c[0]: [] for c in configs}
    walls = {c[0]: [] for c in configs}
    for name, binary, flags, env in alternating(configs, rounds):
        cpu1, faults1, _ = perf_stat(binary, n, flags, env, 1)
        cpu_k, faults_k, wall = perf_stat(binary, n, flags, env, repeat)
        cpu[name].append((cpu_k - cpu1) / (repeat - 1))
        faults[name].append((faults_k - faults1) / (repeat - 1))
        walls[name] += wall
    print(f"| {n} float32 samples | CPU s a stream | page faults a stream | wall s a stream |")
    print("|---|---:|---:|---:|")
    for name in cpu:
        print(f"| {name} | {spread(cpu[name], 3)} | {statistics.median(faults[name]):.0f} | "
              f"{spread(walls[name], 3)} |")


def main():
    args = sys.argv[1:]
    if args and args[0] == "--cpu":
        cpu_rounds(args[1], int(args[2]), int(args[3]), sides(args[4:]))
    else:
        table_rounds(args[0], int(args[1]), sides(args[2:]))


if __name__ == "__main__":
    main()
