"""The gym world's environment ids: gymnasium's ``module:id`` form and the modules that register ids.

A package of gymnasium environments (neurogym, a lab's own tasks) registers its ids when it is
imported. The ``gym`` world (:mod:`.gym`) names such packages in ``imports``, or prefixes an id
with its module as gymnasium does (``"neurogym:PerceptualDecisionMaking-v0"``). Two steps:

* :func:`check_ids`, when the parameters are checked (an experiment file is read): every module
  name is dotted Python identifiers (anything else is refused before any import), and when no
  module is named every id must already be registered;
* :func:`import_ids`, when the world is built (in every process that builds it: the registry is
  per process): each module the user named is imported, in order (``imports``, then the
  ``module:`` prefixes), and every id must then be registered. Nothing else is imported.

A failure is one :class:`~neurocur.config.ConfigError` naming the key (``imports[i]``, ``envs[i]``).
"""

from __future__ import annotations

import importlib
import keyword
from collections.abc import Sequence

import gymnasium

from ..config import ConfigError, describe

__all__ = ["check_ids", "import_ids", "is_module_name", "split_id"]

_REGISTERED = "a registered gymnasium environment id (e.g. 'CartPole-v1')"


def is_module_name(text: str) -> bool:
    """Whether ``text`` is an absolute module name: Python identifiers, not keywords, joined by dots.

    Parameters
    ----------
    text : str
        The name to check.

    Returns
    -------
    bool
        True for a dotted module name such as ``"neurogym"`` or ``"my_lab.tasks"``.
    """
    return all(part.isidentifier() and not keyword.iskeyword(part) for part in text.split("."))


def split_id(text: str) -> tuple[str | None, str]:
    """``(module, id)`` of gymnasium's ``"module:id"`` form; ``(None, text)`` without a colon.

    Parameters
    ----------
    text : str
        An environment id, optionally prefixed ``"module:"``.

    Returns
    -------
    tuple of (str or None, str)
        The module (None without a prefix) and the id.
    """
    module, colon, env_id = text.partition(":")
    return (module, env_id) if colon else (None, text)


def check_ids(envs: Sequence[str], imports: Sequence[str] | None, where: str) -> None:
    """The checks that need no import (module docstring); ConfigError naming ``imports[i]`` or ``envs[i]``.

    Parameters
    ----------
    envs : sequence of str
        The environment ids, each optionally ``"module:id"``.
    imports : sequence of str, optional
        The modules to import when the world is built.
    where : str
        The parameter class, named by the ``ConfigError``.

    Raises
    ------
    ConfigError
        A module name that is not dotted Python identifiers, a malformed ``module:id``, or, when no
        module is named at all, an id gymnasium has not registered.
    """
    for i, name in enumerate(imports or ()):
        if not is_module_name(name):
            raise ConfigError(where, f"imports[{i}]", "a module name (dotted Python identifiers, e.g. 'neurogym')",
                              describe(name))
    importing = bool(imports) or any(split_id(text)[0] is not None for text in envs)
    for i, text in enumerate(envs):
        module, env_id = split_id(text)
        if module is not None and not (is_module_name(module) and env_id and ":" not in env_id):
            raise ConfigError(where, f"envs[{i}]", "a gymnasium environment id, or 'module:id' whose module is "
                              "dotted Python identifiers (e.g. 'neurogym:PerceptualDecisionMaking-v0')", describe(text))
        if not importing and env_id not in gymnasium.registry:
            raise ConfigError(where, f"envs[{i}]", f"{_REGISTERED}, or 'module:id' whose module registers it, or "
                              "the module that registers it in imports", describe(text))


def import_ids(envs: Sequence[str], imports: Sequence[str] | None, where: str) -> tuple[str, ...]:
    """Import the modules named in ``imports`` and in ``envs``' prefixes; the ids without prefix.

    Raises ConfigError naming the key when an import fails (the exception's first line) or an
    id is not registered after the imports.

    Parameters
    ----------
    envs : sequence of str
        The environment ids, each optionally ``"module:id"``.
    imports : sequence of str, optional
        Modules to import first, in order, before the ids' own prefixes.
    where : str
        The parameter class, named by the ``ConfigError``.

    Returns
    -------
    tuple of str
        The ids without their ``module:`` prefixes, in the order of ``envs``.
    """
    named = [(f"imports[{i}]", name) for i, name in enumerate(imports or ())]
    named += [(f"envs[{i}]", split_id(text)[0]) for i, text in enumerate(envs) if split_id(text)[0] is not None]
    for key, name in named:
        try:
            importlib.import_module(name)
        except Exception as exc:  # the module's own code runs: any error is the module's, reported in one line
            reason = (str(exc).strip().splitlines() or [""])[0]
            raise ConfigError(where, key, "a module that imports (installed, or on PYTHONPATH)",
                              f"{name!r}, whose import raised {type(exc).__name__}: {reason}") from None
    ids = tuple(split_id(text)[1] for text in envs)
    for i, env_id in enumerate(ids):
        if env_id not in gymnasium.registry:
            modules = ", ".join(repr(name) for _, name in named)
            imported = f"once {modules} {'is' if len(named) == 1 else 'are'} imported" if named else "(no module named)"
            raise ConfigError(where, f"envs[{i}]", f"{_REGISTERED} {imported}", describe(envs[i]))
    return ids
