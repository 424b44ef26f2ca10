"""docs/_ext/sphinx_roles.py: the docstrings' Sphinx roles become autorefs references or code text.

A small package made on the fly (griffe's temporary package) stands for neurocur: each role form the
docstrings use (short names, ``~``, a leading dot, ``title <target>``, inherited members, names
re-exported lazily) must resolve to the canonical path a hand-read of the package gives, and an
unknown or ambiguous one must fall back to code text, never to a reference that could fail --strict.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import griffe
import pytest

EXT = Path(__file__).resolve().parents[2] / "docs" / "_ext" / "sphinx_roles.py"
_spec = importlib.util.spec_from_file_location("sphinx_roles", EXT)
sphinx_roles = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sphinx_roles)

PACKAGE = {
    "__init__.py": '"""The package."""\nfrom .core import Base\n__all__ = ["Base", "lazy_one"]\n',
    "core.py": (
        '"""Core: :class:`Base`, :func:`helper`, :mod:`.tools`."""\n'
        "class Base:\n"
        '    """A base; :meth:`run` runs, :attr:`rate` rates."""\n'
        "    rate = 1\n"
        "    def run(self):\n"
        '        """Run; see :func:`helper` and :meth:`Child.run`."""\n'
        "class Child(Base):\n"
        '    """A child."""\n'
        "def helper():\n"
        '    """Help."""\n'
    ),
    "tools.py": '"""Tools: :func:`~pkg.core.helper`, :class:`.Base`, :func:`numpy.mean`."""\ndef lazy_one():\n    pass\n'
                "def run():\n    pass\n",
}


@pytest.fixture(scope="module")
def package():
    with griffe.temporary_visited_package("pkg", PACKAGE) as pkg:
        yield pkg


@pytest.mark.parametrize(("target", "where", "expected"), [
    ("Base", "core", "pkg.core.Base"),  # the docstring's own module
    ("run", "core.Base", "pkg.core.Base.run"),  # its own class
    ("helper", "core.Base.run", "pkg.core.helper"),  # the enclosing module of a method
    ("Child.run", "core.Base.run", "pkg.core.Base.run"),  # inherited: the member where it is defined
    ("tools", "core", "pkg.tools"),  # an enclosing package
    ("pkg.Base", "tools", "pkg.core.Base"),  # a full path through an import
    ("pkg.lazy_one", "core", "pkg.tools.lazy_one"),  # not imported (a lazy export): the one under pkg
    ("Base.rate", "tools", "pkg.core.Base.rate"),  # the one object whose path ends so
])
def test_targets_resolve_to_canonical_paths(package, target, expected, where):
    assert sphinx_roles.PackageIndex(package).resolve(target, package[where]) == expected


@pytest.mark.parametrize("target", ["numpy.mean", "missing", "run", "pkg.core.nothing"])
def test_unknown_and_ambiguous_targets_do_not_resolve(package, target):
    # from pkg.core, "run" is ambiguous: pkg.core.Base.run and pkg.tools.run both end so
    assert sphinx_roles.PackageIndex(package).resolve(target, package["core"]) is None


def test_rewrite_forms():
    paths = {"a.b.c": "a.b.c", "x": "a.x", ".rel": "a.rel"}
    text = (":func:`~a.b.c` and :class:`x`, :py:meth:`the title <x>` and :mod:`.rel`; "
            ":data:`numpy.pi`, :ref:`x`, :attr:`long\n    name`")
    out, linked, plain = sphinx_roles.rewrite_roles(text, paths.get)
    assert out == (
        '<autoref identifier="a.b.c" optional>`c`</autoref> and <autoref identifier="a.x" optional>`x`</autoref>, '
        '<autoref identifier="a.x" optional>`the title`</autoref> and '
        '<autoref identifier="a.rel" optional>`rel`</autoref>; `numpy.pi`, `x`, `long name`'
    )
    assert (linked, plain) == (4, 3)


def test_fenced_code_is_left_alone():
    text = "See :func:`f`.\n\n```python\n# :func:`f` in code\n```\nThen :func:`g`."
    out, linked, plain = sphinx_roles.rewrite_roles(text, lambda t: None)
    assert out == "See `f`.\n\n```python\n# :func:`f` in code\n```\nThen `g`."
    assert (linked, plain) == (0, 2)


def test_extension_rewrites_every_docstring_on_load():
    extensions = griffe.load_extensions(sphinx_roles.SphinxRoles)
    with griffe.temporary_visited_package("pkg", PACKAGE, extensions=extensions) as pkg:
        assert pkg["core"].docstring.value == (
            'Core: <autoref identifier="pkg.core.Base" optional>`Base`</autoref>, '
            '<autoref identifier="pkg.core.helper" optional>`helper`</autoref>, '
            '<autoref identifier="pkg.tools" optional>`tools`</autoref>.'
        )
        assert pkg["tools"].docstring.value == (
            'Tools: <autoref identifier="pkg.core.helper" optional>`helper`</autoref>, '
            '<autoref identifier="pkg.core.Base" optional>`Base`</autoref>, `numpy.mean`.'
        )
        for obj in sphinx_roles._objects(pkg):
            assert obj.docstring is None or not sphinx_roles.ROLE.search(obj.docstring.value)
