"""The quick start (scripts/quickstart.sh) without the package's compiled core: it reads and
draws with the package's Python source (PYTHONPATH=python) in a .venv that holds only
scripts/requirements-quickstart.txt. And the stamps of scripts/setup.sh: the quick start's
partial .venv never passes for the full set-up's."""
from __future__ import annotations

import os
import re
import shutil
import stat
import subprocess
import sys
from pathlib import Path

from conftest import BIN, ROOT

SMALL_DEMO = """
name = "small-demo"
[body]
nu = 0.5
eta = 0.5
[axes]
alpha = [0.5]
beta = [3.0]
kappa = { start = 0.0, stop = 2.0, num = 21 }
energy = { start = 0.5, stop = 4.5, num = 17 }
[outputs]
fields = ["theta_min", "theta_max", "period", "omega_theta", "omega_psi", "rotation_number",
          "drift", "drift_radius", "bounded", "motion", "status", "error_estimate"]
"""

# The importable modules of the full set-up's requirements that the quick start's lack.
MODULES = {"tqdm": ["tqdm"], "pytest": ["pytest", "_pytest"], "mpmath": ["mpmath"], "scipy": ["scipy"],
           "gmpy2": ["gmpy2"], "dask": ["dask"], "maturin": ["maturin"], "cfchecker": ["cfchecker"],
           "compliance-checker": ["compliance_checker"], "netCDF4": ["netCDF4", "cftime"]}

# Run by the interpreter under test with PYTHONPATH=<a copy of python/>: the quick start's
# Python calls, with the modules of the full set-up hidden.
DRIVER = """
import importlib.machinery, runpy, sys
folder, atlas, table, csv_table, hidden, source, scripts = sys.argv[1:8]
hidden = set(hidden.split(","))


# The path finder, blind to the hidden packages (as if they were not installed).
class Hiding(importlib.machinery.PathFinder):
    @classmethod
    def find_spec(cls, name, path=None, target=None):
        if name.partition(".")[0] in hidden:
            return None
        return super().find_spec(name, path, target)


sys.meta_path[:] = [Hiding if f is importlib.machinery.PathFinder else f for f in sys.meta_path]
assert Hiding in sys.meta_path
import rubber_atlas as ra
assert ra.HAS_CORE is False, "the compiled core was found"
assert ra.__file__.startswith(source), ra.__file__
ds = ra.open_atlas(atlas)
print(ds)
print(ds.rubber.families(), ds.rubber.components(alpha=0.5, beta=3.0, kappa=0.8, energy=2.5))
try:
    ra.cells(0.5, 3.0, 0.5, 0.5, 0.8, 2.5)
except ImportError as e:
    print("cells:", e)
else:
    raise AssertionError("cells computed without the core")
for script, args in (("plot_atlas.py", [atlas, "--out", f"{folder}/demo.png"]),
                     ("plot_trajectory.py", [table, "--out", f"{folder}/xy.png"]),
                     ("plot_trajectory.py", [csv_table, "--out", f"{folder}/xy-csv.png"])):
    sys.argv = [script] + args
    try:
        runpy.run_path(f"{scripts}/{script}", run_name="__main__")
    except SystemExit as e:
        if e.code not in (0, None):
            raise
"""


def test_the_quick_start_draws_without_the_compiled_core(make_atlas, tmp_path):
    atlas = make_atlas("small-demo", SMALL_DEMO)
    tables = []
    for suffix in ("h5", "csv"):
        out = tmp_path / f"xy.{suffix}"
        subprocess.run([BIN, "trajectory", "--alpha", "0.5", "--beta", "3", "--nu", "0.5", "--eta", "0.5",
                        "--kappa", "0.8", "--theta0", "0.4670288", "--periods", "2", "--samples", "400",
                        "--out", str(out), "--force"], check=True, capture_output=True)
        tables.append(out)
    # The package's Python source alone (a core built into python/ by `maturin develop` stays out).
    source = tmp_path / "python"
    (source / "rubber_atlas").mkdir(parents=True)
    for f in (ROOT / "python" / "rubber_atlas").glob("*.py"):
        shutil.copy(f, source / "rubber_atlas" / f.name)
    full = requirement_names(ROOT / "scripts" / "requirements.txt")
    quick = requirement_names(ROOT / "scripts" / "requirements-quickstart.txt")
    assert set(MODULES) == set(full) - set(quick), "MODULES must name every package the quick start lacks"
    hidden = ",".join(m for ms in MODULES.values() for m in ms)
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    env = dict(os.environ, PYTHONPATH=str(source), MPLBACKEND="Agg")
    done = subprocess.run([sys.executable, str(driver), str(tmp_path), str(atlas), str(tables[0]), str(tables[1]),
                           hidden, str(source), str(ROOT / "scripts")], env=env, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "<xarray.Dataset>" in done.stdout and "rotation_number" in done.stdout
    assert "cells: rubber_atlas's compiled core is not installed: `pip install .`" in done.stdout
    for name in ("demo.png", "xy.png", "xy-csv.png"):
        assert f"wrote {tmp_path}/{name}" in done.stdout
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (tmp_path / name).stat().st_size > 15_000


def requirement_names(path: Path) -> list[str]:
    """The packages a requirements file names itself (not through -r)."""
    names = []
    for line in path.read_text().splitlines():
        line = line.split("#")[0].strip()
        if line and not line.startswith("-"):
            names.append(re.split(r"[<>=!~;\[ ]", line)[0])
    return names


def test_the_full_requirements_include_the_quick_starts():
    text = (ROOT / "scripts" / "requirements.txt").read_text()
    assert re.search(r"^-r requirements-quickstart\.txt$", text, re.M)
    quick = requirement_names(ROOT / "scripts" / "requirements-quickstart.txt")
    assert {"numpy", "h5py", "xarray", "h5netcdf", "matplotlib"} <= set(quick)
    assert not set(quick) & set(requirement_names(ROOT / "scripts" / "requirements.txt"))


FAKE_PYTHON = """#!/usr/bin/env bash
# Logs what setup.sh asks of Python; "installs" the package as a marker file.
echo "python $*" >> LOG
case "$*" in
  "-m pip install"*" -r "*) ;;
  "-m pip install"*) touch MARKER ;;
  "-c import rubber_atlas._core") [ -e MARKER ] ;;
esac
"""


def executable(path: Path, text: str) -> None:
    path.write_text(text)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)


def test_setup_stamps_keep_a_later_full_set_up_correct(tmp_path):
    """In a copy of the tree's set-up files with a fake Python (and a fake apt-get that does
    nothing): the quick start's set-up installs only its requirements and no package; the
    full set-up after it installs everything; each says when nothing is to do."""
    root = tmp_path / "repo"
    (root / "scripts").mkdir(parents=True)
    for name in ("setup.sh", "requirements.txt", "requirements-quickstart.txt"):
        shutil.copy(ROOT / "scripts" / name, root / "scripts" / name)
    for name in ("Cargo.toml", "Cargo.lock", "build.rs", "pyproject.toml", "src/lib.rs",
                 "python/rubber_atlas/__init__.py"):
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text("")
    log, marker = tmp_path / "log", tmp_path / "package-installed"
    (root / ".venv" / "bin").mkdir(parents=True)
    executable(root / ".venv" / "bin" / "python",
               FAKE_PYTHON.replace("LOG", str(log)).replace("MARKER", str(marker)))
    fake = tmp_path / "bin"
    fake.mkdir()
    executable(fake / "apt-get", f"#!/usr/bin/env bash\necho \"apt-get $*\" >> {log}\n")
    executable(fake / "sudo", "#!/usr/bin/env bash\nexec \"$@\"\n")
    env = dict(os.environ, PATH=f"{fake}:{os.environ['PATH']}")

    def setup(*args) -> tuple[str, list[str]]:
        before = log.read_text().splitlines() if log.exists() else []
        done = subprocess.run(["bash", str(root / "scripts" / "setup.sh"), *args], env=env, capture_output=True,
                              text=True, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        after = log.read_text().splitlines() if log.exists() else []
        return done.stdout, [line for line in after[len(before):] if "pip install" in line]

    def current() -> bool:
        return subprocess.run(["bash", str(root / "scripts" / "setup.sh"), "--package-is-current"], env=env,
                              cwd=tmp_path).returncode == 0

    quick_r = f"-r {root}/scripts/requirements-quickstart.txt"
    full_r = f"-r {root}/scripts/requirements.txt"
    out, pip = setup("--quickstart")
    assert len(pip) == 1 and pip[0].endswith(quick_r), pip
    assert "installing the quick start's Python packages" in out and not current()
    out, pip = setup("--quickstart")
    assert pip == [] and "quick start's Python packages already installed" in out
    # The full set-up after the quick start's: everything, and the package.
    out, pip = setup()
    assert len(pip) == 2 and pip[0].endswith(full_r) and pip[1].endswith(str(root)), pip
    assert current()
    out, pip = setup()
    assert pip == [] and "already installed" in out and "installed and current" in out
    out, pip = setup("--quickstart")
    assert pip == []
    # A changed source rebuilds the package only; a changed quick-start list reinstalls the full one.
    (root / "src" / "lib.rs").write_text("// changed\n")
    assert not current()
    out, pip = setup()
    assert len(pip) == 1 and pip[0].endswith(str(root)) and current()
    with (root / "scripts" / "requirements-quickstart.txt").open("a") as f:
        f.write("# changed\n")
    out, pip = setup()
    assert len(pip) == 1 and pip[0].endswith(full_r), pip
    done = subprocess.run(["bash", str(root / "scripts" / "setup.sh"), "--bogus"], env=env, capture_output=True,
                          text=True)
    assert done.returncode == 2 and "unknown option --bogus" in done.stderr
