"""Every learner parameter is declared once, as a dataclass field carrying a ParamSpec (as regions and
worlds declare theirs), and checked through it."""

from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest

from neurocur.config import describe, param_specs
from neurocur.learn.ccipca import CCIPCA, AmnesicSchedule
from neurocur.learn.incsfa import IncSFA
from neurocur.learn.lspi import LSPI, lspi, value_iteration
from neurocur.learn.mca import MCA
from neurocur.learn.omega import omega
from neurocur.learn.roc import MIN_WEIGHT, ROCBank

P2 = np.array([[[1.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [1.0, 0.0]]])  # 2 states, 2 actions
R2 = np.array([[1.0, 0.0], [0.0, 1.0]])


def make(cls, **kwargs):
    """A learner with ``kwargs`` over valid required arguments."""
    if cls is CCIPCA or cls is MCA:
        return cls(**({"n_components": 1} | kwargs))
    if cls is ROCBank:
        return cls(**({"n_states": 3, "n_features": 2} | kwargs))
    if cls is LSPI:
        return cls(P2, **kwargs)
    return cls(**kwargs)


def spec(cls, name):
    """The declared spec of ``cls``'s parameter ``name`` (``prune``'s argument for ROCBank's ``min_weight``)."""
    return MIN_WEIGHT if (cls, name) == (ROCBank, "min_weight") else param_specs(cls)[name]


BAD = [
    (CCIPCA, "n_components", [0, -1, 2.5, True, "2", None]),
    (CCIPCA, "amnesic", [-1.0, -1e-12, "2", np.nan, np.inf, True, None]),
    (CCIPCA, "var_fraction", [0.0, -0.1, 1.0000001, 1.5, "0.9", np.nan]),
    (CCIPCA, "eig_cutoff", [1.0, -0.1, 1.5, np.nan, None, "0"]),
    (CCIPCA, "random_state", [-1, 1.5, "seed", [1, 2]]),
    (MCA, "n_components", [0, 2.0]),
    (MCA, "learning_rate", [0.0, -0.1, 0.5000001, 0.6, "0.1", None, np.inf]),
    (MCA, "gamma", [0.0, -1.0, "big", np.inf, None, False]),
    (MCA, "random_state", ["seed"]),
    (IncSFA, "n_components", [0, 1.0]),
    (IncSFA, "n_pca", [0, 2.0]),
    (IncSFA, "amnesic", [-2.0, "l"]),
    (IncSFA, "var_fraction", [0.0, 2.0]),
    (IncSFA, "eig_cutoff", [1.0, 1.5, -1e-3]),
    (IncSFA, "mca_rate", [0.0, 0.51, 0.9, 1.0]),
    (IncSFA, "gamma", [0.0, "fast"]),
    (IncSFA, "random_state", ["seed", -3]),
    (ROCBank, "n_states", [0, 3.0]),
    (ROCBank, "n_features", [0, 2.0]),
    (ROCBank, "max_clusters", [1, 0, 2.0]),
    (ROCBank, "amnesic", [-0.1, 1.5, np.nan, "0.01"]),
    (ROCBank, "width", [0.0, -1.0, np.nan, np.inf, "wide"]),
    (LSPI, "discount", [1.0, -0.1, np.nan, "high", None]),
    (LSPI, "max_iter", [0, -5, 1.5]),
    (LSPI, "tol", [-1.0, np.nan, "0"]),
]


@pytest.mark.parametrize("cls, name, value", [(c, n, v) for c, n, values in BAD for v in values])
def test_out_of_range_parameter_is_named(cls, name, value):
    with pytest.raises(ValueError) as err:
        make(cls, **{name: value})
    expected = spec(cls, name).expected()
    assert str(err.value) == f"{cls.__name__}: key '{name}': expected {expected}, got {describe(value)}"


@pytest.mark.parametrize("cls, name, text", [
    (IncSFA, "mca_rate", "a number > 0 and <= 0.5"),
    (MCA, "gamma", "a number > 0 or 'auto'"),
    (CCIPCA, "eig_cutoff", "a number >= 0 and < 1"),
    (CCIPCA, "var_fraction", "a number > 0 and <= 1 or None (omit the key)"),
    (CCIPCA, "amnesic", "a number >= 0 or an AmnesicSchedule"),
    (CCIPCA, "random_state", "an integer >= 0 or a SeedSequence or a Generator or None (omit the key)"),
    (ROCBank, "max_clusters", "an integer >= 2"),
    (ROCBank, "amnesic", "a number >= 0 and <= 1"),
    (ROCBank, "min_weight", "a number >= 0"),
    (LSPI, "discount", "a number >= 0 and < 1"),
])
def test_declared_bounds(cls, name, text):
    assert spec(cls, name).expected() == text


@pytest.mark.parametrize("cls, kwargs", [
    (CCIPCA, dict(amnesic=0)), (CCIPCA, dict(amnesic=AmnesicSchedule())), (CCIPCA, dict(eig_cutoff=0.0)),
    (CCIPCA, dict(var_fraction=1.0)), (CCIPCA, dict(var_fraction=1e-9)), (CCIPCA, dict(n_components=np.int64(2))),
    (CCIPCA, dict(random_state=np.random.default_rng(0))), (CCIPCA, dict(random_state=np.random.SeedSequence(1))),
    (CCIPCA, dict(random_state=0)), (MCA, dict(learning_rate=0.5)), (MCA, dict(gamma="auto")),
    (MCA, dict(gamma=1e-9)), (IncSFA, dict(n_components=3, n_pca=3)), (IncSFA, dict(mca_rate=0.5)),
    (ROCBank, dict(amnesic=0)), (ROCBank, dict(amnesic=1)), (ROCBank, dict(max_clusters=2)),
    (LSPI, dict(discount=0.0)), (LSPI, dict(discount=0.999)), (LSPI, dict(tol=0)), (LSPI, dict(max_iter=1)),
])
def test_boundary_values_accepted(cls, kwargs):
    make(cls, **kwargs)


@pytest.mark.parametrize("cls", [CCIPCA, MCA, IncSFA, ROCBank])
def test_every_constructor_parameter_is_a_field_with_a_spec(cls):
    assert dataclasses.is_dataclass(cls)
    assert [f.name for f in dataclasses.fields(cls)] == list(param_specs(cls))
    assert list(param_specs(cls)) == list(inspect.signature(cls).parameters)


def test_lspi_fields_are_its_parameters_and_the_rest_is_data():
    assert list(param_specs(LSPI)) == ["discount", "max_iter", "tol"]
    assert list(inspect.signature(LSPI).parameters) == ["P", "discount", "features", "max_iter", "tol"]
    planner = LSPI(P2, 0, tol=0)
    assert type(planner.discount) is float and type(planner.tol) is float  # stored checked and coerced
    assert repr(planner) == "LSPI(discount=0.0, max_iter=100, tol=0.0)"


def test_learners_compare_by_identity():
    """As estimators do (scikit-learn's clone and caches rely on it): the dataclasses define no ``__eq__``."""
    a, b = IncSFA(random_state=0), IncSFA(random_state=0)
    assert a != b and a == a and len({a, b, ROCBank(1, 1), ROCBank(1, 1)}) == 4


def test_incsfa_reuses_ccipca_and_mca_specs():
    """One declaration per bound: IncSFA's specs are CCIPCA's and MCA's objects."""
    specs, ccipca, mca = param_specs(IncSFA), param_specs(CCIPCA), param_specs(MCA)
    assert specs["mca_rate"] is mca["learning_rate"]
    assert specs["mca_rates"] is mca["component_rates"]
    assert specs["gamma"] is mca["gamma"]
    assert specs["n_components"] is mca["n_components"]
    for name in ("amnesic", "var_fraction", "eig_cutoff", "orthonormalize", "random_state"):
        assert specs[name] is ccipca[name]
    assert specs["n_pca"] is ccipca["n_components"]


def test_arguments_stored_unchanged():
    schedule = AmnesicSchedule()
    model = IncSFA(np.int64(1), 2, amnesic=schedule, mca_rate=1 / 4, gamma="auto", random_state=np.int64(5))
    params = model.get_params()
    assert type(params["n_components"]) is np.int64 and params["amnesic"] is schedule
    assert type(params["random_state"]) is np.int64
    assert type(CCIPCA(2, amnesic=2).amnesic) is int


def test_set_params_and_partial_fit_check_specs():
    X = np.random.default_rng(0).standard_normal((20, 4))
    model = IncSFA(random_state=0)
    with pytest.raises(ValueError, match=r"^IncSFA: key 'eig_cutoff': expected a number >= 0 and < 1, got 1.0"):
        model.set_params(eig_cutoff=1.0)
    assert model.eig_cutoff == 1e-3
    model.mca_rate = 0.9  # bypasses set_params: the next partial_fit checks it
    with pytest.raises(ValueError, match=r"key 'mca_rate'"):
        model.partial_fit(X)
    assert not hasattr(model, "mean_")
    mca = MCA(1)
    mca.gamma = "big"
    with pytest.raises(ValueError, match=r"key 'gamma'"):
        mca.partial_fit(X)
    pca = CCIPCA(2).partial_fit(X)
    pca.var_fraction = 0.0
    with pytest.raises(ValueError, match=r"key 'var_fraction'"):
        pca.transform(X)


@pytest.mark.parametrize("kwargs, key", [
    (dict(t1=-1), "t1"), (dict(t2=np.inf), "t2"), (dict(c=-0.5), "c"), (dict(r=0.0), "r"), (dict(r="2000"), "r"),
    (dict(t1=200, t2=20), "t2"), (dict(t1=20, t2=20), "t2"),
])
def test_amnesic_schedule_names_the_field(kwargs, key):
    with pytest.raises(ValueError, match=rf"^AmnesicSchedule: key '{key}': expected "):
        AmnesicSchedule(**kwargs)


def test_schedule_coerced_and_used_like_before():
    s = AmnesicSchedule(t1=20, t2=200, c=2, r=2000)
    assert s == AmnesicSchedule() and isinstance(s.t1, float)


def test_prune_and_functions_check_their_parameters():
    bank = ROCBank(2, 2)
    with pytest.raises(ValueError, match=r"^ROCBank.prune: key 'min_weight': expected a number >= 0, got -0.1"):
        bank.prune(-0.1)
    assert bank.prune(0.0) == 0
    with pytest.raises(ValueError, match=r"^value_iteration: key 'max_iter': expected an integer >= 1, got 0"):
        value_iteration(P2, R2, 0.5, max_iter=0)
    with pytest.raises(ValueError, match=r"^LSPI: key 'discount'"):
        lspi(P2, R2, 1.0)
    X = np.sin(np.linspace(0, 20, 200))[:, None] * [1.0, 0.5] + np.cos(np.linspace(0, 3, 200))[:, None] * [0, 1.0]
    with pytest.raises(ValueError, match=r"^omega: key 'eta': expected a number > 0 and <= 0.5, got 0.5000001"):
        omega(X, 0.5000001)
