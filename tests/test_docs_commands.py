"""The fenced ``bash`` and ``python`` blocks of README.md and docs/tutorial.md run as pasted, after the
README's set-up line, on small settings.

Each document runs in its own empty folder, its blocks in the order printed. Consecutive Python blocks
are one interpreter session (the tutorial's sections 1-3 build on one ``circuit``), run in a subprocess
with the worktree on ``PYTHONPATH``; a shell block ends the session and runs in bash with ``set -euo
pipefail``, ``neurocur`` being this interpreter's ``neurocur.cli.command`` (the console script that
``pip install -e .`` writes calls the same function). Paper-size settings are replaced by small ones
through ``SMALL``, and the set-up commands listed in ``SKIPPED`` are not run. Both tables must match
the documents, so that a changed page changes the test with it.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ("README.md", "docs/tutorial.md")

# (document, text as printed, text run): paper-size settings replaced by small ones (2 runs of 2000
# frames in one process, so that each document runs in about 30 s on a shared machine).
SMALL = (
    ("README.md", "neurocur run synthetic --runs 8 --out",
     "neurocur run synthetic --runs 2 --steps 2000 --jobs 1 --out"),
    ("README.md", "sim.run(350_000)", "sim.run(2_000)"),
    ("docs/tutorial.md", "sim.run(50_000, progress=False)", "sim.run(2_000, progress=False)"),
    ("docs/tutorial.md", "neurocur run synthetic --runs 4 --steps 60000",
     "neurocur run synthetic --runs 2 --steps 2000 --jobs 1"),
)

# The `&&`-joined parts of the shell blocks that are not run, each with the reason.
_ENVIRONMENT = "makes the environment this test already runs in"
_TEST_COMMAND = ("a step of the README's test command, which .ci/run runs as printed (and pytest within "
                 "pytest would run this test again)")
SKIPPED = {
    "python3 -m venv .venv": _ENVIRONMENT,
    ". .venv/bin/activate": _ENVIRONMENT,
    "pip install -e .": _ENVIRONMENT,
    'pip install -e ".[test]"': _ENVIRONMENT,
    "ruff check": _TEST_COMMAND,
    "lint-imports": _TEST_COMMAND,
    "mkdocs build --strict -q": _TEST_COMMAND,
    "python -m pytest -q": _TEST_COMMAND,
}

_FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
_NEUROCUR = ("neurocur() { \"$NEUROCUR_PYTHON\" -c 'import sys; from neurocur.cli import command; "
             "sys.argv[0] = \"neurocur\"; sys.exit(command())' \"$@\"; }\n")
_SESSION = ("import json, sys\nnamespace = {'__name__': '__main__'}\n"
            "for name, code in json.load(sys.stdin):\n"
            "    print('---', name, flush=True)\n"
            "    exec(compile(code, name, 'exec'), namespace)\n")


def blocks(doc: str) -> list[tuple[str, str, str]]:
    """(language, 'doc:line', code) of every ``bash`` and ``python`` fence of ``doc``, in order."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    return [(m.group(1), f"{doc}:{text.count(chr(10), 0, m.start()) + 1}", m.group(2))
            for m in _FENCE.finditer(text) if m.group(1) in ("bash", "python")]


def small(doc: str, code: str, used: set) -> str:
    for i, (where, printed, run) in enumerate(SMALL):
        if where == doc and printed in code:
            code = code.replace(printed, run)
            used.add(i)
    return code


def shell_commands(code: str, skipped: set) -> str:
    """The block's lines with the ``SKIPPED`` parts of each ``&&`` chain left out."""
    lines = []
    for line in code.splitlines():
        parts = [part.strip() for part in line.split("&&")]
        skipped.update(part for part in parts if part in SKIPPED)
        kept = [part for part in parts if part not in SKIPPED]
        if kept:
            lines.append(" && ".join(kept))
    return "\n".join(lines)


def _environment() -> dict:
    env = dict(os.environ, MPLBACKEND="Agg", NEUROCUR_PYTHON=sys.executable)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    return env


def _check(result: subprocess.CompletedProcess, what: str) -> None:
    if result.returncode:
        pytest.fail(f"{what} failed (exit {result.returncode}):\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")


def run_document(doc: str, folder: Path, used: set, skipped: set) -> None:
    env = _environment()
    session: list[tuple[str, str]] = []

    def run_session():
        if session:
            result = subprocess.run([sys.executable, "-c", _SESSION], input=json.dumps(session), cwd=folder,
                                    env=env, capture_output=True, text=True, timeout=300)
            _check(result, "python blocks " + ", ".join(name for name, _ in session))
            session.clear()

    for language, name, code in blocks(doc):
        code = small(doc, code, used)
        if language == "python":
            session.append((name, code))
            continue
        run_session()
        commands = shell_commands(code, skipped)
        if commands:
            result = subprocess.run(["bash", "-euo", "pipefail", "-c", _NEUROCUR + commands], cwd=folder,
                                    env=env, capture_output=True, text=True, timeout=300)
            _check(result, f"bash block {name}")
    run_session()


@pytest.mark.parametrize("doc", DOCS)
def test_blocks_run_as_printed(doc, tmp_path):
    run_document(doc, tmp_path, set(), set())
    assert any(language == "bash" for language, _, _ in blocks(doc))
    assert any(language == "python" for language, _, _ in blocks(doc))


def test_tables_match_the_documents():
    """Every substitution and every skipped part appears in the documents: a stale entry would
    otherwise let a paper-size command, or a command nobody runs, in unnoticed."""
    used, skipped = set(), set()
    for doc in DOCS:
        for language, _, code in blocks(doc):
            code = small(doc, code, used)
            if language == "bash":
                shell_commands(code, skipped)
    assert used == set(range(len(SMALL)))
    assert skipped == set(SKIPPED)


def test_set_up_activates_and_ci_runs_the_readme_test_command():
    """The README's set-up commands activate the environment that the later commands assume, and
    .ci/run ends with exactly the README's test command."""
    shell = [code.strip() for language, _, code in blocks("README.md") if language == "bash"]
    assert all(code.startswith("python3 -m venv .venv && . .venv/bin/activate && pip install -e ") for code in shell)
    test_command = next(code for code in shell if "pytest" in code)
    assert (ROOT / ".ci/run").read_text(encoding="utf-8").strip().splitlines()[-1] == test_command
