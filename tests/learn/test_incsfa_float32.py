"""IncSFA's opt-in fast path (``dtype="float32"``) against the float64 path and the references.

The fast path stores CCIPCA's directions in float32 and compiles the loops with fast-math
(``neurocur.learn._kernels``), so it is compared with stated tolerances, never bitwise:

* one block from the same state equals the float64 transcription of Algorithms 1-3
  (``test_reference_algorithms``) to ``RTOL_FLOAT32`` (float32 round-off grown over a
  100-sample block: measured up to 4e-7), where the float64 path is held to 1e-8;
* trained to convergence, it passes the float64 path's batch-SFA and mdp-toolkit
  thresholds (``test_incsfa``), and its slow features correlate with the float64 path's
  to within 1e-6;
* on 7500-pixel frames (the iCub size) its eigenvalues and slowest feature follow the
  float64 path's.
"""

import numpy as np
import pytest
import test_incsfa
import test_reference_algorithms as reference

from neurocur.config import ConfigError
from neurocur.learn.ccipca import AmnesicSchedule
from neurocur.learn.incsfa import IncSFA
from neurocur.learn.sfa_batch import batch_sfa
from neurocur.regions.ec import ECParams

RTOL_FLOAT32 = 1e-5

sb_frames = reference.sb_frames
mixture = test_incsfa.mixture
reference_mixture = pytest.fixture(reference.mixture.__wrapped__, scope="module", name="reference_mixture")


@pytest.mark.parametrize("case", list(reference.CASES))
def test_block_equals_algorithms_1_and_2_to_float32_round_off(request, monkeypatch, case):
    data, params = reference.CASES[case]
    X = request.getfixturevalue("reference_mixture" if data == "mixture" else data)
    model = IncSFA(**params, random_state=11, dtype="float32")
    for start in range(0, 300, 100):
        model.partial_fit(X[start : start + 100])
    state, block = reference.incsfa_state(model), X[300:400]
    ref = reference.incsfa_reference(state, block, model.get_params())
    model.partial_fit(block)
    monkeypatch.setattr(reference, "RTOL", RTOL_FLOAT32)
    reference.assert_same_state(model, ref)
    assert model._mask.sum() >= 2


def test_matches_batch_sfa_and_the_float64_path(mixture):
    """The float64 test's thresholds (test_incsfa.test_matches_batch_sfa), and the float64 path's features."""
    ref = batch_sfa(mixture, 3)
    fast, exact = IncSFA(3, 6, random_state=0, dtype="float32"), IncSFA(3, 6, random_state=0)
    for model in (fast, exact):
        test_incsfa.train(model, mixture, passes=60)
    y, yb, y64 = fast.transform(mixture), ref.transform(mixture), exact.transform(mixture)
    assert y.dtype == np.float64
    assert test_incsfa.abs_corr(y[:, 0], yb[:, 0]) >= 0.98
    assert min(test_incsfa.abs_corr(y[:, j], yb[:, j]) for j in range(3)) >= 0.95
    np.testing.assert_allclose(fast.delta(mixture), ref.delta, rtol=0.1)
    assert fast.n_active_ == exact.n_active_ == 4
    assert min(test_incsfa.abs_corr(y[:, j], y64[:, j]) for j in range(3)) >= 1 - 1e-6
    # a feature's sign is arbitrary; with the default (slower) CIMCA rates the two paths' slowest
    # features take opposite signs and their projections agree to 1.1e-3 of the largest entry
    sign = np.sign(np.sum(fast.projection_ * exact.projection_, axis=0))
    np.testing.assert_allclose(fast.projection_ * sign, exact.projection_, atol=2e-3 * np.abs(exact.projection_).max())


def test_mdp_toolkit_comparison():
    """The toy of test_incsfa.test_peer_quality_on_mdp_toolkits_incsfa_test, with the same thresholds."""
    X = test_incsfa.wiskott_toy()
    model = IncSFA(4, 5, amnesic=AmnesicSchedule(20, 200, 3, 2000), mca_rate=0.05, mca_rates="decreasing",
                   random_state=0, dtype="float32")
    for i in range(30):
        model.partial_fit(X, continues=i > 0)
    y, yb = model.transform(X), batch_sfa(X, 4).transform(X)
    assert min(test_incsfa.abs_corr(y[:, j], yb[:, j]) for j in range(4)) >= 0.99


def test_icub_size_frames_follow_the_float64_path():
    """7500-pixel frames of rank 12 (three slow and nine fast sources), K = 15, J = 2, the
    iCub experiment's rates; after 3000 frames the two paths' eigenvalues and slowest
    feature agree."""
    rng = np.random.default_rng(2)
    t = np.arange(3000)[:, None]
    cycles = np.array([1, 2, 3, 40, 47, 53, 61, 67, 71, 79, 83, 89])
    sources = np.sin(2 * np.pi * t * cycles / 3000 + rng.uniform(0, 6, cycles.size))
    X = 0.5 + sources @ rng.standard_normal((cycles.size, 7500)) / 20
    models = [IncSFA(2, 15, amnesic=0.4, mean_rate="amnesic", derivative="current", var_fraction=0.98,
                     mca_rate=0.01, mca_rates="equal", gamma=4.0, random_state=3, dtype=dtype) for dtype in ("float32", "float64")]
    for model in models:
        for start in range(0, len(X), 100):
            model.partial_fit(X[start : start + 100])
    fast, exact = models
    assert fast.n_active_ == exact.n_active_
    np.testing.assert_allclose(fast.eigenvalues_[:12], exact.eigenvalues_[:12], rtol=1e-3)
    y, y64 = fast.transform(X), exact.transform(X)
    assert test_incsfa.abs_corr(y[:, 0], y64[:, 0]) >= 0.999


def test_dtype_parameter():
    assert IncSFA().dtype == "float64"
    X = test_incsfa.sinusoids((3, 11, 29))[:200]
    with pytest.raises(ValueError, match="key 'dtype'"):
        IncSFA(dtype="float16").fit(X)
    model = IncSFA(random_state=0, dtype="float32").partial_fit(X)
    assert model._dirs.dtype == np.float32
    model.set_params(dtype="float64")
    with pytest.raises(ValueError, match="dtype cannot change"):
        model.partial_fit(X)
    assert model.fit(X)._dirs.dtype == np.float64  # fit starts afresh


def test_ec_passes_dtype_on():
    assert ECParams().dtype == "float64"
    assert ECParams(dtype="float32").dtype == "float32"
    with pytest.raises(ConfigError, match="dtype"):
        ECParams(dtype="half")
