"""Many models in one call: `sfcsampler sample-many` and sfcsampler.sample_many()
over a folder of real models (STEP made by OpenCASCADE, OBJ, PLY) plus broken
files. Every good model's output is byte-identical to `sample` on it alone with
its derived seed, whatever the order and the number of workers; the broken
ones are named with their errors and the exit status is 1."""

import csv
import filecmp
import hashlib
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

import sfcsampler
from sfcsampler import many
from conftest import CLI
from test_meshes import same_samples, torus_mesh

FIXTURES = os.environ.get("SFC_CAD_FIXTURES", "build/cad/make_cad_fixtures")
GOOD = ["box_with_hole.step", "cylinder.step", "ring.obj", "sphere.step", "sub/ring.obj",
        "torus.ply", "wavy.ply"]
BROKEN = ["broken.ply", "broken.step"]
FLAGS = ["--count", "3000", "--seed", "11", "--normals"]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("many")
    models = root / "models"
    if not os.path.exists(FIXTURES):
        pytest.skip("no CAD fixtures (a build without SFC_BUILD_CAD)")
    subprocess.run([FIXTURES, str(root / "cad")], check=True, capture_output=True)
    models.mkdir()
    for name in ("box_with_hole.step", "cylinder.step", "sphere.step"):
        shutil.copy(root / "cad" / name, models / name)
    v, f = torus_mesh(20, 12, wobble=0.05)
    sfcsampler.write_ply(models / "torus.ply", (v, f))
    v2, f2 = torus_mesh(14, 9, R=2.0, wobble=0.1, seed=5)
    sfcsampler.write_ply(models / "wavy.ply", (v2.astype(np.float32), f2))
    v3, f3 = torus_mesh(10, 8, wobble=0.1, seed=3)
    with open(models / "ring.obj", "w") as out:
        out.writelines("v %r %r %r\n" % tuple(r) for r in v3)
        out.writelines("f %d %d %d\n" % tuple(r + 1) for r in f3)
    (models / "sub").mkdir()
    # A subfolder, mirrored in the output.
    shutil.copy(models / "ring.obj", models / "sub" / "ring.obj")
    (models / "broken.ply").write_bytes((models / "torus.ply").read_bytes()[:700])  # truncated
    (models / "broken.step").write_text("ISO-10303-21;\nthis is not a STEP file\n")
    (models / "notes.txt").write_text("not a model: skipped in a folder\n")
    return models


def listing(root):
    return sorted(os.path.relpath(os.path.join(top, n), root) for top, _, files in os.walk(root)
                  for n in files)


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def run(*args):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)


def alone(path, seed, out, fmt="npy"):
    """`sfcsampler sample` on one model with the given seed and its model column."""
    flags = list(FLAGS)
    flags[flags.index("--seed") + 1] = str(seed)
    flags += ["--face"] if many.model_format(path) not in ("obj", "ply") else ["--triangle"]
    done = run("sample", "--surface", f"{many.model_format(path)}:{path}", *flags, "--format", fmt,
               "-o", out, "-q")
    assert done.returncode == 0, done.stderr
    return out


def test_extensions_and_parse_budget_are_the_clis():
    """many.py keeps no table of its own: its extensions and parse budget are the CLI's
    (request/model_files.h), as `sample-many --help` shows them."""
    shown = run("sample-many", "--help").stdout
    assert f"their {' '.join(many.EXTENSIONS)} files" in shown, shown
    budget = re.search(r"--model-parse-seconds FLOAT:POSITIVE=(\S+)", shown)
    assert budget and float(budget.group(1)) == many.MODEL_PARSE_SECONDS, shown
    assert many.model_format("a/PART.STP") == "step" and many.model_format("notes.txt") is None
    assert set(many.EXTENSIONS.values()) == {"step", "iges", "nurbs", "obj", "ply"}


def test_cli_folder_each_model_as_alone(folder, tmp_path):
    out = tmp_path / "out"
    done = run("sample-many", folder, "-O", out, *FLAGS, "--face", "--triangle", "-j", "2",
               "--manifest", tmp_path / "m.tsv")
    assert done.returncode == 1, done.stderr
    assert listing(out) == sorted(n.rsplit(".", 1)[0] + ".npy" for n in GOOD)
    for name in BROKEN:  # named, with the reader's error
        assert f"FAILED {name}: INVALID_ARGUMENT" in done.stderr, done.stderr
    assert "9 models, 7 written" in done.stderr and "2 failed" in done.stderr
    rows = {r["name"]: r for r in csv.DictReader(open(tmp_path / "m.tsv"), delimiter="\t")}
    assert set(rows) == set(GOOD + BROKEN)
    for name in GOOD:
        path = folder / name
        seed = many.model_seed(11, sha(path))
        # C++ == Python
        assert int(rows[name]["seed"]) == seed and rows[name]["sha256"] == sha(path)
        got = out / (name.rsplit(".", 1)[0] + ".npy")
        assert filecmp.cmp(got, alone(path, seed, tmp_path / "alone.npy"), shallow=False), name
        assert len(np.load(got)) == 3000
    assert rows["broken.ply"]["output"] == "" and "truncated" in rows["broken.ply"]["error"]


def test_cli_order_and_workers_do_not_matter(folder, tmp_path):
    names = folder / "list.txt"  # a list file: paths relative to its folder, in its order
    names.write_text("# reversed\n" + "\n".join(reversed(GOOD)) + "\n")
    one = run("sample-many", names, "-O", tmp_path / "a", *FLAGS, "-j", "1", "-q")
    assert one.returncode == 0, one.stderr
    three = run("sample-many", f"{folder}/*.step", f"{folder}/*.ply", f"{folder}/ring.obj",
                "-O", tmp_path / "b", *FLAGS, "-j", "3", "-q")
    assert three.returncode == 1 and "broken.ply" in three.stderr  # the glob takes broken.ply too
    assert listing(tmp_path / "a") == sorted(n.rsplit(".", 1)[0] + ".npy" for n in GOOD)
    for name in listing(tmp_path / "a"):
        b = tmp_path / "b" / os.path.basename(name)  # the glob names sub/ring.obj ring.obj
        assert filecmp.cmp(tmp_path / "a" / name, b, shallow=False), name


def test_cli_csv_and_ply_formats(folder, tmp_path):
    for fmt in ("csv", "ply"):
        done = run("sample-many", folder / "torus.ply", folder / "sphere.step", "-O",
                   tmp_path / fmt, *FLAGS, "--format", fmt, "--face", "--triangle", "-q")
        assert done.returncode == 0, done.stderr
        for name in ("torus.ply", "sphere.step"):
            seed = many.model_seed(11, sha(folder / name))
            expected = alone(folder / name, seed, tmp_path / f"alone.{fmt}", fmt)
            got = tmp_path / fmt / (name.rsplit(".", 1)[0] + "." + fmt)
            assert filecmp.cmp(got, expected, shallow=False), (fmt, name)


def test_cli_names(folder, tmp_path):
    (tmp_path / "dup").mkdir()
    shutil.copy(folder / "torus.ply", tmp_path / "dup" / "sphere.ply")
    stems = run("sample-many", folder / "sphere.step", tmp_path / "dup", "-O", tmp_path / "o", "-q")
    assert stems.returncode == 0
    assert listing(tmp_path / "o") == ["sphere.ply.npy", "sphere.step.npy"]
    twice = run("sample-many", folder / "sphere.step", folder / "sphere.step", "-O", tmp_path / "o")
    assert twice.returncode == 2 and "would both write" in twice.stderr
    py = sfcsampler.sample_many([folder / "sphere.step", tmp_path / "dup"], count=3000, seed=11,
                                out_dir=tmp_path / "p")
    assert [r.name for r in py] == ["sphere.step", "sphere.ply"] and not py.failed
    assert sorted(os.listdir(tmp_path / "p")) == ["sphere.ply.npy", "sphere.step.npy"]


def test_cli_a_cad_file_that_holds_the_kernel_fails_alone(folder, tmp_path):
    # A sphere whose shell lists its face 40 000 times: valid, and some 15 s of
    # CPU in OpenCASCADE's shell healing. Read in the check program, it is
    # stopped at --model-parse-seconds and named; the other models go on.
    text = (folder / "sphere.step").read_text()
    shell = text.index("CLOSED_SHELL('',(")
    start = text.index("(", text.index(",", shell))
    end = text.index(")", start)
    models = tmp_path / "models"
    models.mkdir()
    (models / "hostile.step").write_text(
        text[:start + 1] + ",".join([text[start + 1:end]] * 40000) + text[end:])
    shutil.copy(folder / "sphere.step", models / "sphere.step")
    shutil.copy(folder / "torus.ply", models / "torus.ply")
    done = run("sample-many", models, "-O", tmp_path / "out", *FLAGS, "--face", "--triangle",
               "--model-parse-seconds", "1", "-j", "2")
    assert done.returncode == 1, done.stderr
    assert "FAILED hostile.step: RESOURCE_EXHAUSTED" in done.stderr
    assert "model_parse_seconds" in done.stderr
    assert listing(tmp_path / "out") == ["sphere.npy", "torus.npy"]
    seed = many.model_seed(11, sha(models / "sphere.step"))
    assert filecmp.cmp(tmp_path / "out" / "sphere.npy",
                       alone(models / "sphere.step", seed, tmp_path / "alone.npy"), shallow=False)
    # Python's sample_many finds the same program and stops the same file.
    assert many.find_model_check_program()
    results = sfcsampler.sample_many(models, count=3000, seed=11, model_parse_seconds=1, workers=2)
    by_name = {r.name: r for r in results}
    assert "RESOURCE_EXHAUSTED" in by_name["hostile.step"].error
    assert by_name["sphere.step"].ok and by_name["torus.ply"].ok


def test_cli_bad_usage(folder, tmp_path):
    empty = run("sample-many", tmp_path / "nothing-*.obj", "-O", tmp_path / "o")
    assert empty.returncode == 2 and "matches no files" in empty.stderr
    bad = run("sample-many", folder, "-O", tmp_path / "o", "--sequence", "nonsense")
    assert bad.returncode == 2 and "--sequence must be" in bad.stderr
    density = run("sample-many", folder / "torus.ply", "-O", tmp_path / "o", "--density",
                  "nonsense")
    assert density.returncode == 1
    assert 'FAILED torus.ply: INVALID_ARGUMENT: unknown density "nonsense"' in density.stderr


def test_python_sample_many_equals_sample_alone(folder, tmp_path):
    results = sfcsampler.sample_many(folder, count=3000, seed=11, normals=True, face=True,
                                     triangle=True, workers=3)
    assert [r.name for r in results] == sorted(GOOD + BROKEN)
    assert {r.name for r in results.failed} == set(BROKEN)
    assert all("INVALID_ARGUMENT" in r.error for r in results.failed)
    assert "2 failed" in results.summary() and "FAILED broken.step" in results.summary()
    assert [r.name for r in results if r.ok] == GOOD
    for r in results:
        if not r.ok:
            continue
        fmt = many.model_format(r.name)
        assert r.seed == many.model_seed(11, sha(folder / r.name))
        cols = dict(face=True) if fmt not in ("obj", "ply") else dict(triangle=True)
        same_samples(r.samples, sfcsampler.sample(surface=f"{fmt}:{folder / r.name}", count=3000,
                                                  seed=r.seed, normals=True, **cols))
        assert r.count == len(r.samples) == 3000
    # Another order on one worker: the same samples; written files equal the CLI's.
    again = sfcsampler.sample_many({n: folder / n for n in reversed(GOOD)}, count=3000, seed=11,
                                   normals=True, face=True, triangle=True, workers=1,
                                   out_dir=tmp_path / "py", keep=True)
    by_name = {r.name: r for r in results}
    for r in again:
        same_samples(r.samples, by_name[r.name].samples)
    cli = run("sample-many", folder, "-O", tmp_path / "cli", *FLAGS, "--face", "--triangle", "-q")
    assert cli.returncode == 1, cli.stderr
    for name in listing(tmp_path / "cli"):
        assert filecmp.cmp(tmp_path / "py" / name, tmp_path / "cli" / name, shallow=False), name


def test_python_meshes_in_memory_and_progress(capsys):
    meshes = {f"m{k}": torus_mesh(8 + k, 6, wobble=0.1, seed=k) for k in range(5)}
    results = sfcsampler.sample_many(meshes, count=2000, seed=3, workers=2, progress=True)
    assert not results.failed
    for r in results:
        ply = sfcsampler.meshes.mesh_ply(meshes[r.name])
        assert r.sha256 == hashlib.sha256(ply).hexdigest()
        same_samples(r.samples, sfcsampler.sample(mesh=meshes[r.name], count=2000,
                                                  seed=many.model_seed(3, r.sha256)))
    assert "5/5 models, 0 failed" in capsys.readouterr().err
    with pytest.raises(TypeError, match="first argument"):
        sfcsampler.sample_many(meshes, surface="sphere")


def test_python_meshes_as_arrays_are_bit_for_bit_single_calls():
    # Arrays take sample_many's C++ path (Engine.sample_mesh_arrays: the PLY, its hash, the seed
    # and the samples in one call); every mesh must still be exactly sample(mesh=...) with its
    # derived seed, for every kind of input and any worker count: int64 and int32 faces (the
    # C++ path), float32 vertices, Fortran order and a list (the other path), a bad mesh.
    base = [torus_mesh(9 + k, 7, wobble=0.1, seed=k) for k in range(4)]
    meshes = {"i64": base[0], "i32": (base[1][0], base[1][1].astype(np.int32)),
              "f32": (base[2][0].astype(np.float32), base[2][1]),
              "fortran": (np.asfortranarray(base[3][0]), base[3][1]),
              "list": [base[0][0] * 2, base[0][1]],
              "bad": (base[1][0], base[1][1] + 1000)}
    request = dict(count=1500, seed=7, normals=True, triangle=True, density_column=True,
                   curve_position=True)
    alone = {}
    for name, mesh in meshes.items():
        if name == "bad":
            continue
        seed = many.model_seed(7, hashlib.sha256(sfcsampler.meshes.mesh_ply(mesh)).hexdigest())
        alone[name] = (seed, {p: sfcsampler.sample(mesh=mesh, precision=p,
                                                   **dict(request, seed=seed))
                              for p in ("float64", "float32")})
    for workers in (1, 2, 3):
        for precision in ("float64", "float32"):
            results = sfcsampler.sample_many(meshes, workers=workers, precision=precision,
                                             **request)
            assert [r.name for r in results.failed] == ["bad"]
            assert "vertex indices must lie in" in results.failed[0].error
            for r in results:
                if r.ok:
                    assert r.seed == alone[r.name][0] and r.count == 1500
                    same_samples(r.samples, alone[r.name][1][precision])
    # columns=: only those, the same bytes.
    points = sfcsampler.sample_many(meshes, workers=2, columns=("x", "y", "z"), **request)
    for r in points:
        if r.ok:
            assert r.samples.index is None and r.samples.normals is None
            assert np.array_equal(r.samples.points, alone[r.name][1]["float64"].points)


def test_python_sample_many_keeps_and_writes_only_the_named_columns(folder, tmp_path):
    names = [folder / "torus.ply", folder / "sphere.step"]
    full = sfcsampler.sample_many(names, count=2000, seed=5, triangle=True)
    some = sfcsampler.sample_many(names, count=2000, seed=5, triangle=True,
                                  columns=["x", "y", "z", "triangle"])
    assert not some.failed, some.summary()
    for a, b in zip(full, some):
        assert b.samples.index is None and b.samples.u is None and len(b.samples) == 2000
        assert np.array_equal(a.samples.points, b.samples.points)
    # The mesh keeps its triangle column; the CAD model has none to keep.
    assert np.array_equal(some[0].samples.triangle, full[0].samples.triangle)
    assert some[1].samples.triangle is None
    written = sfcsampler.sample_many(names, count=2000, seed=5, columns=iter(["x", "y", "z"]),
                                     out_dir=tmp_path)  # a one-shot iterator serves every model
    assert not written.failed, written.summary()
    assert all(np.load(r.path).dtype.names == ("x", "y", "z") for r in written)
    # The CLI's --columns writes the same files byte for byte.
    cli = run("sample-many", folder / "torus.ply", folder / "sphere.step", "-O", tmp_path / "cli",
              "--count", "2000", "--seed", "5", "--columns", "x,y,z", "-q")
    assert cli.returncode == 0, cli.stderr
    for r in written:
        assert filecmp.cmp(r.path, tmp_path / "cli" / os.path.basename(r.path), shallow=False)
    faces_only = sfcsampler.sample_many(names, count=100, face=True, columns=["face"])
    assert "no 'face' column" in faces_only[0].error and faces_only[1].ok
    with pytest.raises(sfcsampler.InvalidArgumentError, match="unknown column 'w'"):
        sfcsampler.sample_many(names, count=100, columns=["x", "w"])


def test_python_sample_many_over_the_wire(server, folder):
    names = [folder / "torus.ply", folder / "sphere.step", folder / "broken.ply"]
    local = sfcsampler.sample_many(names, count=2000, seed=5)
    remote = sfcsampler.sample_many(names, count=2000, seed=5, server=server)
    assert [r.ok for r in remote] == [True, True, False]
    # The result is named by its file; the server names a stored model by its
    # format and hash, never by an upload name (issue 21).
    assert remote[2].name.endswith("broken.ply")
    assert "INVALID_ARGUMENT" in remote[2].error and remote[2].sha256 in remote[2].error
    assert "broken.ply" in remote.summary()
    for a, b in zip(local[:2], remote[:2]):
        same_samples(a.samples, b.samples)


def test_cli_over_the_wire_same_files(server, folder, tmp_path):
    local = run("sample-many", folder, "-O", tmp_path / "local", *FLAGS, "--face", "--triangle",
                "-q")
    remote = run("sample-many", folder, "-O", tmp_path / "remote", *FLAGS, "--face", "--triangle",
                 "--server", server, "-j", "3", "-q")
    assert local.returncode == remote.returncode == 1, remote.stderr
    for name in BROKEN:
        assert f"FAILED {name}: INVALID_ARGUMENT" in remote.stderr, remote.stderr
    assert listing(tmp_path / "remote") == listing(tmp_path / "local") != []
    for name in listing(tmp_path / "local"):
        assert filecmp.cmp(tmp_path / "local" / name, tmp_path / "remote" / name,
                           shallow=False), name
    f32 = run("sample-many", folder / "torus.ply", "-O", tmp_path / "f32", *FLAGS, "--precision",
              "float32", "--server", server, "-q")
    f32_local = run("sample-many", folder / "torus.ply", "-O", tmp_path / "f32l", *FLAGS,
                    "--precision", "float32", "-q")
    assert f32.returncode == f32_local.returncode == 0
    assert filecmp.cmp(tmp_path / "f32" / "torus.npy", tmp_path / "f32l" / "torus.npy",
                       shallow=False)
