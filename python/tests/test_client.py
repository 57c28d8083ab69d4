"""sfcsampler.Client against a real loopback sfcsampler-server: the same
numbers as the embedded path and the CLI, resumes, and errors that carry the
server's status code and message."""

import os
import subprocess
import tempfile
import warnings

import numpy as np
import pytest

import sfcsampler
from conftest import CLI, assert_same, cli_columns, launch_server, run_cli, stop
from test_embedded import CASES


@pytest.mark.parametrize("kwargs,flags", CASES)
def test_same_numbers_as_cli_and_embedded(server, kwargs, flags):
    with sfcsampler.Client(server) as client:
        remote = client.sample(**kwargs)
    assert_same(remote, cli_columns(*flags, "--server", server))
    embedded = sfcsampler.sample(**kwargs)
    for name, column in embedded.columns().items():
        assert np.array_equal(getattr(remote, name), column), name
    assert remote.tree["key"] == embedded.tree["key"]


def test_float32_and_batches(server):
    with sfcsampler.Client(server, batch_size=4096) as client:
        points = client.sample(surface="torus", count=10000, columns=["x", "y", "z"])
        assert points.index is None and np.array_equal(
            points.points, sfcsampler.sample(surface="torus", count=10000).points)
        parts = client.batches(surface="torus", count=5000, columns="x")
        assert [p.u for p in parts] == [None, None]
        parts = list(client.batches(surface="torus", count=10000, precision="float32"))
        assert [len(p) for p in parts] == [4096, 4096, 1808]
        x = np.concatenate([p.x for p in parts])
    assert x.dtype == np.float32
    assert np.array_equal(x, sfcsampler.sample(surface="torus", count=10000, precision="float32").x)
    assert parts[0].x.flags.writeable  # a copy, not a view of the message


@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_raw_and_packed_columns_decode_to_the_embedded_arrays(server, precision):
    kwargs = dict(surface="torus", density="gaussian:floor=0.1", count=20000, seed=4,
                  normals=True, density_column=True, curve_position=True)
    embedded = sfcsampler.sample(precision=precision, **kwargs)
    for encoding in ("raw", "packed"):
        with sfcsampler.Client(server, batch_size=3000, encoding=encoding) as client:
            remote = client.sample(precision=precision, **kwargs)
        for name, column in embedded.columns().items():
            got = getattr(remote, name)
            assert got.dtype == column.dtype, (encoding, name)
            # Bit for bit: compare the bytes, not the values.
            assert got.tobytes() == column.tobytes(), (encoding, name)


@pytest.mark.parametrize("encoding", ["raw", "packed"])
def test_columns_left_out_are_not_sent(server, encoding):
    kwargs = dict(surface="torus", density="gaussian:floor=0.1", count=20000, seed=2, normals=True,
                  density_column=True)
    embedded = sfcsampler.sample(**kwargs)
    sent = {}
    for columns in (None, ("x", "y", "z"), ("nz",), ("index",), ("u", "density")):
        with sfcsampler.Client(server, batch_size=5000, encoding=encoding) as client:
            remote = client.sample(columns=columns, **kwargs)
            parts = list(client.batches(columns=columns, **kwargs))
            # Each request streamed once by sample(), once by batches().
            sent[columns] = client.wire_bytes / 2
        kept = (embedded.columns() if columns is None
                else {c: embedded.columns()[c] for c in columns})
        assert set(remote.columns()) == set(kept), columns
        for name, column in kept.items():
            assert getattr(remote, name).tobytes() == column.tobytes(), (columns, name)
            joined = np.concatenate([getattr(p, name) for p in parts])
            assert joined.tobytes() == column.tobytes(), (columns, name)
    # u v x y z nx ny nz density: 9 float64 columns; the bytes follow the columns sent
    # (index alone still needs one value column: u and v travel).
    full = sent[None]
    assert sent[("x", "y", "z")] < full * 3.2 / 9
    assert sent[("nz",)] < full * 3.2 / 9
    assert sent[("index",)] < full * 2.2 / 9
    assert sent[("u", "density")] < full * 3.2 / 9


@pytest.mark.parametrize("columns", ["x,y,z", "nz,x,index", "index", "u,density"])
def test_cli_columns_over_the_wire_write_the_in_process_file(server, columns):
    flags = ("sample", "--surface", "torus", "--density", "gaussian:floor=0.1", "--count", "3000",
             "--normals", "--density-column", "--columns", columns, "--format", "npy", "-q", "-o",
             "-")
    assert run_cli(*flags, "--server", server) == run_cli(*flags)


def test_a_model_column_is_refused_on_a_surface_without_it_whatever_columns_keeps(server):
    # Leaving face or triangle out of the file must not skip the check that the surface has it.
    for flag in ("--face", "--triangle"):
        for where in ((), ("--server", server)):
            done = subprocess.run([CLI, "sample", "--surface", "sphere", "--count", "10", flag,
                                   "--columns", "x,y,z", "-q", "-o", "-", *where],
                                  capture_output=True)
            assert done.returncode != 0 and b"INVALID_ARGUMENT" in done.stderr, (flag, where)
    with sfcsampler.Client(server) as client:
        for flag in ("face", "triangle"):
            with pytest.raises(sfcsampler.InvalidArgumentError):
                client.sample(surface="sphere", count=10, columns=("x",), **{flag: True})
            with pytest.raises(sfcsampler.InvalidArgumentError):
                sfcsampler.sample(surface="sphere", count=10, columns=("x",), **{flag: True})


def test_a_stream_left_early_stops_and_the_client_goes_on(server):
    with sfcsampler.Client(server, batch_size=1000) as client:
        for part in client.batches(surface="sphere", count=10**6):
            break
        assert len(part) == 1000 and part.index[0] == 0
        assert part.x.flags.writeable and part.x.flags.owndata is False  # the C++ buffer
        assert len(client.sample(surface="sphere", count=5000)) == 5000


def test_a_closed_client_refuses_calls(server):
    client = sfcsampler.Client(server)
    client.close()
    with pytest.raises(sfcsampler.Error) as info:
        client.sample(surface="sphere", count=10)
    assert info.value.code == "FAILED_PRECONDITION" and "closed" in info.value.message


def test_empty_region(server):
    with sfcsampler.Client(server) as client:
        s = client.sample(surface="sphere", count=1000, region="box:5,5,5,6,6,6")
    assert len(s) == 0 and s.x.dtype == np.float64
    assert s.tree["key"] == sfcsampler.sample(surface="sphere", count=1000).tree["key"]


def test_float32_that_cannot_hold_the_values_is_refused_by_the_server(server):
    with sfcsampler.Client(server) as client:
        with pytest.raises(sfcsampler.InvalidArgumentError) as info:
            client.sample(surface="expr:x=u;y=v;z=0", density="expr:1e300*u", density_column=True,
                          count=500, precision="float32")
        assert "the density column reaches" in info.value.message
        assert "received 0 samples" in info.value.message
        assert len(client.sample(surface="sphere:r=1e70", count=500)) == 500


def test_server_errors_carry_code_and_message(server):
    with sfcsampler.Client(server) as client:
        with pytest.raises(sfcsampler.InvalidArgumentError) as info:
            client.sample(surface="expr:x=u;y=v;z=", count=10)
        assert info.value.code == "INVALID_ARGUMENT" and "received 0 samples" in info.value.message
        with pytest.raises(sfcsampler.InvalidArgumentError) as info:
            client.sample(count=10**9)
        assert "max_count" in info.value.message
        # Caught before the wire, by the same parser as the CLI's.
        with pytest.raises(sfcsampler.InvalidArgumentError):
            client.sample(sequence="halton")


def test_prepare_then_sample_hits_the_cache(server):
    with sfcsampler.Client(server) as client:
        tree = client.prepare(surface="monkey_saddle", count=30000)
        s = client.sample(surface="monkey_saddle", count=30000)
        assert s.tree["cache_hit"] and s.tree["key"] == tree["key"]
        assert client.cache_stats()["hits"] >= 1
        assert "sphere" in {e["name"] for e in client.catalog()["surfaces"]}


def test_health(server):
    with sfcsampler.Client(server) as client:
        assert client.health() is True
        with pytest.raises(sfcsampler.Error) as info:
            client.health(service="no.such.Service")
        assert info.value.code == "NOT_FOUND"


def test_unreachable_server_is_unavailable():
    with sfcsampler.Client("127.0.0.1:1", max_resumes=1, resume_backoff=0.01, timeout=5) as client:
        with pytest.raises(sfcsampler.UnavailableError) as info:
            client.sample(count=10)
    assert info.value.code == "UNAVAILABLE"


@pytest.mark.parametrize("sequence", ["jittered", "random"])
def test_resumes_after_the_server_restarts(sequence):
    # Kill the server mid-stream and start a new one on the same port: the
    # client resumes (monotone sets from the next index, others by skipping)
    # and the result equals the uninterrupted set.
    request = dict(surface="sphere", count=400000, sequence=sequence)
    expected = sfcsampler.sample(**request)
    with tempfile.TemporaryDirectory() as tmp:
        first, port = launch_server(os.path.join(tmp, "a.log"), "--shutdown-grace", "0")
        second = None
        try:
            client = sfcsampler.Client(f"127.0.0.1:{port}", batch_size=1000, resume_backoff=0.5)
            parts = []
            for i, part in enumerate(client.batches(**request)):
                parts.append(part)
                if i == 5:
                    first.kill()
                    first.wait()
                    second, _ = launch_server(os.path.join(tmp, "b.log"), "--shutdown-grace", "0",
                                              port=port)
            assert client.resumes >= 1
            got = np.concatenate([p.x for p in parts])
            index = np.concatenate([p.index for p in parts])
            client.close()
        finally:
            stop(first)
            stop(second)
    assert second is not None
    assert np.array_equal(index, expected.index)
    assert np.array_equal(got, expected.x)


def test_cli_over_the_wire_float32_npy_is_the_embedded_file(server, tmp_path):
    args = ["sample", "--surface", "torus", "--density", "mean:floor=0.1", "--count", "30000",
            "--format", "npy", "--precision", "float32", "-q", "-o"]
    run_cli(*args, str(tmp_path / "embedded.npy"))
    run_cli(*args, str(tmp_path / "wire.npy"), "--server", server)
    assert (tmp_path / "embedded.npy").read_bytes() == (tmp_path / "wire.npy").read_bytes()


def test_cli_render_over_the_wire(server, tmp_path):
    run_cli("render", "--surface", "torus", "--count", "2000", "--size", "200", "-o",
            str(tmp_path / "t.png"), "--server", server)
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    failed = subprocess.run([CLI, "render", "--what", "curve", "--server", server, "-o",
                             str(tmp_path / "c.png")], capture_output=True, text=True)
    assert failed.returncode != 0 and "FAILED_PRECONDITION" in failed.stderr


def test_cli_eval_over_the_wire_gives_the_same_discrepancies(server, tmp_path):
    # Our point sets come from the server, the rest is computed locally: the
    # same trees give the same sets, so every discrepancy is the same.
    def csv_without_timing(out_dir):
        lines = (out_dir / "discrepancy.csv").read_text().splitlines()
        return [line.rsplit(",", 1)[0] for line in lines]

    local = run_cli("eval", "--l-max", "6", "--out-dir", str(tmp_path / "local"))
    wire = run_cli("eval", "--l-max", "6", "--out-dir", str(tmp_path / "wire"), "--server", server)
    assert local == wire and b"hilbert-jittered" in local
    assert csv_without_timing(tmp_path / "local") == csv_without_timing(tmp_path / "wire")


def test_tls_and_token(tmp_path):
    cert, key = tmp_path / "cert.pem", tmp_path / "key.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
                    "-subj", "/CN=localhost", "-addext",
                    "subjectAltName=IP:127.0.0.1,DNS:localhost", "-keyout", str(key), "-out",
                    str(cert)], capture_output=True, check=True)
    (tmp_path / "token").write_text("s3cret-token\n")
    proc, port = launch_server(tmp_path / "tls.log", "--tls-cert", str(cert), "--tls-key", str(key),
                               "--token-file", str(tmp_path / "token"))
    try:
        target = f"127.0.0.1:{port}"
        with sfcsampler.Client(target, token="s3cret-token", tls_roots=str(cert)) as client:
            s = client.sample(surface="torus", count=1000)
        assert np.array_equal(s.x, sfcsampler.sample(surface="torus", count=1000).x)
        with sfcsampler.Client(target, tls_roots=str(cert)) as client:
            with pytest.raises(sfcsampler.UnauthenticatedError) as info:
                client.sample(count=10)
            assert info.value.code == "UNAUTHENTICATED"
        with sfcsampler.Client(target, token="s3cret-token", max_resumes=0, timeout=5) as client:
            with pytest.raises(sfcsampler.Error):  # plaintext against TLS
                client.sample(count=10)
        with pytest.raises(sfcsampler.InvalidArgumentError, match="cannot read TLS roots"):
            sfcsampler.Client(target, tls_roots=str(tmp_path / "missing.pem"))
    finally:
        stop(proc)


OCTAHEDRON = ("v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
              "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n")


def test_a_mesh_is_uploaded_once_and_samples_as_in_process(server, tmp_path):
    path = tmp_path / "octahedron.obj"
    path.write_text(OCTAHEDRON)
    request = dict(surface=f"obj:{path}", count=4000, triangle=True, density="expr:1+z*z")
    with sfcsampler.Client(server) as client:
        spec = client.upload(f"obj:{path}")
        assert spec.startswith("obj:sha256=")
        uploads = client.cache_stats().get("model_uploads", 0)
        remote = client.sample(**request)
        assert client.cache_stats().get("model_uploads", 0) == uploads  # found, not sent again
        by_hash = client.sample(**dict(request, surface=spec))
    local = sfcsampler.sample(**request)
    assert remote.triangle.dtype == np.uint32 and len(remote.triangle) == 4000
    for name in ("x", "y", "z", "u", "v", "triangle"):
        assert np.array_equal(getattr(remote, name), getattr(local, name)), name
        assert np.array_equal(getattr(by_hash, name), getattr(local, name)), name


def _tree_summary_cases(tmp_path):
    """(name, request, bytes_measured) for each kind of tree: surfaces (plain, capped by the depth
    cap, singular), a mesh and, in a build with CAD, a model (whose bytes include its parse as
    measured on each process's heap, so they differ)."""
    obj = tmp_path / "grid.obj"
    n = 8
    with open(obj, "w") as out:
        out.writelines(f"v {i} {j} {(i * j) % 3}\n" for i in range(n + 1) for j in range(n + 1))
        out.writelines(f"f {i * (n + 1) + j + 1} {(i + 1) * (n + 1) + j + 1} "
                       f"{(i + 1) * (n + 1) + j + 2} {i * (n + 1) + j + 2}\n"
                       for i in range(n) for j in range(n))
    cases = [("surface", dict(surface="torus", count=10000), False),
             ("capped", dict(surface="sphere", count=100000, depth_cap=4), False),
             ("singular", dict(surface="superellipsoid", count=24576), False),
             ("mesh", dict(surface=f"obj:{obj}", count=5000), False)]
    fixtures = os.environ.get("SFC_CAD_FIXTURES", "build/cad/make_cad_fixtures")
    if os.path.exists(fixtures):
        subprocess.run([fixtures, str(tmp_path / "cad")], check=True, capture_output=True)
        cases.append(("model", dict(surface=f"step:{tmp_path / 'cad' / 'sphere.step'}", count=2000),
                      True))
    return cases


def test_a_tree_summary_has_the_same_keys_and_values_in_process_and_from_a_server(tmp_path):
    """Samples.tree and prepare() give the same dict embedded and over the wire (the TreeInfo's
    fields, for every kind of tree): once built (cache_hit aside: a server prepares a model's tree
    before its stream, which then finds it cached), then found in a cache on both sides."""
    def same(local, remote, name, bytes_measured):
        assert list(local) == list(remote), name  # the same keys, in order
        if bytes_measured:
            assert local["bytes"] > 0 and remote["bytes"] > 0, name
            local, remote = dict(local, bytes=0), dict(remote, bytes=0)
        assert local == remote, name

    with tempfile.TemporaryDirectory() as tmp:
        proc, port = launch_server(os.path.join(tmp, "server.log"))  # a cache of its own
        try:
            with sfcsampler.Client(f"127.0.0.1:{port}") as client:
                embedded = sfcsampler.Sampler()
                for name, request, bytes_measured in _tree_summary_cases(tmp_path):
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", sfcsampler.DepthCapWarning)
                        built = embedded.sample(**request).tree
                        remote = client.sample(**request).tree
                        assert not built["cache_hit"], name
                        same(built, dict(remote, cache_hit=False), name, bytes_measured)
                        for local, remote in [(embedded.sample(**request).tree,
                                               client.sample(**request).tree),
                                              (embedded.prepare(**request),
                                               client.prepare(**request))]:
                            assert local["cache_hit"], name
                            same(local, remote, name, bytes_measured)
                    assert built["kind"] == {"capped": "surface", "singular": "surface"}.get(
                        name, name)
                    if name == "capped":
                        assert built["warnings"]
                        assert built["flatness_capped_leaves"] + built["mass_capped_leaves"] > 0
                    if name == "singular":
                        assert built["singular"] and built["warped_leaves"] > 0
        finally:
            stop(proc)
