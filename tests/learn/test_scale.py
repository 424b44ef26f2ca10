"""Input scale: in the accepted range a scaled input gives the unscaled features; outside it, a
ValueError that names the scale found and the range accepted (never NaN, zeros or no columns)."""

import re

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from neurocur.learn import CCIPCA, MCA, IncSFA
from neurocur.learn._scale import MAX_SCALE, MIN_SCALE, _largest_abs

T = 600
_t = np.arange(T)
#: a slow, a faster and a fast sinusoid mixed into 4 dimensions, with an offset
X = np.stack([np.sin(2 * np.pi * _t / 300), np.sin(2 * np.pi * _t / 23 + 1), 0.5 * np.sin(2 * np.pi * _t / 7 + 2)],
             1) @ np.random.default_rng(0).standard_normal((3, 4)) + 2.0


def slow_features(X):
    model = IncSFA(2, 3, random_state=0).fit(X)
    for _ in range(3):
        model.partial_fit(X)
    return model.transform(X)


def whitened(X):
    return CCIPCA(3, random_state=0).fit(X).transform(X)


def up_to_sign(a, b) -> float:
    """Largest difference between the columns of ``a`` (each with the sign that fits best) and ``b``."""
    return float(np.abs(a * np.sign(np.sum(a * b, axis=0)) - b).max())


def scale_error(X, *, first=True, centred=True) -> str:
    """The message expected for ``X`` out of range: the scale found and the range accepted."""
    biggest = np.abs(X).max()
    if biggest > MAX_SCALE:
        return rf"largest \|value\| is {re.escape(f'{biggest:.3g}')}, which would overflow \(accepted: largest \|value\| <= 1e\+60"
    low, what = (np.ptp(X, axis=0).max(), r"largest feature range \(max - min\)") if centred else (biggest,
                                                                                                   r"largest \|value\|")
    assert first and low < MIN_SCALE
    return rf"its {what} is {re.escape(f'{low:.3g}')}, which would underflow .*>= 1e-60\)"


def in_range(X, centred=True) -> bool:
    low = np.ptp(X, axis=0).max() if centred else np.abs(X).max()
    return np.abs(X).max() <= MAX_SCALE and low >= MIN_SCALE


BASE_Y = slow_features(X)
BASE_Z = whitened(X)
SCALES = st.floats(-200, 200).map(lambda e: 10.0**e)


@settings(max_examples=60, deadline=None)
@given(scale=SCALES)
@example(scale=1e77).via("the issue: NaN eigenvalues")
@example(scale=1e-100).via("the issue: all-zero features")
@example(scale=1e60 / 4).via("just in range")
def test_incsfa_scaled_input(scale):
    Xs = X * scale
    if in_range(Xs):
        assert up_to_sign(slow_features(Xs), BASE_Y) < 1e-4
    else:
        with pytest.raises(ValueError, match=scale_error(Xs)):
            slow_features(Xs)


@settings(max_examples=60, deadline=None)
@given(scale=SCALES)
@example(scale=1e77).via("the issue: NaN eigenvalues")
@example(scale=1e-100).via("the issue: a zero-width output")
def test_ccipca_scaled_input(scale):
    Xs = X * scale
    if in_range(Xs):
        assert up_to_sign(whitened(Xs), BASE_Z) < 1e-4
    else:
        with pytest.raises(ValueError, match=scale_error(Xs)):
            whitened(Xs)


@settings(max_examples=60, deadline=None)
@given(scale=SCALES)
@example(scale=1e77)
@example(scale=1e-100)
def test_mca_scaled_input(scale):
    """CIMCA is not scale-free (its rate is η times the eigenvalues, eq 20), so in range the
    claim is finite unit components and finite projections, not the unscaled result."""
    Zs = (X[:, :3] - 2.0) * scale
    if in_range(Zs, centred=False):
        mca = MCA(2, random_state=0).fit(Zs)
        np.testing.assert_allclose(np.linalg.norm(mca.components_, axis=1), 1.0)
        assert np.isfinite(mca.transform(Zs)).all() and np.isfinite(mca.gamma_) and mca.gamma_ > 0
    else:
        with pytest.raises(ValueError, match=scale_error(Zs, centred=False)):
            MCA(2, random_state=0).fit(Zs)


@pytest.mark.parametrize("cls", [IncSFA, CCIPCA, MCA])
def test_later_blocks_and_transform_are_checked_too(cls):
    """A fitted learner rejects an overflowing block before learning it, and so does transform."""
    model = cls(random_state=0).fit(X)
    state = model.copy()
    huge = X * 1e70
    with pytest.raises(ValueError, match=scale_error(huge, first=False)):
        model.partial_fit(huge)
    with pytest.raises(ValueError, match="would overflow"):
        model.transform(huge)
    np.testing.assert_array_equal(model.transform(X), state.transform(X))
    model.partial_fit(X * 1e-70)  # a quiet block in a running stream is fine: the state keeps the scale
    assert model.n_samples_seen_ == 2 * T


def test_at_the_limits():
    """At the limits of the accepted range the learners still give the unscaled features."""
    top = MAX_SCALE / np.abs(X).max() * (1 - 1e-12)
    bottom = MIN_SCALE / np.ptp(X, axis=0).max() * (1 + 1e-12)
    for scale in (top, bottom):
        assert up_to_sign(slow_features(X * scale), BASE_Y) < 1e-4
        assert up_to_sign(whitened(X * scale), BASE_Z) < 1e-4


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 5000), at=st.floats(0, 1), bad=st.sampled_from([None, np.nan, np.inf, -np.inf]))
def test_largest_abs_is_numpys_max_abs_in_one_pass(n, at, bad):
    """The scale check's one compiled pass: max |x|, NaN when any value is NaN, inf when infinite."""
    x = np.random.default_rng(n).standard_normal(n) * 10.0 ** np.random.default_rng(n + 1).integers(-50, 50)
    if bad is not None:
        x[min(int(at * n), n - 1)] = bad
    expected = np.abs(x).max()
    if np.isnan(expected):
        assert np.isnan(_largest_abs(x))
    else:
        assert _largest_abs(x) == expected
