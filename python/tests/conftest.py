"""Shared fixtures: the CLI and server built alongside the package (paths from
ctest's environment), CSV reading, and a loopback sfcsampler-server."""

import csv
import io
import os
import re
import subprocess
import tempfile
import time

import numpy as np
import pytest

CLI = os.environ.get("SFC_CLI", "build/client/sfcsampler")
SERVER = os.environ.get("SFC_SERVER", "build/server/sfcsampler-server")


def run_cli(*args):
    """Runs `sfcsampler ARGS` and returns its stdout bytes; fails the test on an error exit."""
    done = subprocess.run([CLI, *args], capture_output=True, check=False)
    assert done.returncode == 0, done.stderr.decode()
    return done.stdout


def cli_columns(*args):
    """The CLI's CSV output (-o -) as a dict of arrays; float() reads the
    shortest round-trip text back to the exact double."""
    rows = list(csv.reader(io.StringIO(run_cli("sample", *args, "-q", "-o", "-").decode())))
    header, body = rows[0], rows[1:]
    out = {}
    for i, name in enumerate(header):
        if name == "index":
            out[name] = np.array([int(r[i]) for r in body], dtype=np.uint64)
        else:
            out[name] = np.array([float(r[i]) for r in body], dtype=np.float64)
    return out


def assert_same(samples, columns):
    """Every column of the CLI's output equals the Samples' column bit for bit."""
    assert set(columns) == set(samples.columns()), (set(columns), set(samples.columns()))
    for name, expected in columns.items():
        got = getattr(samples, name)
        assert got.shape == expected.shape, name
        assert np.array_equal(got.view(np.uint8), expected.astype(got.dtype).view(np.uint8)), name


def launch_server(log_path, *extra, port=0):
    """Starts sfcsampler-server on 127.0.0.1:PORT (0 = a free port) with `extra`
    flags, logging to log_path; returns (process, port) once it listens."""
    with open(log_path, "w") as log:
        proc = subprocess.Popen([SERVER, "--address", f"127.0.0.1:{port}", "--health-address",
                                 "127.0.0.1:0", "--metrics-address", "127.0.0.1:0", *extra],
                                stdout=log, stderr=log)
    for _ in range(200):
        match = re.search(r" port=(\d+) health_port=", open(log_path).read())
        if match:
            return proc, int(match.group(1))
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    proc.kill()
    raise AssertionError("the server did not start: " + open(log_path).read())


def stop(proc):
    if proc is not None and proc.poll() is None:
        proc.terminate()
        proc.wait(timeout=30)


@pytest.fixture(scope="module")
def server():
    """A loopback sfcsampler-server on free ports; yields its address."""
    with tempfile.TemporaryDirectory() as tmp:
        proc, port = launch_server(os.path.join(tmp, "server.log"))
        try:
            yield f"127.0.0.1:{port}"
        finally:
            stop(proc)
