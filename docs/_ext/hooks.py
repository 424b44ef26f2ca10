"""Checks of every built page, run by ``mkdocs build`` as a hook (mkdocs.yml ``hooks:``).

First, ``--strict`` with ``--quiet`` (the test command's ``mkdocs build --strict -q``) is made to
fail on warnings: MkDocs 1.6's ``-q`` raises the ``mkdocs`` logger to ERROR, so warnings never
reach the counter strict mode aborts on (mkdocs/mkdocs#4126) and a broken link or anchor passed.
Under strict, ``on_config`` lowers the logger back to WARNING: a passing build has no warning to
print, a failing one prints what failed.

A page fails the build (a ``PluginError`` naming the page and what was found) when, outside code,

- it shows a Sphinx role as literal text (``:func:`` before a code span): the docstrings' roles are
  translated at load time by ``sphinx_roles.py``, so a literal one is a role that translation does
  not see (a Markdown page, a gallery example's text) or a form it does not know;
- its title (the browser's and the navigation's label) shows a backtick: Markdown is not rendered
  there, so a gallery example's title must be plain text;
- (API pages) it shows a numpy section heading ("Parameters" over its dashed underline) as a
  Markdown heading or as text, a section mkdocstrings did not parse, or a Parameters/Attributes table row with an empty description (the
  text of ``name : description`` read as the type: numpy style wants the description on the next,
  indented line).
"""

from __future__ import annotations

import logging
import re

from mkdocs.exceptions import PluginError

LITERAL_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|data|attr|obj|exc|const|ref):")
_SECTIONS = r"(?:Parameters|Other Parameters|Attributes|Returns|Yields|Receives|Raises|Warns|See Also)"
# Markdown reads an unparsed "Parameters" over its dashes as a heading; dashes too short for that stay text
UNPARSED_SECTION = re.compile(rf"<h[1-6][^>]*>\s*{_SECTIONS}\s*<a class=\"headerlink\"|\b{_SECTIONS}\s+-{{3,}}")
_TITLE = re.compile(r"<title>(?P<title>.*?)</title>", re.DOTALL)
_CODE = re.compile(r"<(pre|code)\b[^>]*>.*?</\1>", re.DOTALL)
_SECTION_TABLE = re.compile(
    r'<span class="doc-section-title">(?P<title>[^<]+):</span></p>\s*<table>(?P<table>.*?)</table>', re.DOTALL
)
_ROW = re.compile(r'<tr class="doc-section-item">(?P<row>.*?)</tr>', re.DOTALL)
_EMPTY_DESCRIPTION = re.compile(r'<div class="doc-md-description">\s*</div>')
_NAME = re.compile(r"<td>\s*<code>(?P<name>.*?)</code>", re.DOTALL)


def _shown(html: str) -> str:
    """``html`` without its code blocks and code spans (where a role may be quoted on purpose)."""
    return _CODE.sub(" ", html)


def literal_roles(html: str) -> list[str]:
    """The roles a page shows as literal text, each with the words around it."""
    text = _shown(html)
    return [" ".join(text[max(m.start() - 60, 0):m.end() + 20].split()) for m in LITERAL_ROLE.finditer(text)]


def unrendered_sections(html: str) -> list[str]:
    """Docstring sections an API page shows unparsed, and table rows without a description."""
    found = [f"unparsed section {re.search(_SECTIONS, m[0])[0]!r}" for m in UNPARSED_SECTION.finditer(_shown(html))]
    for section in _SECTION_TABLE.finditer(html):
        for row in _ROW.finditer(section["table"]):
            if _EMPTY_DESCRIPTION.search(row["row"]):
                name = _NAME.search(row["row"])
                found.append(f"{section['title']} row {name['name'] if name else '?'!r} has no description")
    return found


def check_page(html: str, src_uri: str) -> None:
    """Raise ``PluginError`` naming ``src_uri`` when its built ``html`` fails a check."""
    problems = [f"literal role: ...{snippet}..." for snippet in literal_roles(html)]
    if (title := _TITLE.search(html)) and "`" in title["title"]:
        problems.append(f"backticks in the title {title['title'].strip()!r}")
    if src_uri.startswith("api/"):
        problems += unrendered_sections(html)
    if problems:
        more = f" (and {len(problems) - 3} more)" if len(problems) > 3 else ""
        raise PluginError(f"{src_uri}: {'; '.join(problems[:3])}{more}")


def on_config(config, **kwargs):
    mkdocs_log = logging.getLogger("mkdocs")
    if config.strict and mkdocs_log.getEffectiveLevel() > logging.WARNING:
        mkdocs_log.setLevel(logging.WARNING)
    return config


def on_post_page(output: str, page, config, **kwargs) -> str:
    check_page(output, page.file.src_uri)
    return output
