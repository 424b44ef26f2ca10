"""A small scikit-learn-style base class for the learners (no scikit-learn dependency).

Parameters are exactly the keyword arguments of ``__init__``, stored under the same
names and unchanged; each has a :class:`~neurocur.config.ParamSpec` in the class's
``param_specs``, the one place its type and range are declared (regions that pass a
parameter on to a learner reuse it, see :func:`neurocur.config.learner_param`).
``get_params`` reads the parameters back by introspecting the signature,
``set_params`` writes them and re-validates, ``copy`` returns an independent deep copy
(learned state included), and ``repr`` shows the parameters.
"""

from __future__ import annotations

import copy as _copy
import inspect
from typing import ClassVar

import numpy as np

from ..config import ParamSpec, coerce_params

#: ``random_state``: None, a seed, a numpy SeedSequence or a numpy Generator.
RANDOM_STATE = ParamSpec(int, low=0, optional=True, classes=(np.random.SeedSequence, np.random.Generator))


class NotFittedError(ValueError, AttributeError):
    """Raised when a learner is used before its first ``partial_fit``."""


class Estimator:
    """Base class: subclasses store every ``__init__`` argument as an attribute of the same
    name, declare a :class:`~neurocur.config.ParamSpec` for each in ``param_specs``, and
    override ``_check_params`` for checks that involve several parameters or the fitted
    state."""

    param_specs: ClassVar[dict[str, ParamSpec]] = {}

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

    def _validate_params(self) -> dict:
        """The parameters checked by their specs and by ``_check_params``, coerced (ints to
        float, ...); a bad one raises a ``ValueError`` (a ``ConfigError``) naming it, what
        was expected and what was given."""
        params = coerce_params(self.param_specs, self.get_params(), source=type(self).__name__)
        self._check_params(params)
        return params

    def _check_params(self, params: dict) -> None:
        """Checks beyond each parameter's spec, on the coerced ``params``; none by default."""

    def copy(self):
        """An independent deep copy, learned state included."""
        return _copy.deepcopy(self)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"
