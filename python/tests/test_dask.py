"""sfcsampler.dask on a LocalCluster of 2 worker processes on loopback: the
results equal one process's, byte for byte."""

import os

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

import sfcsampler
import sfcsampler.dask
from sfcsampler import many
from test_meshes import same_samples, torus_mesh


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None)
    c = distributed.Client(cluster)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


def meshes20():
    return {f"mesh{k:02d}": torus_mesh(8 + k % 7, 5 + k % 4, R=1 + 0.05 * k, wobble=0.1, seed=k)
            for k in range(20)}


def test_sample_many_equals_one_process(client, tmp_path):
    models = meshes20()
    local = sfcsampler.sample_many(models, count=4000, seed=9, normals=True, triangle=True,
                                   workers=1)
    assert len({pid for pid in client.run(os.getpid).values()}) == 2
    for per_task in (0, 1, 7):  # one model a task, 7, and the default (2 here)
        remote = sfcsampler.dask.sample_many(client, models, count=4000, seed=9, normals=True,
                                             triangle=True, models_per_task=per_task)
        assert len(remote) == 20 and not remote.failed
        for a, b in zip(local, remote):
            assert (a.name, a.seed, a.sha256) == (b.name, b.seed, b.sha256)
            same_samples(a.samples, b.samples)
            assert len(b.samples) == 4000
    # Written by the workers: the CLI's NPY of the same samples; a bad model is named.
    bad = dict(models, broken=(np.zeros((3, 3)), np.array([[0, 1, 5]])))
    written = sfcsampler.dask.sample_many(client, bad, count=4000, seed=9, out_dir=tmp_path)
    assert [r.name for r in written.failed] == ["broken"]
    assert "mesh faces row 0" in written.failed[0].error
    for a, b in zip(local, written):
        assert b.samples is None and b.path == str(tmp_path / f"{a.name}.npy")
        assert np.array_equal(np.load(b.path)["x"], a.samples.x)


def test_sample_many_files_sent_as_bytes(client, tmp_path):
    models = meshes20()
    for name, mesh in list(models.items())[:5]:
        sfcsampler.write_ply(tmp_path / f"{name}.ply", mesh)
    local = sfcsampler.sample_many(tmp_path, count=3000, seed=2)
    for send_bytes in (False, True):
        remote = sfcsampler.dask.sample_many(client, tmp_path, count=3000, seed=2,
                                             send_bytes=send_bytes)
        for a, b in zip(local, remote):
            assert a.name == b.name
            same_samples(a.samples, b.samples)


def test_sample_shards_equal_one_run(client, tmp_path):
    n = 10**6
    whole = sfcsampler.sample(surface="torus", count=n, seed=5, normals=True)
    out = sfcsampler.dask.sample_shards(client, "torus", n, shards=4, seed=5, normals=True,
                                        out_dir=tmp_path)
    assert ([os.path.basename(o[0]) for o in out]
            == [f"shard-{i:05d}-of-00004.npy" for i in range(4)])
    assert [(o[2], o[3]) for o in out] == [(i * n // 4, (i + 1) * n // 4) for i in range(4)]
    joined = sfcsampler.dask.load_shards([o[0] for o in out])
    assert len(joined) == n
    assert joined.tobytes() == many.structured(whole).tobytes()
    # The shard files' data, concatenated, are the bytes of one run's NPY data.
    body = b"".join(open(o[0], "rb").read()[-o[1] * joined.dtype.itemsize:] for o in out)
    one = many.npy_bytes(whole)
    assert len(body) == n * joined.dtype.itemsize and body == one[-len(body):]


def test_sample_shards_of_a_mesh_and_a_model_file(client, tmp_path):
    v, f = torus_mesh(30, 20, wobble=0.05)
    whole = sfcsampler.sample(mesh=(v, f), count=200000, seed=3, triangle=True)
    parts = sfcsampler.dask.sample_shards(client, mesh=(v, f), count=200000, shards=3, seed=3,
                                          triangle=True)
    for name in ("index", "x", "y", "z", "u", "v", "triangle"):
        assert np.array_equal(np.concatenate([getattr(p, name) for p in parts]),
                              getattr(whole, name))
    sfcsampler.write_ply(tmp_path / "t.ply", (v, f))
    parts = sfcsampler.dask.sample_shards(client, f"ply:{tmp_path / 't.ply'}", 200000, shards=5,
                                          seed=3, triangle=True)
    assert np.array_equal(np.concatenate([p.x for p in parts]), whole.x)
    # Calls in a row (the first's futures still alive) do not share tasks.
    again = sfcsampler.dask.sample_shards(client, f"ply:{tmp_path / 't.ply'}", 200000, shards=5,
                                          seed=4, triangle=True)
    assert not np.array_equal(np.concatenate([p.x for p in again]), whole.x)
    assert np.array_equal(np.concatenate([p.x for p in again]),
                          sfcsampler.sample(mesh=(v, f), count=200000, seed=4).x)
    with pytest.raises(TypeError):
        sfcsampler.dask.sample_shards(client, "torus", 100, shards=2, begin=3)


def test_workers_on_a_service(client, server):
    models = dict(list(meshes20().items())[:4])
    local = sfcsampler.sample_many(models, count=3000, seed=4)
    remote = sfcsampler.dask.sample_many(client, models, count=3000, seed=4, service=server)
    for a, b in zip(local, remote):
        same_samples(a.samples, b.samples)
    whole = sfcsampler.sample(surface="sphere", count=100000, seed=4)
    parts = sfcsampler.dask.sample_shards(client, "sphere", 100000, shards=4, seed=4,
                                          service=server)
    assert np.array_equal(np.concatenate([p.x for p in parts]), whole.x)
