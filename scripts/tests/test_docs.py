"""Every code block of README.md and docs/*.md runs, so that the documentation cannot drift
from the program.

Which blocks run is decided by the info string of the fence:
- ```python (or ```py): run with this interpreter (the venv's Python, which has rubber_atlas).
  The Python blocks of one file share one namespace, in document order.
- ```bash (or ```sh): run with `bash -e -o pipefail`, `rubber-atlas` on PATH (the directory
  of RUBBER_ATLAS_BIN) and `python` the venv's.
- anything else does not run: ```text for command synopses and set-up commands, ```console
  for a session shown with its output, ```toml, ```json, ```csv, ... A fence without an info
  string is refused (say what the block is).

The blocks of one file run in document order, Python and shell interleaved, in one process
(a driver: this file run as a script) in a fresh temporary folder that holds a copy of the
repository's atlas/*.toml and links to its scripts/ and docs/ folders, so that paths such as
`atlas/demo.toml` or `scripts/plot_atlas.py` resolve. matplotlib draws with Agg. A failing
block fails the file's test with the file name and the block's first line, e.g.
`docs/scenes.md:42`; Python tracebacks show the markdown file's own line numbers.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = os.environ.get("RUBBER_ATLAS_BIN", str(ROOT / "target" / "release" / "rubber-atlas"))

# Info-string words that run, and how.
RUNNERS = {"python": "python", "py": "python", "bash": "bash", "sh": "bash"}
# The whole file may take this long (each block is meant to take seconds).
FILE_TIMEOUT = 600

FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})\s*(?P<info>[^`]*?)\s*$")


@dataclass
class Block:
    path: str  # as shown in messages (relative to the repository when possible)
    line: int  # 1-based line of the block's first content line
    info: str  # the first word of the info string, lower case ("" if none)
    source: str

    @property
    def runner(self) -> str | None:
        return RUNNERS.get(self.info)

    @property
    def where(self) -> str:
        return f"{self.path}:{self.line}"


def shown(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


def blocks(path: Path) -> list[Block]:
    """The fenced code blocks of a markdown file (CommonMark fences: ``` or ~~~, at most
    three spaces of indentation, closed by a fence of the same character at least as long).
    Raises ValueError for a fence left open."""
    found: list[Block] = []
    lines = path.read_text(encoding="utf-8").splitlines()
    name = shown(path)
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        fence, indent = m["fence"], len(m["indent"])
        info = m["info"].split()[0].lower() if m["info"].split() else ""
        start = i + 1
        body: list[str] = []
        i += 1
        while i < len(lines):
            close = FENCE.match(lines[i])
            if close and close["fence"][0] == fence[0] and len(close["fence"]) >= len(fence) and not close["info"]:
                break
            line = lines[i]
            # Content is de-indented by the fence's indentation (CommonMark).
            strip = len(line) - len(line.lstrip(" "))
            body.append(line[min(indent, strip):])
            i += 1
        else:
            raise ValueError(f"{name}:{start}: a code fence {fence} is never closed")
        found.append(Block(name, start + 1, info, "\n".join(body) + "\n"))
        i += 1
    return found


def documents() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def prepare(folder: Path) -> None:
    """The blocks' working folder: atlas/*.toml copied (runs write beside their scene),
    scripts/ and docs/ linked (read only)."""
    (folder / "atlas").mkdir(parents=True, exist_ok=True)
    for scene in (ROOT / "atlas").glob("*.toml"):
        shutil.copy(scene, folder / "atlas" / scene.name)
    for name in ("scripts", "docs"):
        link = folder / name
        if not link.exists():
            link.symlink_to(ROOT / name, target_is_directory=True)


def environment() -> dict[str, str]:
    env = dict(os.environ)
    bin_dir = str(Path(BIN).resolve().parent)
    python_dir = str(Path(sys.executable).parent)  # not resolved: the venv's bin/
    env["PATH"] = os.pathsep.join([bin_dir, python_dir, env.get("PATH", "")])
    env["MPLBACKEND"] = "Agg"
    env["RUBBER_ATLAS_BIN"] = str(Path(BIN).resolve())
    env.setdefault("PYTHONDONTWRITEBYTECODE", "1")
    return env


# --- the driver: runs the blocks of one file in the current folder --------------------------

def run_file(path: Path, keep_going: bool = False) -> int:
    """Runs the blocks of `path` in order in the current folder; 0 if all pass, else 1 after
    naming the failing block (with `keep_going`, after running the rest too)."""
    namespace: dict = {"__name__": "__main__"}
    failed = 0
    for block in blocks(path):
        if block.runner is None:
            continue
        began = time.perf_counter()
        print(f"--- {block.where} ({block.info})", flush=True)
        if block.runner == "python":
            # Blank lines in front: tracebacks give the markdown file's line numbers.
            code_text = "\n" * (block.line - 1) + block.source
            try:
                code = compile(code_text, block.path, "exec")
                exec(code, namespace)
            except BaseException:  # noqa: BLE001 - report anything, SystemExit included
                traceback.print_exc()
                print(f"docs test: the python block at {block.where} failed", flush=True)
                failed = 1
                if keep_going:
                    continue
                return 1
            finally:
                try:
                    import matplotlib.pyplot as plt

                    plt.close("all")
                except ImportError:
                    pass
        else:
            sys.stdout.flush()
            done = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", block.source])
            if done.returncode != 0:
                print(f"docs test: the {block.info} block at {block.where} failed "
                      f"(exit status {done.returncode})", flush=True)
                failed = 1
                if keep_going:
                    continue
                return 1
        print(f"--- {block.where} passed in {time.perf_counter() - began:.1f} s", flush=True)
    return failed


def drive(path: Path, folder: Path) -> subprocess.CompletedProcess:
    """Runs this file as the driver for `path` in `folder`; output captured."""
    prepare(folder)
    return subprocess.run([sys.executable, str(Path(__file__).resolve()), str(path.resolve())],
                          cwd=folder, env=environment(), capture_output=True, text=True,
                          timeout=FILE_TIMEOUT)


if __name__ == "__main__":
    # python scripts/tests/test_docs.py [--keep-going] FILE.md, in a prepared folder (the
    # tests call it so); --keep-going runs every block and reports each failure.
    keep = "--keep-going" in sys.argv[1:]
    files = [a for a in sys.argv[1:] if a != "--keep-going"]
    sys.exit(run_file(Path(files[0]), keep_going=keep))


# --- the tests -------------------------------------------------------------------------------

import pytest  # noqa: E402


@pytest.mark.parametrize("path", documents(), ids=shown)
def test_code_blocks_run(path: Path, tmp_path: Path) -> None:
    assert Path(BIN).exists(), f"the rubber-atlas binary is missing: {BIN} (set RUBBER_ATLAS_BIN)"
    runnable = [b for b in blocks(path) if b.runner]
    if not runnable:
        return
    done = drive(path, tmp_path)
    if done.returncode != 0:
        failed = re.findall(r"docs test: .* at (\S+:\d+) failed.*", done.stdout)
        where = failed[-1] if failed else shown(path)
        pytest.fail(f"{where}: a code block failed\n--- stdout\n{done.stdout[-6000:]}\n"
                    f"--- stderr\n{done.stderr[-6000:]}", pytrace=False)


def test_blocks_are_found() -> None:
    """The docs are there and have runnable blocks (a broken parser would pass everything)."""
    paths = documents()
    assert (ROOT / "README.md").exists()
    assert len(paths) >= 2, "no docs/*.md found"
    runnable = {shown(p): sum(1 for b in blocks(p) if b.runner) for p in paths}
    assert sum(runnable.values()) > 0, "no runnable code block in README.md or docs/*.md"
    assert runnable["README.md"] > 0, "README.md has no runnable code block"


def test_every_fence_says_what_it_is() -> None:
    """A bare ``` would silently not run: every block names its language (or text)."""
    bare = [b.where for p in documents() for b in blocks(p) if not b.info]
    assert not bare, f"code blocks without an info string (use ```text if it must not run): {bare}"


def test_no_reference_to_files_outside_the_repository() -> None:
    """The docs cite only what the repository holds: no developer notes outside it."""
    bad = []
    for p in documents():
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1):
            if re.search(r"SPEC\b|shared/", line):
                bad.append(f"{shown(p)}:{n}: {line.strip()[:80]}")
    assert not bad, "references to files the repository does not contain:\n" + "\n".join(bad)


LINK = re.compile(r"\]\((?!https?://|mailto:)([^)\s]+)\)")


def anchors(path: Path) -> set[str]:
    """The anchors GitHub gives the headings of a markdown file (lower case, punctuation
    dropped, spaces to hyphens; repeats get -1, -2, ...)."""
    found: set[str] = set()
    fenced = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            fenced = not fenced
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m and not fenced:
            slug = re.sub(r"[^\w\- ]", "", m[1].lower()).replace(" ", "-")
            candidate, k = slug, 0
            while candidate in found:
                k += 1
                candidate = f"{slug}-{k}"
            found.add(candidate)
    return found


def test_local_links_exist() -> None:
    """Every relative link and image of the docs points at a file of the repository, and
    every #anchor at a heading of its file."""
    missing = []
    for p in documents():
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1):
            for target in LINK.findall(line):
                file, _, anchor = target.partition("#")
                where = p if not file else p.parent / file
                if not where.exists():
                    missing.append(f"{shown(p)}:{n}: {target}")
                elif anchor and where.suffix == ".md" and anchor not in anchors(where):
                    missing.append(f"{shown(p)}:{n}: {target} (no such heading)")
    assert not missing, "links to missing files or headings:\n" + "\n".join(missing)


def test_the_runner_names_a_failing_block(tmp_path: Path) -> None:
    """The driver stops at the first failing block and names its file and line, for Python
    (with the markdown's line in the traceback) and for shell blocks."""
    doc = (tmp_path / "doc.md").resolve()
    doc.write_text("# t\n\n```python\nx = 1\n```\n\n```text\nnot run\n```\n\n"
                   "```python\nassert x == 1\nraise RuntimeError('boom')\n```\n")
    done = drive(doc, tmp_path / "py")
    assert done.returncode == 1
    assert f"the python block at {doc}:12 failed" in done.stdout
    assert f'File "{doc}", line 13' in done.stderr
    doc.write_text("```sh\ntrue\n```\n\n```bash\nfalse\necho never\n```\n\n```python\nprint('never')\n```\n")
    done = drive(doc, tmp_path / "sh")
    assert done.returncode == 1
    assert f"the bash block at {doc}:6 failed (exit status 1)" in done.stdout
    assert "never\n" not in done.stdout
    doc.write_text("```python\nimport rubber_atlas\n```\n\n```bash\nrubber-atlas --version\ntest -f atlas/demo.toml\n```\n")
    done = drive(doc, tmp_path / "ok")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "rubber-atlas" in done.stdout


def test_the_parser(tmp_path: Path) -> None:
    doc = tmp_path / "doc.md"
    doc.write_text("````markdown\n```python\nnot a block\n```\n````\n\n  ```Python title\n  a = 1\n  ```\n"
                   "~~~sh\nls\n~~~\n")
    found = blocks(doc)
    assert [(b.info, b.line) for b in found] == [("markdown", 2), ("python", 8), ("sh", 11)]
    assert found[1].source == "a = 1\n"
    doc.write_text("```python\nnever closed\n")
    with pytest.raises(ValueError, match="never closed"):
        blocks(doc)
