"""The examples of the installed package's docstrings run (doctest), and every public
function and accessor method has a numpydoc docstring with its sections."""
from __future__ import annotations

import doctest
import inspect
import re

import pytest

import rubber_atlas as ra
import rubber_atlas._api
import rubber_atlas.accessor

MODULES = (ra, ra._api, ra.accessor)
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def examples() -> list[doctest.DocTest]:
    finder = doctest.DocTestFinder()
    found = [t for m in MODULES for t in finder.find(m) if t.examples]
    return sorted(found, key=lambda t: t.name)


EXAMPLES = examples()


def test_there_are_examples_in_every_module():
    names = {t.name for t in EXAMPLES}
    assert "rubber_atlas" in names  # the module's own docstring
    for module in ("rubber_atlas._api.", "rubber_atlas.accessor."):
        assert any(n.startswith(module) for n in names), module
    assert sum(len(t.examples) for t in EXAMPLES) > 50


@pytest.mark.parametrize("test", EXAMPLES, ids=[t.name for t in EXAMPLES])
def test_the_examples_run(test, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    pytest.importorskip("matplotlib").use("Agg")
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    lines = []
    runner.run(test, out=lines.append)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0
    assert result.failed == 0, "".join(lines)


PUBLIC = [getattr(ra, name) for name in ra.__all__ if callable(getattr(ra, name)) and name != "RubberAccessor"]
METHODS = [m for name, m in inspect.getmembers(ra.RubberAccessor, inspect.isfunction) if not name.startswith("_")]


@pytest.mark.parametrize("function", PUBLIC + METHODS, ids=lambda f: f.__qualname__)
def test_every_public_function_has_numpydoc_sections(function):
    doc = inspect.getdoc(function)
    assert doc, function
    assert not re.search(r"\bSPEC\b", doc)
    wanted = ["Returns", "Examples"]
    if inspect.signature(function).parameters.keys() - {"self"}:
        wanted.append("Parameters")
    for section in wanted:
        assert f"\n{section}\n{'-' * len(section)}\n" in doc, (function.__qualname__, section)


def test_no_module_cites_the_developers_spec():
    for module in MODULES:
        source = inspect.getsource(module)
        # (As a word: ASPECT is no citation.)
        assert not re.search(r"\bSPEC\b", source), module.__name__
