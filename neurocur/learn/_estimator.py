"""The base class of the incremental learners IncSFA, CCIPCA and MCA: scikit-learn transformers.

They subclass scikit-learn's ``BaseEstimator`` and ``TransformerMixin``, so ``get_params``
(``deep`` accepted), ``set_params``, ``clone``, ``fit_transform``, ``Pipeline`` and
``GridSearchCV`` work as for any scikit-learn transformer, and an unfitted learner
raises scikit-learn's ``NotFittedError``.

Parameters are declared as regions and worlds declare theirs: each learner is a
dataclass (``@dataclass(eq=False, repr=False)``: compared by identity, as estimators are, and
shown by scikit-learn's ``repr``) whose fields are made with :func:`~neurocur.config.param`,
:func:`~neurocur.config.spec_param` or :func:`~neurocur.config.learner_param`, the one place
each parameter's type, range and default are declared (regions that pass a parameter on to a
learner reuse its spec, :func:`~neurocur.config.learner_param`). The dataclass's ``__init__``
is the keyword-argument constructor scikit-learn expects, storing every parameter under its
name and unchanged. As scikit-learn expects, neither the constructor nor ``set_params`` checks
the values: every ``fit`` and ``partial_fit`` checks them through the specs
(:func:`~neurocur.config.param_specs`), and a bad one raises a one-line ``ValueError`` (a
``ConfigError``) naming the parameter and what was expected; :meth:`Estimator.validate_params`
checks them without fitting.

Learning is streaming: ``partial_fit`` continues from the learned state, ``fit`` forgets
it first (``fit(X)`` is ``partial_fit(X)`` on a new instance with the same parameters).
Input is checked once per call, never per sample: scikit-learn's ``validate_data``
(2-d, numeric, finite, the feature count seen first, ``n_features_in_``), then the
learners' own scale check (:func:`~neurocur.learn._scale.check_scale`); a fresh
learner's first block must also vary and, for IncSFA and CCIPCA, reach past the samples
that only set the mean (:func:`~neurocur.learn.ccipca.check_first_block`).

``copy`` returns an independent deep copy (learned state included), and ``repr`` is
scikit-learn's: only the parameters changed from their defaults (``print_changed_only``). :func:`expected_failed_checks` lists the checks of scikit-learn's
``check_estimator`` that these learners fail by design, each with its reason.
"""

from __future__ import annotations

import copy as _copy
from typing import ClassVar

import numpy as np
from sklearn.base import BaseEstimator, ClassNamePrefixFeaturesOutMixin, TransformerMixin
from sklearn.exceptions import NotFittedError
from sklearn.utils.validation import check_is_fitted, validate_data

from ..config import coerce_params, param_specs
from ..config.checks import check_nonconstant
from ._scale import check_scale

__all__ = ["TWO_FEATURE_CHECKS", "Estimator", "NotFittedError", "expected_failed_checks"]

class Estimator(ClassNamePrefixFeaturesOutMixin, TransformerMixin, BaseEstimator):
    """Base class: subclasses are dataclasses (``@dataclass(eq=False, repr=False)``) whose fields are their
    parameters, each declared with a spec; they override ``_check_params`` for checks that
    involve several parameters or the fitted state, and implement ``partial_fit`` (setting
    ``n_samples_seen_`` when it starts a fresh state) and ``transform``."""

    #: rows the first block of a fresh learner needs
    _min_first_rows: ClassVar[int] = 1
    #: whether the learner centres its input (see ``check_scale``)
    _centred: ClassVar[bool] = True

    def set_params(self, **params):
        """Set parameters by name; returns ``self``.

        An unknown name raises ``ValueError`` and changes nothing. Values are not checked
        here but by the next ``fit`` or ``partial_fit`` (scikit-learn's convention); on an
        already fitted learner, parameters that fix array shapes cannot change unless ``fit``
        starts afresh (``partial_fit`` says so), and the others take effect from the next call.
        """
        old = self.get_params(deep=False)
        try:
            super().set_params(**params)
        except ValueError:
            for name, value in old.items():
                setattr(self, name, value)
            raise
        return self

    def validate_params(self):
        """Check the parameters now, as ``fit`` and ``partial_fit`` do; returns ``self``.

        For a caller that builds a learner from a file and wants a bad value reported where
        it is read, before any data arrives.
        """
        self._checked_params()
        return self

    def _checked_params(self) -> dict:
        """The parameters checked by their specs and by ``_check_params``, coerced (ints to
        float, ...); a bad one raises a ``ValueError`` (a ``ConfigError``) naming it, what
        was expected and what was given."""
        specs = param_specs(self)
        raw = tuple(getattr(self, k) for k in specs)
        cached = self.__dict__.get("_params_checked")
        if cached is not None and _same(cached[0], raw):  # unchanged since the last check
            return dict(cached[1])
        params = coerce_params(specs, self.get_params(deep=False), source=type(self).__name__)
        self._check_params(params)
        self._params_checked = (raw, params)
        return dict(params)

    def _check_params(self, params: dict) -> None:
        """Checks beyond each parameter's spec, on the coerced ``params``; none by default."""

    def __sklearn_is_fitted__(self) -> bool:
        return hasattr(self, "n_samples_seen_")

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.requires_fit = True  # stateful: transform uses the learned state
        tags.non_deterministic = False  # the same random_state and input give the same result
        tags.target_tags.required = False  # unsupervised: y is accepted and ignored
        tags.input_tags.two_d_array = True  # rows are time steps (samples), columns features
        tags.input_tags.sparse = False  # dense input only
        tags.input_tags.allow_nan = False  # X must be finite
        tags.transformer_tags.preserves_dtype = ["float64"]  # output is float64 whatever the input
        # no tag states the rows a first block needs (IncSFA and CCIPCA: more than the
        # samples that only set the mean, 4 for l = 2): the first partial_fit checks them
        return tags

    def fit(self, X, y=None):
        """Learn from the rows of ``X`` on a fresh state; returns ``self``.

        Exactly ``partial_fit(X)`` on a new instance with the same parameters: the
        learned state is dropped, then the rows are learned in order. ``y`` is ignored.
        """
        self._unfit()
        return self.partial_fit(X)

    def _unfit(self) -> None:
        """Mark the learner unfitted: the next block is a first block, whose ``partial_fit``
        re-creates the whole learned state from the parameters (``_start``) and resets
        ``n_features_in_``."""
        if self.__sklearn_is_fitted__():
            del self.n_samples_seen_

    def _check_fitted(self) -> None:
        check_is_fitted(self)

    def _check_X(self, X, *, learn: bool, min_rows: int = 1) -> np.ndarray:
        """``X`` checked once for this call, as a C-contiguous float64 array (time, features).

        ``learn``: the call learns from ``X``; on a fresh learner ``X`` is then the first
        block, which needs ``_min_first_rows`` rows, sets ``n_features_in_``, must vary if
        the learner centres its input, and must not be too small in scale. Otherwise (and
        for ``transform``) the learner must be fitted and ``X`` must have
        ``n_features_in_`` columns.
        """
        first = learn and not self.__sklearn_is_fitted__()
        if not learn:
            self._check_fitted()
        elif not first and _plain_block(X, self.n_features_in_):
            # the per-episode path of a fitted learner: the same contract as below (finite,
            # n_features_in_ columns, in range) checked in one pass, without validate_data's overhead
            check_scale(X, first=False, centred=self._centred)
            return X
        X = validate_data(
            self, X, reset=first, dtype="numeric", ensure_min_samples=max(min_rows, self._min_first_rows if first else 1)
        )
        X = np.ascontiguousarray(X, dtype=np.float64)
        if first and self._centred:
            check_nonconstant(X)
        check_scale(X, first=first, centred=self._centred)
        return X

    @property
    def _n_features_out(self) -> int:
        """Output columns (for ``get_feature_names_out``): always ``n_components``."""
        self._check_fitted()
        return self.n_components

    def copy(self):
        """An independent deep copy, learned state included."""
        return _copy.deepcopy(self)


#: The checks of scikit-learn 1.9 that fit data with only 2 features.
TWO_FEATURE_CHECKS = (
    "check_estimators_overwrite_params",
    "check_estimators_fit_returns_self",
    "check_readonly_memmap_input",
    "check_fit_idempotent",
    "check_fit_check_is_fitted",
    "check_n_features_in",
)


def expected_failed_checks(estimator) -> dict[str, str]:
    """The checks of ``sklearn.utils.estimator_checks`` that ``estimator`` (an IncSFA, CCIPCA
    or MCA) fails by design, mapped to the reason; pass it as ``check_estimator(estimator,
    expected_failed_checks=expected_failed_checks(estimator))``.

    The checks whose data have 2 features, when the learner is set to estimate more than 2
    components (IncSFA's ``n_pca`` or CCIPCA's and MCA's ``n_components`` above 2): like
    PCA, a learner cannot estimate more components than there are features. None otherwise:
    the defaults pass every check.

    Parameters
    ----------
    estimator : IncSFA or CCIPCA or MCA
        The learner checked.

    Returns
    -------
    dict of str to str or None
        The reason of each check failed by design, or None.
    """
    name = "n_pca" if hasattr(estimator, "n_pca") else "n_components"
    needed = getattr(estimator, name)
    if not isinstance(needed, int) or needed <= 2:
        return {}
    reason = f"the check fits data with 2 features, fewer than {name}={needed} (it must not exceed the features)"
    return dict.fromkeys(TWO_FEATURE_CHECKS, reason)


def _same(a: tuple, b: tuple) -> bool:
    """Parameter tuples equal value by value, each the same type (``1 == 1.0`` is not enough)."""
    return len(a) == len(b) and all(type(x) is type(y) and x == y for x, y in zip(a, b))


def _plain_block(X, n_features: int) -> bool:
    """``X`` is already what ``validate_data`` would return: a C-contiguous 2-d float64 ndarray
    of ``n_features`` columns and at least one row."""
    return (type(X) is np.ndarray and X.dtype == np.float64 and X.ndim == 2 and X.shape[0] >= 1
            and X.shape[1] == n_features and X.flags.c_contiguous)

