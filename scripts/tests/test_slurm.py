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
kappa = { start = 0.0, stop = 1.5, num = 30 }
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
