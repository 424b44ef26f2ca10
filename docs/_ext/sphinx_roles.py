"""Sphinx cross-reference roles in the docstrings, rendered as mkdocs-autorefs links: a griffe extension.

neurocur's docstrings cross-reference in Sphinx's notation (``:func:`fit_ml```,
``:class:`~neurocur.config.ConfigError```, ``:mod:`.user_sources```), which Markdown would show as
literal text. mkdocs.yml loads this file as a griffe extension of mkdocstrings' Python handler; once
the package has loaded (``on_package``: every module is known), each docstring's roles are rewritten:

- a target found in the package becomes an *optional* autorefs reference to the object's canonical
  path, ``<autoref identifier="neurocur.fit.mle.fit_ml" optional>`fit_ml`</autoref>``: a link when
  an API page renders that object, code text otherwise (autorefs renders an unresolved optional
  reference as its title, without a warning, so a private or undocumented target never fails
  ``mkdocs build --strict``);
- any other target (numpy, the standard library, a ``:ref:`` label, a name the package lacks)
  becomes code text.

A target is looked up as Sphinx's Python domain does: in the docstring's own class or module, then in
each enclosing package, then as a full path (through imports and inherited members, with griffe's
member lookup). A name still not found resolves when exactly one object's path ends with it: the
one under the longest prefix that exists (``neurocur.experiments.load_experiment``, exported
lazily; a module since moved into a subpackage), else anywhere in the package (a leading dot,
Sphinx's "search" form, a class member named from elsewhere). The text shown is the target as
written without a leading dot, its last component after ``~``, or the title of ``title <target>``.
Roles inside fenced code blocks are left alone. The site's build hook (``hooks.py``) fails on any
role left literal in the built pages.
"""

from __future__ import annotations

import logging
import re
from collections import defaultdict

import griffe

_log = logging.getLogger(f"mkdocs.plugins.{__name__}")

ROLE = re.compile(
    r"(?<![\w`]):(?:py:)?(?P<role>func|class|meth|mod|data|attr|obj|exc|const|ref):`(?P<body>[^`]+)`"
)
_TITLED = re.compile(r"^(?P<title>.+?)\s*<(?P<target>[^<>]+)>$", re.DOTALL)
_FENCED = re.compile(r"^([ \t]*)(```|~~~).*?^\1\2[ \t]*$", re.DOTALL | re.MULTILINE)


class PackageIndex:
    """Where the targets of one loaded package's roles are: griffe's member lookup, and paths by suffix."""

    def __init__(self, package: griffe.Module) -> None:
        self.package = package
        self.by_suffix: dict[str, set[str]] = defaultdict(set)
        for obj in _objects(package):
            parts = obj.path.split(".")
            for i in range(len(parts)):
                self.by_suffix[".".join(parts[i:])].add(obj.path)

    def lookup(self, path: str) -> str | None:
        """The canonical path of the package's object ``path`` (through imports and inheritance), or None."""
        root, _, rest = path.partition(".")
        if root != self.package.name:
            return None
        if not rest:
            return self.package.path
        try:
            return self.package[rest].canonical_path
        except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
            return None

    def _unique(self, suffix: str, under: str = "") -> str | None:
        found = {p for p in self.by_suffix.get(suffix, ()) if p.startswith(under)}
        return next(iter(found)) if len(found) == 1 else None

    def resolve(self, target: str, where: griffe.Object) -> str | None:
        """The canonical path ``target`` names in the docstring of ``where``, or None."""
        name = target.lstrip(".")
        scope: griffe.Object | None = where if (where.is_module or where.is_class) else where.parent
        while scope is not None:
            if (path := self.lookup(f"{scope.path}.{name}")) is not None:
                return path
            scope = scope.parent
        if (path := self.lookup(name)) is not None:
            return path
        parts = name.split(".")
        for i in range(len(parts) - 1, 0, -1):  # a name re-exported lazily, or a module since moved
            if (head := self.lookup(".".join(parts[:i]))) is not None:
                return self._unique(".".join(parts[i:]), head + ".")
        return self._unique(name)


def rewrite_roles(text: str, resolve) -> tuple[str, int, int]:
    """``text`` with every role outside fenced code replaced; also the counts linked and left as code.

    ``resolve(target)`` gives the canonical path of a target, or None.
    """
    linked = plain = 0

    def replace(match: re.Match) -> str:
        nonlocal linked, plain
        body = " ".join(match["body"].split())
        if titled := _TITLED.match(body):
            title, target = " ".join(titled["title"].split()), titled["target"].strip()
        else:
            target = body.lstrip("~")
            title = target.lstrip(".")  # as Sphinx shows it: no leading dot; after "~" the last component
            title = title.rsplit(".", 1)[-1] if body.startswith("~") else title
        path = None if match["role"] == "ref" else resolve(target.lstrip("~"))
        if path is None:
            plain += 1
            return f"`{title}`"
        linked += 1
        return f'<autoref identifier="{path}" optional>`{title}`</autoref>'

    pieces, start = [], 0
    for fence in _FENCED.finditer(text):
        pieces += [ROLE.sub(replace, text[start:fence.start()]), fence[0]]
        start = fence.end()
    pieces.append(ROLE.sub(replace, text[start:]))
    return "".join(pieces), linked, plain


class SphinxRoles(griffe.Extension):
    """Rewrites the Sphinx roles of every docstring of a package once the package has loaded."""

    def on_package(self, *, pkg: griffe.Module, **kwargs) -> None:
        index = PackageIndex(pkg)
        linked = plain = 0
        for obj in _objects(pkg):
            docstring = obj.docstring
            if docstring is None or not ROLE.search(docstring.value):
                continue
            docstring.value, n_linked, n_plain = rewrite_roles(docstring.value, lambda t, o=obj: index.resolve(t, o))
            docstring.__dict__.pop("parsed", None)  # parsed lazily: drop a parse of the old text
            linked, plain = linked + n_linked, plain + n_plain
        _log.debug("%s: %d Sphinx roles to references, %d to code text", pkg.path, linked, plain)


def _objects(obj: griffe.Object):
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _objects(member)
