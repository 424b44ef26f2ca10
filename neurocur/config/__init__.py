"""Configuration: errors that name the file and key (:mod:`.errors`), and the one parameter
system (:mod:`.params`, with :mod:`.param_tables` for TOML tables).

Every configuration problem raises :class:`ConfigError`, a ``ValueError`` whose message
reads ``"<file>: key '<dotted.key>': expected <...>, got <...>"``, so a user can go
straight to the offending line. Reading the files themselves is :mod:`neurocur.tables`.

Parameters of regions (and of anything else configured from a file) are frozen
dataclasses whose fields are declared with :func:`param` (or :func:`spec_param` for a
ready :class:`ParamSpec`, e.g. a list, a table or nested parameters);
:func:`check_params` validates type and range, and :func:`make_params` builds an
instance from a TOML table. The learners of :mod:`neurocur.learn` declare their
parameters the same way, as fields of dataclasses (scikit-learn estimators store them
unchanged, so they check a copy: :func:`param_specs`, :func:`coerce_params`); a
parameter passed on to a learner is declared with :func:`learner_param`, so it takes
the learner's spec. Loading a configuration never executes code.

A feature whose optional package is missing names the extra to install (:mod:`.extras`).

The checks shared by every layer (input blocks, seeds, scalar arguments of functions called
from Python) are :mod:`.checks`.
"""

from .checks import (
    RANDOM_STATE,
    check_block,
    check_fraction,
    check_nonconstant,
    check_positive_int,
    check_random_state,
)
from .errors import ConfigError, describe, join_key
from .extras import MissingExtra, extra
from .param_tables import (
    check_params,
    check_table,
    coerce_params,
    make_params,
    params_to_dict,
    path_values,
    resolve_paths,
)
from .params import ParamSpec, learner_param, param, param_specs, spec_param

__all__ = [
    "ConfigError",
    "ParamSpec",
    "param",
    "spec_param",
    "learner_param",
    "param_specs",
    "coerce_params",
    "check_params",
    "check_table",
    "make_params",
    "resolve_paths",
    "params_to_dict",
    "path_values",
    "describe",
    "join_key",
    "MissingExtra",
    "extra",
    "RANDOM_STATE",
    "check_block",
    "check_fraction",
    "check_nonconstant",
    "check_positive_int",
    "check_random_state",
]
