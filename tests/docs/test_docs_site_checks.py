"""docs/_ext/hooks.py: the checks ``mkdocs build`` runs on every built page.

The pages are hand-made from what the site showed before the checks existed (a role left literal,
a numpy "Parameters" section read as a Markdown heading over a run-on paragraph, a ``name :
description`` line read as a type) and from what mkdocstrings emits for a parsed section; and a
two-page site built as the test command builds it, ``mkdocs build --strict -q``.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
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


def test_backticks_in_a_title_fail_the_page():
    page = "<html><head><title>PPO (needs ``neurocur[rl]``). - neurocur</title></head><body></body></html>"
    with pytest.raises(PluginError, match=r"rl_ppo/index\.md: backticks in the title"):
        hooks.check_page(page, "generated/gallery/rl_ppo/index.md")
    hooks.check_page(page.replace("``neurocur[rl]``", "neurocur[rl]"), "generated/gallery/rl_ppo/index.md")


def test_on_post_page_returns_the_page_or_raises():
    class Page:
        class file:
            src_uri = "api/fit.md"

    assert hooks.on_post_page(LINKED, page=Page, config={}) == LINKED
    with pytest.raises(PluginError):
        hooks.on_post_page(LITERAL, page=Page, config={})


def _build(tmp_path, index: str) -> subprocess.CompletedProcess:
    """``mkdocs build --strict -q`` (the test command's form) of a two-page site with the hooks."""
    (tmp_path / "docs").mkdir(exist_ok=True)
    (tmp_path / "docs" / "index.md").write_text(index, encoding="utf-8")
    (tmp_path / "docs" / "other.md").write_text("# Other\n\n## A heading\n", encoding="utf-8")
    (tmp_path / "mkdocs.yml").write_text(
        f"site_name: t\nvalidation:\n  anchors: warn\nhooks:\n  - {EXT}\n", encoding="utf-8")
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize(("index", "error"), [
    ("# Home\n\n[there](other.md#a-heading)\n", None),
    ("# Home\n\n[there](other.md#no-such-heading)\n", "does not contain an anchor '#no-such-heading'"),
    ("# Home\n\n[there](missing.md)\n", "'missing.md', but the target is not found"),
    ("# Home\n\nSee :func:`fit_ml`.\n", "index.md: literal role"),
])
def test_a_quiet_strict_build_fails_on_warnings_and_checks(tmp_path, index, error):
    # without the hooks' on_config, -q hid the two warnings and the build passed
    build = _build(tmp_path, index)
    if error is None:
        assert build.returncode == 0, build.stderr
    else:
        assert build.returncode == 1 and error in build.stderr, build.stderr
