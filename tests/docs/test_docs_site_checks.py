"""docs/_ext/hooks.py: the checks ``mkdocs build`` runs on every built page.

The pages are hand-made from what the site showed before the checks existed (a role left literal,
a numpy "Parameters" section read as a Markdown heading over a run-on paragraph, a ``name :
description`` line read as a type) and from what mkdocstrings emits for a parsed section.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
from mkdocs.exceptions import PluginError

EXT = Path(__file__).resolve().parents[2] / "docs" / "_ext" / "hooks.py"
_spec = importlib.util.spec_from_file_location("docs_hooks", EXT)
hooks = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(hooks)

LITERAL = "<p>Fitted by :func:<code>fit_ml</code> with :class:<code>~neurocur.config.ConfigError</code>.</p>"
QUOTED = ("<p>Write <code>:func:`fit_ml`</code> in a docstring.</p>\n"
          '<pre><code class="language-python">""":class:`Region`"""</code></pre>')
LINKED = ('<p>Fitted by <a class="autorefs autorefs-internal" href="../fit/#neurocur.fit.mle.fit_ml">'
          '<code>fit_ml</code></a>, else <span title="neurocur.fit.mle._bounds"><code>_bounds</code></span>.</p>')
UNPARSED = ('<h4 id="neurocur.learn.MCA--parameters">Parameters<a class="headerlink" '
            'href="#neurocur.learn.MCA--parameters" title="Permanent link">&para;</a></h4>\n'
            "<p>n_components : J, the number of minor components.\nlearning_rate : η in (0, 0.5].</p>")
UNPARSED_TEXT = "<p>Attributes ---------- centers_ : float64</p>"


def table(title: str, description: str) -> str:
    return (f'<p><span class="doc-section-title">{title}:</span></p>\n    <table>\n      <thead><tr><th>Name</th>'
            "<th>Type</th><th>Description</th></tr></thead>\n      <tbody>\n"
            '          <tr class="doc-section-item">\n            <td>\n                <code>n_states</code>\n'
            "            </td>\n            <td>\n                  <code>int</code>\n            </td>\n"
            f'            <td>\n              <div class="doc-md-description">\n                {description}\n'
            "              </div>\n            </td>\n          </tr>\n      </tbody>\n    </table>")


def test_a_literal_role_fails_the_page():
    with pytest.raises(PluginError, match=r"guide\.md: literal role: .*:func:.*literal role: .*:class:"):
        hooks.check_page(LITERAL, "guide.md")
    assert len(hooks.literal_roles(LITERAL)) == 2


@pytest.mark.parametrize("html", [QUOTED, LINKED, table("Parameters", "<p>number of context-states.</p>")])
def test_roles_in_code_links_and_tables_pass(html):
    hooks.check_page(html, "api/fit.md")


@pytest.mark.parametrize(("html", "found"), [
    (UNPARSED, "unparsed section 'Parameters'"),
    (UNPARSED_TEXT, "unparsed section 'Attributes'"),
    (table("Parameters", ""), "Parameters row 'n_states' has no description"),
])
def test_an_unrendered_section_fails_an_api_page(html, found):
    assert hooks.unrendered_sections(html) == [found]
    with pytest.raises(PluginError, match=f"api/learn.md: {found}"):
        hooks.check_page(html, "api/learn.md")
    hooks.check_page(html, "guide.md")  # a guide's own "Parameters" heading is its business


def test_on_post_page_returns_the_page_or_raises():
    class Page:
        class file:
            src_uri = "api/fit.md"

    assert hooks.on_post_page(LINKED, page=Page, config={}) == LINKED
    with pytest.raises(PluginError):
        hooks.on_post_page(LITERAL, page=Page, config={})
