"""Fingerprints of what determines a run besides its resolved configuration: the content
of its input files and the code.

* An input file (a world parameter declared as a path, e.g. a user source ``.npy``) is
  recorded by its sha256 (:func:`file_hashes`); a folder is not an input file.
* The code is recorded as the package version, a sha256 of the source of every module
  that can compute a run (the package's ``.py`` files except :mod:`neurocur.analysis`,
  which only reads results folders, and :mod:`neurocur.rl`, which no run imports) and, when the
  package runs from a git clone, the commit and whether the package has uncommitted changes
  (:func:`code_fingerprint`), and every plug-in loaded from the region or world entry-point groups:
  its distribution's name and version and a sha256 of its Python files and of the entry point's
  module (:func:`plugin_fingerprints`). Two fingerprints describe the same code when version,
  source hash and plug-ins agree.
* Paths inside the package (a shipped experiment or circuit) are recorded relative to it,
  ``<neurocur>/circuits/cd_misfa.toml`` (:func:`portable`), so a moved clone or a
  re-created virtualenv resumes its own folders; their content is in the resolved
  configuration (the circuit) or in the code fingerprint.

:meth:`neurocur.results.ResultsStore.check` records both in ``config.toml`` and compares
them on resume (:func:`changed_input`, :func:`code_changed`).
"""

from __future__ import annotations

import functools
import hashlib
import subprocess
import sys
from collections.abc import Iterable, Mapping
from importlib.metadata import entry_points
from pathlib import Path

__all__ = ["changed_input", "code_changed", "code_fingerprint", "file_hashes", "local_path", "plugin_fingerprints",
           "portable", "same_code"]

PACKAGE = Path(__file__).resolve().parents[1]
#: subpackages left out of the code fingerprint: they never compute a run (the analysis reads
#: results folders; :mod:`neurocur.rl` wraps gymnasium environments for other agents)
NOT_RUN_CODE = ("analysis", "rl")


def file_hashes(paths: Iterable[str]) -> dict[str, str]:
    """The sha256 (hex) of each path that is a file, by path; other paths are left out.

    Parameters
    ----------
    paths : iterable of str
        The input file paths (each hashed once; a folder or a missing path is left out).

    Returns
    -------
    dict of str to str
        The hex sha256 of each file's content, by path as given.
    """
    return {str(p): _sha256(Path(p)) for p in dict.fromkeys(paths) if Path(p).is_file()}


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def changed_input(old: Mapping[str, str], new: Mapping[str, str]) -> str | None:
    """A description of the first file recorded in both ``old`` and ``new`` whose hash differs.

    Parameters
    ----------
    old : mapping of str to str
        The hashes the folder recorded (:func:`file_hashes`), by path.
    new : mapping of str to str
        The hashes of the experiment to resume, by path.

    Returns
    -------
    str or None
        The path with both hashes' first 12 digits; None when no file recorded in both changed.
    """
    for path, digest in new.items():
        if path in old and old[path] != digest:
            return f"input file {path} changed since this folder's runs were computed (sha256 {old[path][:12]} then, " \
                   f"{digest[:12]} now)"
    return None


def code_fingerprint() -> dict:
    """``{"version", "source", "commit", "dirty", "plugins"}`` of the running code: the package's
    (computed once per process) and the plug-ins loaded so far (:func:`plugin_fingerprints`).

    ``commit`` is ``""`` and ``dirty`` false when the package does not run from a git clone
    (or git is not installed).
    """
    return {**_package_fingerprint(), "plugins": plugin_fingerprints()}


#: the entry-point groups whose types compute runs (region and world plug-ins)
PLUGIN_GROUPS = ("neurocur.regions", "neurocur.worlds")


def plugin_fingerprints() -> list[dict]:
    """``[{"entry_point", "name", "version", "source"}]`` of every region or world entry point whose
    module is loaded in this process, sorted; ``source`` is a sha256 of the distribution's ``.py``
    files and of the entry point module's file (for an editable install, whose files the
    distribution does not list)."""
    found = []
    for group in PLUGIN_GROUPS:
        for ep in entry_points(group=group):
            module = sys.modules.get(ep.module)
            if module is None:
                continue
            h = hashlib.sha256()
            files = [Path(str(ep.dist.locate_file(f))) for f in (ep.dist.files or []) if f.suffix == ".py"] \
                if ep.dist is not None else []
            own = getattr(module, "__file__", None)
            for path in sorted({*files, *([Path(own)] if own else [])}):
                if path.is_file():
                    h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
            found.append({"entry_point": f"{group}:{ep.name}", "name": ep.dist.name if ep.dist else ep.module,
                          "version": ep.dist.version if ep.dist else "", "source": h.hexdigest()[:16]})
    return sorted(found, key=lambda fp: fp["entry_point"])


def portable(tree):
    """``tree`` with every string (and key) naming a path inside the package written relative to it,
    ``<neurocur>/...``.

    Parameters
    ----------
    tree : object
        A plain-data tree (mappings and lists are walked; other values are kept).

    Returns
    -------
    object
        The tree rewritten (a new tree; ``tree`` is left as it is).
    """
    prefix = str(PACKAGE) + "/"
    if isinstance(tree, Mapping):
        return {portable(k): portable(v) for k, v in tree.items()}
    if isinstance(tree, list):
        return [portable(v) for v in tree]
    if isinstance(tree, str) and tree.startswith(prefix):
        return "<neurocur>/" + tree[len(prefix):]
    return tree


def local_path(text: str) -> Path:
    """The path that a :func:`portable` string names in the running package (other paths as they are).

    Parameters
    ----------
    text : str
        A path as ``config.toml`` records it.

    Returns
    -------
    path
        The path in this installation.
    """
    return PACKAGE / text.removeprefix("<neurocur>/") if text.startswith("<neurocur>/") else Path(text)


@functools.cache
def _package_fingerprint() -> dict:
    from neurocur import __version__

    h = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE)
        if relative.parts[0] not in NOT_RUN_CODE:
            h.update(relative.as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    commit, dirty = "", False
    if _git("ls-files", "--", "__init__.py"):  # the package is tracked by the clone it sits in
        commit = _git("rev-parse", "HEAD") or ""
        excluded = [f":(exclude){name}" for name in NOT_RUN_CODE]
        dirty = bool(commit and _git("status", "--porcelain", "--", ".", *excluded))
    return {"version": __version__, "source": h.hexdigest()[:16], "commit": commit, "dirty": dirty}


def same_code(a: Mapping, b: Mapping) -> bool:
    """Whether two code fingerprints describe the same code (version, source hash and plug-ins).

    Parameters
    ----------
    a, b : mapping
        Two code fingerprints (:func:`code_fingerprint`); the commit and ``dirty`` are not compared.

    Returns
    -------
    bool
        True when version, source hash and plug-ins agree.
    """
    return (a.get("version"), a.get("source"), a.get("plugins", [])) == \
        (b.get("version"), b.get("source"), b.get("plugins", []))


def code_changed(recorded: list, current: Mapping) -> str | None:
    """A description of the change when ``current`` matches none of the ``recorded`` fingerprints.

    Parameters
    ----------
    recorded : list
        The fingerprints a folder's ``config.toml`` records (``code``); entries that are not tables match nothing.
    current : mapping
        The running code's fingerprint.

    Returns
    -------
    str or None
        The last recorded and the current code ([`describe_code`][neurocur.results.fingerprint.describe_code]);
        None when ``current`` is the same code as one recorded ([`same_code`][neurocur.results.fingerprint.same_code]).
    """
    if any(same_code(old, current) for old in recorded if isinstance(old, Mapping)):
        return None
    then = describe_code(recorded[-1]) if recorded else "a neurocur that recorded no code fingerprint"
    return f"the code changed since this folder's runs were computed ({then} then, {describe_code(current)} now)"


def describe_code(fp: Mapping) -> str:
    """``"neurocur 0.1.0, commit 28b7d983e348 with uncommitted changes, source 1a2b3c4d"``."""
    text = f"neurocur {fp.get('version', '?')}"
    if fp.get("commit"):
        text += f", commit {fp['commit'][:12]}" + (" with uncommitted changes" if fp.get("dirty") else "")
    text += f", source {str(fp.get('source', '?'))[:8]}"
    for plugin in fp.get("plugins", []):
        if isinstance(plugin, Mapping):
            text += (f", plug-in {plugin.get('name', '?')} {plugin.get('version', '?')} "
                     f"source {str(plugin.get('source', '?'))[:8]}")
    return text


def _git(*args: str) -> str | None:
    try:
        done = subprocess.run(["git", "-C", str(PACKAGE), *args], capture_output=True, timeout=10, check=True)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.decode("utf-8", "replace").strip()
