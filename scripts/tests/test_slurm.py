"""scripts/slurm/atlas.sbatch run as Slurm would run it (array tasks with SLURM_* set, then
the merge job), without Slurm: the merged atlas equals a single run, array for array."""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BIN = str(Path(os.environ.get("RUBBER_ATLAS_BIN", ROOT / "target" / "release" / "rubber-atlas")).resolve())
SBATCH = ROOT / "scripts" / "slurm" / "atlas.sbatch"

SCENE = """name = "tiny"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = [0.3, 0.5]
beta = [3.0]
kappa = { start = 0.0, stop = 1.5, num = 60 }
energy = { start = 0.5, stop = 4.0, num = 200 }
[solver]
tolerance = 1e-9
"""


def sbatch(cwd: Path, *args: str, task: int | None = None, count: int = 3) -> str:
    env = dict(os.environ, RUBBER_ATLAS_BIN=BIN)
    if task is not None:
        env.update(SLURM_ARRAY_TASK_ID=str(task), SLURM_ARRAY_TASK_COUNT=str(count), SLURM_CPUS_PER_TASK="1")
    out = subprocess.run(["bash", str(SBATCH), *args], cwd=cwd, env=env, check=True, capture_output=True, text=True)
    return out.stdout + out.stderr


def test_array_tasks_then_merge_equal_a_single_run(tmp_path):
    (tmp_path / "atlas").mkdir()
    (tmp_path / "atlas" / "tiny.toml").write_text(SCENE)
    for task in (1, 2, 3):
        sbatch(tmp_path, "atlas/tiny.toml", task=task)
    # A requeued task whose shard is complete does nothing.
    assert "nothing to do" in sbatch(tmp_path, "atlas/tiny.toml", task=2)
    sbatch(tmp_path, "--merge", "atlas/tiny.toml", "3")
    single = tmp_path / "single.h5"
    subprocess.run([BIN, "run", str(tmp_path / "atlas" / "tiny.toml"), "--out", str(single), "--quiet"], check=True)
    with h5py.File(tmp_path / "atlas" / "tiny.h5") as merged, h5py.File(single) as one:
        assert sorted(merged) == sorted(one)
        for name in one:
            a, b = merged[name][()], one[name][()]
            assert a.tobytes() == b.tobytes(), name
        assert np.isfinite(one["rotation_number"][()]).any()


def _single(tmp_path: Path, scene: Path) -> Path:
    single = tmp_path / "single.h5"
    subprocess.run([BIN, "run", str(scene), "--out", str(single), "--quiet", "--force"], check=True)
    return single


def _same_arrays(a: Path, b: Path) -> bool:
    with h5py.File(a) as x, h5py.File(b) as y:
        return sorted(x) == sorted(y) and all(x[n][()].tobytes() == y[n][()].tobytes() for n in y)


def test_resubmission_after_a_scene_edit_recomputes_and_merges_again(tmp_path):
    """Issue 13 #3: after an edit of the scene (its tolerance), a resubmitted array task
    recomputes its shard instead of saying "nothing to do", and the merge job replaces the
    old merged atlas. A scene name in single quotes (valid TOML) names the files."""
    (tmp_path / "atlas").mkdir()
    scene = tmp_path / "atlas" / "tiny.toml"
    scene.write_text(SCENE.replace('name = "tiny"', "name = 'sq'"))
    for task in (1, 2, 3):
        sbatch(tmp_path, "atlas/tiny.toml", task=task)
    sbatch(tmp_path, "--merge", "atlas/tiny.toml", "3")
    merged = tmp_path / "atlas" / "sq.h5"
    assert _same_arrays(merged, _single(tmp_path, scene))
    scene.write_text(scene.read_text().replace("tolerance = 1e-9", "tolerance = 1e-6"))
    for task in (1, 2, 3):
        assert "nothing to do" not in sbatch(tmp_path, "atlas/tiny.toml", task=task)
    # Now current: a requeue does nothing.
    assert "nothing to do" in sbatch(tmp_path, "atlas/tiny.toml", task=1)
    sbatch(tmp_path, "--merge", "atlas/tiny.toml", "3")
    assert _same_arrays(merged, _single(tmp_path, scene))
    with h5py.File(merged) as f:
        assert f.attrs["tolerance"] == 1e-6


def test_a_shard_left_by_another_build_is_recomputed(tmp_path):
    """A shard whose fingerprint is not this build's (here: altered by hand) is stale."""
    (tmp_path / "atlas").mkdir()
    (tmp_path / "atlas" / "tiny.toml").write_text(SCENE)
    sbatch(tmp_path, "atlas/tiny.toml", task=1)
    shard = tmp_path / "atlas" / "tiny.shard-1-of-3.h5"
    with h5py.File(shard, "r+") as f:
        f.attrs["scene_fingerprint"] = "0123456789abcdef"
    assert "nothing to do" not in sbatch(tmp_path, "atlas/tiny.toml", task=1)
    assert "nothing to do" in sbatch(tmp_path, "atlas/tiny.toml", task=1)


def test_submit_passes_options_and_names_logs(tmp_path):
    """submit.sh with a stand-in sbatch on PATH: the array and the merge job get the extra
    options (partition, account), logs go to atlas/logs/ (created), the merge job's log is
    named by its own job id, and a requeue appends to a task's log."""
    bindir = tmp_path / "bin"
    bindir.mkdir()
    calls = tmp_path / "calls.txt"
    fake = bindir / "sbatch"
    fake.write_text(f'#!/usr/bin/env bash\nprintf "%s\\n" "$*" >> {calls}\necho 4242\n')
    fake.chmod(0o755)
    env = dict(os.environ, PATH=f"{bindir}:{os.environ['PATH']}", RUBBER_ATLAS_BIN=BIN)
    (tmp_path / "atlas").mkdir()
    (tmp_path / "atlas" / "tiny.toml").write_text(SCENE)
    submit = ["bash", str(ROOT / "scripts" / "slurm" / "submit.sh"), "atlas/tiny.toml"]
    # 7 shards do not tile the 2 x 1 x 3 grid: refused in one line, nothing queued.
    refused = subprocess.run([*submit, "7"], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert refused.returncode == 2 and "do not tile" in refused.stderr and not calls.exists()
    subprocess.run([*submit, "3", "--partition=short", "--account=proj"], cwd=tmp_path, env=env, check=True,
                   capture_output=True)
    array, merge = calls.read_text().splitlines()
    assert "--array=1-3" in array and "--partition=short" in array and "--account=proj" in array
    assert "--dependency=afterok:4242" in merge and "--partition=short" in merge and "--account=proj" in merge
    assert "--output=atlas/logs/%x-%j.out" in merge
    assert (tmp_path / "atlas" / "logs").is_dir()
    text = SBATCH.read_text()
    assert "#SBATCH --output=atlas/logs/%x-%A_%a.out" in text and "#SBATCH --open-mode=append" in text
    ignored = subprocess.run(["git", "check-ignore", "-q", "atlas/logs/rubber-atlas-1_1.out"], cwd=ROOT)
    assert ignored.returncode == 0


def _first_shard_and_a_copy(tmp_path: Path) -> tuple[Path, Path]:
    """Shard 1 of 3 of the tiny scene, made by its array task, and a copy of it."""
    (tmp_path / "atlas").mkdir()
    (tmp_path / "atlas" / "tiny.toml").write_text(SCENE)
    sbatch(tmp_path, "atlas/tiny.toml", task=1)
    shard = tmp_path / "atlas" / "tiny.shard-1-of-3.h5"
    good = tmp_path / "good.h5"
    good.write_bytes(shard.read_bytes())
    return shard, good


def test_a_damaged_shard_is_not_taken_as_current(tmp_path):
    """--update reads the whole shard: one with a variable missing, or a chunk overwritten,
    is recomputed; the result equals the undamaged shard."""
    shard, good = _first_shard_and_a_copy(tmp_path)
    with h5py.File(shard, "r+") as f:
        del f["drift"]
    assert "nothing to do" not in sbatch(tmp_path, "atlas/tiny.toml", task=1)
    assert _same_arrays(shard, good)
    data = bytearray(shard.read_bytes())
    middle = len(data) // 2
    data[middle:middle + 4096] = b"\xff" * 4096
    shard.write_bytes(bytes(data))
    assert "nothing to do" not in sbatch(tmp_path, "atlas/tiny.toml", task=1)
    assert _same_arrays(shard, good)


def _attributes(path: Path) -> dict:
    """Every attribute of the root and of each dataset, as text (references by the name of
    the object they point to), and each dataset's dimension scales."""
    out = {}
    with h5py.File(path) as f:
        for name, obj in [("/", f)] + [(n, f[n]) for n in sorted(f)]:
            for key in obj.attrs:
                if key in ("DIMENSION_LIST", "REFERENCE_LIST"):
                    continue
                out[(name, key)] = repr(obj.attrs[key])
            if name != "/":
                out[(name, "dims")] = [[scale.name for scale in d.values()] for d in obj.dims]
    return out


def test_a_shard_with_a_flipped_bit_is_recomputed_or_unchanged(tmp_path):
    """Issue 22: --update on a shard with one bit flipped, anywhere in the file, either
    recomputes it (then its values equal the undamaged shard's) or keeps it as current only
    where the flip changed nothing a reader sees: values, attributes (text included, by the
    file's text_attributes_crc32) and dimension scales. Also a flip in a text attribute and
    one in a coordinate's values, each at a known place."""
    import random

    shard, good = _first_shard_and_a_copy(tmp_path)
    pristine = good.read_bytes()
    seen = _attributes(good)
    text = pristine.find(b"unbounded bounded no_value")
    with h5py.File(good) as f:
        kappa = f["kappa"].id.get_chunk_info(0).byte_offset
    assert text > 0 and kappa is not None
    rng = random.Random(22)
    flips = [(text + 20, 1), (kappa + 8 * 5 + 3, 16)]
    flips += [(rng.randrange(len(pristine)), 1 << rng.randrange(8)) for _ in range(40)]
    kept = 0
    for offset, bit in flips:
        data = bytearray(pristine)
        data[offset] ^= bit
        shard.write_bytes(bytes(data))
        said = sbatch(tmp_path, "atlas/tiny.toml", task=1)
        if "nothing to do" in said:
            kept += 1
            assert _same_arrays(shard, good), offset
            assert _attributes(shard) == seen, offset
        else:
            assert _same_arrays(shard, good), offset
    # The two placed flips were recomputed; most random ones hit the structure.
    assert kept < len(flips) - 2
