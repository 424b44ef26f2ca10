"""The docstring style mkdocs.yml gives mkdocstrings parses every neurocur docstring as meant.

griffe reads the package statically (about a second) with the parser mkdocs.yml names: no docstring
may raise a parser warning (which ``mkdocs build --strict`` would turn into a failure only for the
objects it renders), and each function or class with a Parameters section (the listed ones must have
one) must document exactly the parameters of its signature or constructor, each with a description (``name : text`` would make the text a type and leave
the description empty).
"""

from __future__ import annotations

import logging
from pathlib import Path

import griffe
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
#: Objects whose API entries must show a parameter table (more have one; each that has one is checked below).
SECTIONED = {"neurocur.learn.ccipca.CCIPCA", "neurocur.learn.mca.MCA", "neurocur.learn.incsfa.IncSFA",
             "neurocur.learn.roc.ROCBank", "neurocur.contexts.synthetic.SyntheticWorld",
             "neurocur.fit.mle.fit_ml", "neurocur.fit.hierarchical.fit_hierarchical", "neurocur.fit.bms.bms",
             "neurocur.fit.trials.read_trials", "neurocur.fit.trials.trials_from_table",
             "neurocur.fit.ten2021.read_ten2021_groups", "neurocur.fit.ten2021.free_play",
             "neurocur.analysis.figures.sets.write_figures", "neurocur.fit.hierarchical.HierarchicalFit",
             "neurocur.fit.hierarchical.Subject", "neurocur.fit.squarem.iterate", "neurocur.fit.workers.SubjectWorkers",
             "neurocur.fit.workers.SubjectWorkers.map"}


def _style() -> str:
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    mkdocstrings = next(p["mkdocstrings"] for p in config["plugins"] if isinstance(p, dict) and "mkdocstrings" in p)
    return mkdocstrings["handlers"]["python"]["options"]["docstring_style"]


def _objects(obj):
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _objects(member)


class _Records(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record):
        self.messages.append(record.getMessage())


@pytest.fixture(scope="module")
def parsed():
    """Every docstring of neurocur parsed, by path, and the warnings the parser logged."""
    records, root = _Records(), logging.getLogger()
    root.addHandler(records)
    try:
        package = griffe.load("neurocur", search_paths=[str(ROOT)], docstring_parser=_style())
        docstrings = {obj.path: (obj, obj.docstring.parsed) for obj in _objects(package) if obj.docstring}
    finally:
        root.removeHandler(records)
    return docstrings, records.messages


def test_the_style_is_numpy_and_no_docstring_warns(parsed):
    assert _style() == "numpy"
    assert parsed[1] == []


def test_parameter_sections_document_the_constructor(parsed):
    docstrings, _ = parsed
    sectioned = {path for path, (_, sections) in docstrings.items()
                 if any(s.kind is griffe.DocstringSectionKind.parameters for s in sections)}
    assert SECTIONED <= sectioned, sorted(SECTIONED - sectioned)
    for path in sorted(sectioned):
        obj, sections = docstrings[path]
        (params,) = [s.value for s in sections if s.kind is griffe.DocstringSectionKind.parameters]
        assert [p.name for p in params if p.description.strip()] == [p.name for p in params], path
        assert {p.name.lstrip("*") for p in params} == {p.name for p in obj.parameters} - {"self"}, path


def _documented_modules() -> set[str]:
    """The modules the API pages render (``::: module`` in docs/api/*.md), with their submodules."""
    return {line.split()[1] for page in (ROOT / "docs" / "api").glob("*.md")
            for line in page.read_text(encoding="utf-8").splitlines() if line.startswith("::: ")}


def _exported(module):
    """Each function or class named in ``module.__all__`` and defined in the package, with its module."""
    for name in module.exports or ():
        assert str(name) in module.members, (f"{module.path}.__all__ names {name!r}, which the docs' reader does not "
                                             "find in the module (bound by tuple unpacking? assign it on its own line)")
        obj = module.get_member(str(name))
        if obj.is_alias:
            try:
                obj = obj.final_target
            except griffe.AliasResolutionError:
                continue
        if obj.is_function or obj.is_class:
            yield obj


def _modules(obj):
    yield obj
    for member in obj.members.values():
        if not member.is_alias and member.is_module:
            yield from _modules(member)


def test_public_callables_with_arguments_have_a_parameter_table():
    """Every module an API page renders shows a parameter table for each public function and class that takes
    arguments (each name in a module's ``__all__``, defined in the package)."""
    package = griffe.load("neurocur", search_paths=[str(ROOT)], docstring_parser=_style())
    documented = tuple(sorted(_documented_modules()))
    assert len(documented) >= 15, documented
    missing, checked = set(), 0
    for module in _modules(package):
        if not module.path.startswith(tuple(f"{d}." for d in documented) + documented):
            continue
        for obj in _exported(module):
            if not [p for p in obj.parameters if p.name not in ("self", "cls")]:
                continue
            checked += 1
            sections = obj.docstring.parsed if obj.docstring else []
            if not any(s.kind is griffe.DocstringSectionKind.parameters for s in sections):
                missing.add(obj.path)
    assert checked > 400 and not missing, (checked, sorted(missing))


def test_returned_and_yielded_values_are_described(parsed):
    """A Returns or Yields row without a description fails the site's build (docs/_ext/hooks.py) on a rendered page."""
    docstrings, _ = parsed
    kinds = (griffe.DocstringSectionKind.returns, griffe.DocstringSectionKind.yields)
    bare = sorted(path for path, (_, sections) in docstrings.items() for s in sections if s.kind in kinds
                  for item in s.value if not item.description.strip())
    assert not bare, bare
