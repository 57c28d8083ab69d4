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


@pytest.fixture(scope="module")
def server():
    """A loopback sfcsampler-server on free ports; yields its address."""
    with tempfile.TemporaryDirectory() as tmp:
        log_path = os.path.join(tmp, "server.log")
        with open(log_path, "w") as log:
            proc = subprocess.Popen([SERVER, "--address", "127.0.0.1:0", "--health-address", "127.0.0.1:0",
                                     "--metrics-address", "127.0.0.1:0"], stdout=log, stderr=log)
        try:
            port = None
            for _ in range(200):
                match = re.search(r" port=(\d+) health_port=", open(log_path).read())
                if match:
                    port = match.group(1)
                    break
                time.sleep(0.05)
            assert port, open(log_path).read()
            yield f"127.0.0.1:{port}"
        finally:
            proc.terminate()
            proc.wait(timeout=30)
