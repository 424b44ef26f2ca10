"""The IncSFA author's own test, passed by ``IncSFA()`` with its default parameters.

Kompella's reference implementation (``varunrajk/IncSFA`` on GitHub, ``test_incsfa.py``)
trains IncSFA on Wiskott's toy signal, x1 = sin t + cos²(11 t), x2 = cos 11 t, t in [0, 4π]
(500 samples), expanded to its degree-2 monomials (x1, x2, x1², x1 x2, x2²), with whitening
to 5 dimensions, 5 outputs and η = 0.05, for 20 passes sample by sample (the derivative runs
on across passes), and requires the direction cosine of every learned feature's direction in
input space with batch SFA's to be within 1e-2 of 1.

Run as that code's own user would, the author's code passes with 0.9949 / 0.9999 / 0.9935
for the three hardest directions (2, 3 and 4). With the learners' earlier defaults (a
constant amnesic l = 2, an amnesic mean, the derivative under the current whitening,
``mca_rates="decreasing"``, γ = 4) neurocur's IncSFA reached 0.9854 / 0.9941 / 0.9879 and
failed. The defaults are now the author's code's (``neurocur.learn.incsfa``); of them the
amnesic schedule (20, 200, 3, 2000) is what decides the test.
"""

import numpy as np
import pytest

from neurocur.learn.incsfa import IncSFA
from neurocur.learn.sfa_batch import batch_sfa

PASSES, TOLERANCE = 20, 1e-2
#: the author's code on this test, directions 2-4 (the others are 1.0000)
AUTHOR = np.array([0.9949, 0.9999, 0.9935])
#: the learners' defaults before they became the author's
EARLIER = dict(amnesic=2.0, mean_rate="amnesic", derivative="current", mca_rates="decreasing", gamma=4.0)


def wiskott_toy_degree_2():
    t = np.linspace(0, 4 * np.pi, 500)
    a, b = np.sin(t) + np.cos(11 * t) ** 2, np.cos(11 * t)
    return np.column_stack([a, b, a * a, a * b, b * b])


def direction_cosines(**params):
    """|cos| between each learned direction (a column of ``projection_``) and batch SFA's."""
    X = wiskott_toy_degree_2()
    model = IncSFA(5, 5, mca_rate=0.05, random_state=0, **params)
    for i in range(PASSES):
        model.partial_fit(X, continues=i > 0)
    learned, batch = model.projection_, batch_sfa(X, 5).W
    return np.abs(np.sum(learned * batch, axis=0)) / (np.linalg.norm(learned, axis=0) * np.linalg.norm(batch, axis=0))


def test_defaults_pass_the_authors_test():
    cosines = direction_cosines()
    assert np.allclose(cosines, 1, atol=TOLERANCE), cosines
    np.testing.assert_allclose(cosines[1:4], AUTHOR, atol=1e-3)  # measured 0.9949 / 0.9998 / 0.9929


def test_earlier_defaults_fail_it():
    """The test can fail: the earlier defaults miss it on the same directions."""
    cosines = direction_cosines(**EARLIER)
    assert not np.allclose(cosines, 1, atol=TOLERANCE)
    np.testing.assert_allclose(cosines[1:4], [0.9854, 0.9941, 0.9879], atol=1e-4)


def test_without_the_schedule_the_authors_other_defaults_fail_it():
    """The author's defaults with the constant l = 2 in place of the schedule: direction 4 reaches 0.9705."""
    assert not np.allclose(direction_cosines(amnesic=2.0), 1, atol=TOLERANCE)


@pytest.mark.parametrize("option", ["amnesic", "mean_rate", "derivative", "mca_rates", "gamma"])
def test_only_the_schedule_decides_it(option):
    """Each of the author's defaults but the schedule can be swapped for the earlier one and the
    test still passes; the earlier defaults with the schedule alone pass it too."""
    if option == "amnesic":
        cosines = direction_cosines(**{k: v for k, v in EARLIER.items() if k != "amnesic"})
    else:
        cosines = direction_cosines(**{option: EARLIER[option]})
    assert np.allclose(cosines, 1, atol=TOLERANCE), cosines


def test_reference_options():
    """γ = 1.2 · 0.2/η, the cumulative mean is the plain average, and a first sample with no active
    whitened component leaves no previous z for the successive derivative."""
    X = wiskott_toy_degree_2()
    model = IncSFA(2, 5, mca_rate=0.05, random_state=0).fit(X)
    assert model.gamma_ == pytest.approx(4.8)
    assert IncSFA(mca_rate=0.01).gamma_ == pytest.approx(24.0)
    np.testing.assert_allclose(model.mean_, X.mean(axis=0), rtol=1e-12)
    for derivative, moved in (("successive", False), ("current", True)):
        two = IncSFA(2, 5, derivative=derivative, random_state=0).fit(X[:2])
        initial = IncSFA(2, 5, random_state=0)
        initial._start(5)
        assert (not np.array_equal(two._W, initial._W)) is moved
