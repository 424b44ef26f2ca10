"""IncSFA, CCIPCA and MCA are scikit-learn transformers: check_estimator, Pipeline, clone, GridSearchCV."""

import numpy as np
import pytest
import sklearn.exceptions
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, TimeSeriesSplit
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils import get_tags
from sklearn.utils.estimator_checks import check_estimator

from neurocur.learn import CCIPCA, MCA, IncSFA, expected_failed_checks
from neurocur.learn._estimator import TWO_FEATURE_CHECKS, NotFittedError


def slow_mixture(n=3000, d=3, seed=0):
    """A slow (period 500), a faster and a fast sinusoid mixed into ``d`` dimensions."""
    t = np.arange(n)
    S = np.stack([np.sin(2 * np.pi * t / 500), np.sin(2 * np.pi * t / 37 + 1), np.sin(2 * np.pi * t / 11 + 2)], 1)
    return S @ np.random.default_rng(seed).standard_normal((3, d))


LEARNERS = [IncSFA(), IncSFA(n_components=1, n_pca=2), CCIPCA(), MCA()]


@pytest.mark.filterwarnings("ignore:Skipping check check_array_api_input")  # needs SCIPY_ARRAY_API
@pytest.mark.filterwarnings("error:.*It is recommended to delay parameter validation until fit")
@pytest.mark.parametrize("estimator", LEARNERS, ids=repr)
def test_check_estimator(estimator):
    """Every check passes except the declared ones (none for these), and each declared one does fail."""
    expected = expected_failed_checks(estimator)
    assert len(expected) <= 3
    results = check_estimator(estimator, expected_failed_checks=expected, on_fail=None)
    failed = [(r["check_name"], r["exception"]) for r in results if r["status"] == "failed"]
    assert failed == []
    assert {r["check_name"] for r in results if r["status"] == "xfail"} == set(expected)
    assert {r["check_name"] for r in results if r["status"] == "skipped"} <= {"check_array_api_input"}


def test_expected_failures_and_their_reasons():
    """The defaults fail no check; more than 2 components cannot fit the 2-feature data of some checks."""
    assert expected_failed_checks(CCIPCA()) == expected_failed_checks(MCA()) == expected_failed_checks(IncSFA()) == {}
    three = expected_failed_checks(IncSFA(n_pca=3))
    assert set(three) == set(TWO_FEATURE_CHECKS) and "n_pca=3" in three["check_fit_idempotent"]
    assert set(expected_failed_checks(CCIPCA(3))) == set(TWO_FEATURE_CHECKS)


@pytest.mark.parametrize("cls, bad, key", [(IncSFA, {"mca_rate": 0.9}, "mca_rate"), (CCIPCA, {"eig_cutoff": 1.5}, "eig_cutoff"),
                                          (MCA, {"gamma": "big"}, "gamma")])
def test_parameters_are_checked_at_fit_not_at_construction(cls, bad, key):
    """scikit-learn's convention: construction and set_params store any value; fit names the bad one, in one line."""
    X = slow_mixture(50)
    learner = cls(**bad)
    assert learner.get_params()[key] == bad[key]
    with pytest.raises(ValueError, match=rf"^{cls.__name__}: key '{key}': expected .*, got ") as err:
        learner.fit(X)
    assert "\n" not in str(err.value) and not hasattr(learner, "n_samples_seen_")
    with pytest.raises(ValueError, match=rf"key '{key}'"):
        cls().set_params(**bad).validate_params()  # checked on request, as before any data
    with pytest.raises(ValueError, match="must not exceed n_pca=2"):
        IncSFA(3, 2).fit(X)


def test_incsfa_default_n_pca_is_three_capped_at_the_features():
    """n_pca=None whitens min(3, features): exactly n_pca=3 on wider data, n_pca=2 on 2 features."""
    X = slow_mixture(400, d=5)
    default, three = IncSFA(random_state=0).fit(X), IncSFA(n_pca=3, random_state=0).fit(X)
    assert default.n_pca_ == three.n_pca_ == 3
    np.testing.assert_array_equal(default.projection_, three.projection_)
    narrow = IncSFA(random_state=0).fit(X[:, :2])
    assert narrow.n_pca_ == 2 and narrow.eigenvalues_.shape == (2,)
    np.testing.assert_array_equal(narrow.projection_, IncSFA(n_pca=2, random_state=0).fit(X[:, :2]).projection_)


def test_repr_shows_the_changed_parameters_only():
    assert repr(IncSFA()) == "IncSFA()" and repr(MCA()) == "MCA()"
    assert repr(IncSFA(1, mca_rate=0.02, random_state=0)) == "IncSFA(mca_rate=0.02, n_components=1, random_state=0)"
    assert repr(CCIPCA(3, amnesic=2.0)) == "CCIPCA(amnesic=2.0, n_components=3)"
    assert repr(make_pipeline(StandardScaler(), IncSFA(dtype="float32"))).endswith("('incsfa', IncSFA(dtype='float32'))])")


@pytest.mark.parametrize("estimator", LEARNERS, ids=repr)
def test_tags_state_what_is_true(estimator):
    tags = get_tags(estimator)
    assert tags.requires_fit and not tags.non_deterministic
    assert not tags.input_tags.allow_nan and not tags.input_tags.sparse
    assert not tags.target_tags.required
    assert tags.transformer_tags.preserves_dtype == ["float64"]


def test_pipeline_clone_and_deep_params():
    X = slow_mixture()
    pipe = make_pipeline(StandardScaler(), IncSFA(random_state=0))
    y = pipe.fit(X).transform(X)
    assert y.shape == (len(X), 2) and np.isfinite(y).all()
    params = pipe.get_params(deep=True)
    assert params["incsfa__mca_rate"] == 0.05
    pipe.set_params(incsfa__mca_rate=0.02)
    assert pipe[-1].mca_rate == 0.02
    twin = clone(pipe)
    assert twin[-1].get_params() == pipe[-1].get_params() and not hasattr(twin[-1], "n_features_in_")
    np.testing.assert_array_equal(twin.fit(X).transform(X), clone(twin).fit(X).transform(X))
    assert list(pipe[-1].get_feature_names_out()) == ["incsfa0", "incsfa1"]


@pytest.mark.parametrize("cls", [IncSFA, CCIPCA, MCA])
def test_fit_is_partial_fit_on_a_fresh_state(cls):
    X = slow_mixture(600)
    fresh = cls(random_state=3).partial_fit(X)
    refit = cls(random_state=3).partial_fit(X[::-1]).partial_fit(X[:100]).fit(X)
    np.testing.assert_array_equal(refit.transform(X), fresh.transform(X))
    assert refit.n_samples_seen_ == fresh.n_samples_seen_ == 600
    np.testing.assert_array_equal(cls(random_state=3).fit_transform(X), fresh.transform(X))
    assert cls(random_state=3).partial_fit(X, None).n_features_in_ == 3  # y accepted and ignored


def test_incsfa_fit_is_one_episode():
    """fit learns X as one episode: the same state as partial_fit, not as two calls."""
    X = slow_mixture(400)
    one = IncSFA(random_state=0).fit(X)
    np.testing.assert_array_equal(one.projection_, IncSFA(random_state=0).partial_fit(X).projection_)
    split = IncSFA(random_state=0).partial_fit(X[:200]).partial_fit(X[200:])
    assert not np.array_equal(one.projection_, split.projection_)


@pytest.mark.parametrize("cls", [IncSFA, CCIPCA, MCA])
def test_not_fitted_error_is_sklearns(cls):
    assert NotFittedError is sklearn.exceptions.NotFittedError
    with pytest.raises(sklearn.exceptions.NotFittedError, match="not fitted"):
        cls().transform(np.ones((3, 3)))
    with pytest.raises(ValueError):  # still a ValueError (and an AttributeError), as before
        cls().transform(np.ones((3, 3)))


def test_fixed_output_width_while_learning():
    """CCIPCA's active count changes while it learns; its output width does not."""
    X = slow_mixture(2000, d=6) + 1e-3 * np.random.default_rng(1).standard_normal((2000, 6))
    pca = CCIPCA(4, var_fraction=0.999, random_state=0)
    actives = []
    for start in range(0, 2000, 50):
        pca.partial_fit(X[start : start + 50])
        Z = pca.transform(X[:20])
        assert Z.shape == (20, 4)
        assert np.all(Z[:, pca.n_active_ :] == 0) and np.all(Z[:, : pca.n_active_] != 0)
        actives.append(pca.n_active_)
    assert len(set(actives)) > 1  # the case the fixed width is for


@pytest.mark.parametrize("cls", [IncSFA, CCIPCA])
def test_first_block_must_reach_past_the_mean_only_samples(cls):
    """With the amnesic l = 2 the first 3 samples only set the mean (rate capped at 1): their
    centred values are round-off, and whitening them gave features of order 1e16."""
    X = slow_mixture(200)
    with pytest.raises(ValueError, match="first 3 samples.*at least 4 rows"):
        cls(amnesic=2.0).fit(X[:3])
    assert cls(amnesic=2.0).partial_fit(X[:4]).partial_fit(X[4:5]).n_samples_seen_ == 5  # later blocks may be short
    assert np.abs(cls(amnesic=2.0, random_state=0).fit(X[:4]).transform(X)).max() < 100
    assert cls(amnesic=0.0).fit(X[:2]).n_samples_seen_ == 2  # l = 0: only the first sample sets the mean
    assert cls().fit(X[:2]).n_samples_seen_ == 2  # the default schedule: μ = 0 up to t1, likewise


def test_incsfa_outputs_zeros_before_any_component_is_active():
    """No whitened component is active until one carries variance: the features are then zeros."""
    X = np.array([[0.0, 0.0, 0.0]] * 2 + [[1.0, 1.0, 1.0]] * 3)  # rows 4-5 equal the mean rows 1-3 set, exactly
    model = IncSFA(amnesic=2.0, mean_rate="amnesic", random_state=0).fit(X)
    assert model.n_active_ == 0
    np.testing.assert_array_equal(model.transform(slow_mixture(50)), np.zeros((50, 2)))


def test_score_is_negative_mean_slowness():
    X = slow_mixture()
    model = IncSFA(random_state=0).fit(X)
    assert model.score(X) == pytest.approx(-model.delta(X).mean())
    assert model.score(X, None) < 0
    one = IncSFA(1, 3, random_state=0)
    assert one.fit(X).score(X) > -0.001 > -0.1 > one.fit(X[:50]).score(X)  # learned beats barely trained


def test_grid_search_tunes_mca_rate():
    """Time-ordered cross-validation picks the CIMCA rate that learns the slow source in time."""
    X = slow_mixture()
    search = GridSearchCV(IncSFA(1, 3, random_state=0), {"mca_rate": [0.001, 0.05]}, cv=TimeSeriesSplit(3))
    search.fit(X)
    assert search.best_params_ == {"mca_rate": 0.05}
    slow, fast = search.cv_results_["mean_test_score"][::-1]
    assert slow > -0.02 and fast < -0.2  # a clear winner
    assert search.best_estimator_.n_samples_seen_ == len(X)  # refit on all rows


def test_set_params_rejects_unknown_names_and_rolls_back():
    model = IncSFA(random_state=0)
    with pytest.raises(ValueError, match="Invalid parameter 'mca_rate_typo'"):
        model.set_params(mca_rate=0.1, gamma="auto", eig_cutoff=0.5, n_pca=4, mca_rate_typo=1)
    assert model.get_params() == IncSFA(random_state=0).get_params()


def test_fast_path_of_a_fitted_learner_keeps_the_contract():
    """A fitted learner's plain float64 blocks skip validate_data but are checked the same way."""
    X = np.random.default_rng(0).random((50, 6))
    sfa = IncSFA(2, 3, random_state=0).fit(X)
    reference = IncSFA(2, 3, random_state=0).fit(X)
    sfa.partial_fit(X)
    reference.partial_fit(np.asfortranarray(X))  # not C-contiguous: the validate_data path
    np.testing.assert_array_equal(sfa.projection_, reference.projection_)
    bad = X.copy()
    bad[4, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        sfa.partial_fit(bad)
    with pytest.raises(ValueError, match="features"):
        sfa.partial_fit(X[:, :5].copy())
    sfa.mca_rate = 0.9  # a parameter changed after the last check is checked again
    with pytest.raises(ValueError, match="mca_rate"):
        sfa.partial_fit(X)
