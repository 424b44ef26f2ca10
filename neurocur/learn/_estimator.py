"""A small scikit-learn-style base class for the learners (no scikit-learn dependency).

Parameters are exactly the keyword arguments of ``__init__``, stored under the same
names; ``get_params`` reads them back by introspecting the signature, ``set_params``
writes them and re-validates, ``copy`` returns an independent deep copy (learned state
included), and ``repr`` shows the parameters.
"""

from __future__ import annotations

import copy as _copy
import inspect


class NotFittedError(ValueError, AttributeError):
    """Raised when a learner is used before its first ``partial_fit``."""


class Estimator:
    """Base class: subclasses store every ``__init__`` argument as an attribute of the same
    name and implement ``_validate_params()`` (raise ``ValueError`` on a bad value)."""

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [p.name for p in sig.parameters.values() if p.name != "self" and p.kind != p.VAR_KEYWORD]

    def get_params(self) -> dict:
        """The constructor parameters, by name."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params):
        """Set constructor parameters by name and re-validate; returns ``self``.

        On an already fitted learner, parameters that fix array shapes cannot change
        (a ``ValueError`` says so); the others take effect from the next ``partial_fit``.
        """
        names = set(self._param_names())
        unknown = sorted(set(params) - names)
        if unknown:
            raise ValueError(f"unknown parameter(s) {unknown} for {type(self).__name__}; valid: {sorted(names)}")
        old = self.get_params()
        for name, value in params.items():
            setattr(self, name, value)
        try:
            self._validate_params()
        except ValueError:
            for name, value in old.items():
                setattr(self, name, value)
            raise
        return self

    def _validate_params(self) -> None:  # pragma: no cover - every subclass overrides it
        raise NotImplementedError

    def copy(self):
        """An independent deep copy, learned state included."""
        return _copy.deepcopy(self)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"
