"""The bandit regions (neurocur.regions.bandit) and the world of options: the choice rule measured against its
closed form, the delta rule by hand, the declared domains, the outcomes paid at the declared rates."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.contexts.options import OptionsParams, OptionsWorld
from neurocur.regions.bandit import DeltaPosNegValues, DeltaValues, OptionChoice, option_log_probabilities


def _bound(region, n=3):
    region.bind(OptionsWorld(OptionsParams(options=tuple("ABC"[:n]), p_reward=(0.5,) * n)))
    region.reset(np.random.default_rng(0))
    return region


def test_the_choice_rule_is_the_lapsed_softmax_with_a_perseveration_bonus():
    q, beta, kappa, lapse = np.array([0.2, 0.5, -0.1]), 2.0, 1.0, 0.3
    z = beta * q + kappa * np.array([1.0, 0.0, 0.0])  # previous choice 0
    expected = (1 - lapse) * np.exp(z) / np.exp(z).sum() + lapse / 3
    np.testing.assert_allclose(np.exp(option_log_probabilities(beta, q, 0, kappa, lapse)), expected, rtol=1e-12)
    # no previous choice: no bonus; lapse 0: the softmax itself
    plain = np.exp(beta * q) / np.exp(beta * q).sum()
    np.testing.assert_allclose(np.exp(option_log_probabilities(beta, q, -1, kappa, 0.0)), plain, rtol=1e-12)
    # far in the tail the log-probability stays finite (no log 0)
    assert np.isfinite(option_log_probabilities(50.0, np.array([0.0, 30.0]), -1, 0.0, 0.0)).all()


def test_the_drawn_choices_follow_the_rule():
    region = _bound(OptionChoice("LC", OptionChoice.Params(beta=2.0, kappa=1.0, lapse=0.3)))
    q = np.array([0.2, 0.5, -0.1])
    n = 20_000
    counts = np.bincount([region.step(q, 0)[1] for _ in range(n)], minlength=3)
    p = np.exp(option_log_probabilities(2.0, q, 0, 1.0, 0.3))
    se = np.sqrt(p * (1 - p) / n)
    assert np.all(np.abs(counts / n - p) < 4 * se), (counts / n, p)
    # engage is repeating the previous choice, disengage another option
    action, choice, _ = region.step(q, 1)
    assert action == (0 if choice == 1 else 1)


def test_the_vectorised_likelihood_equals_the_stepped_one():
    rng = np.random.default_rng(4)
    values = rng.normal(size=(30, 3))
    previous = [None, *rng.integers(3, size=29)]
    decisions = rng.integers(3, size=30)
    params = {"beta": np.array([[0.5], [4.0]]), "kappa": np.array([[-1.0], [2.0]]), "lapse": np.array([[0.0], [0.2]])}
    fast = OptionChoice.log_likelihoods(params, {"values": list(values), "context": previous}, decisions)
    for m in range(2):
        region = _bound(OptionChoice("LC", OptionChoice.Params(**{k: float(v[m, 0]) for k, v in params.items()})))
        stepped = []
        for t in range(30):
            region.step(values[t], previous[t])
            stepped.append(region.log_probability(decisions[t]))
        np.testing.assert_allclose(fast[m], stepped, rtol=0, atol=1e-12)


def test_the_delta_rule_by_hand():
    region = _bound(DeltaValues("PFC", DeltaValues.Params(q0=0.5, alpha=0.25)))
    np.testing.assert_array_equal(region.step(None, None)[0], [0.5, 0.5, 0.5])  # first trial: Q0
    np.testing.assert_allclose(region.step(1, 1.0)[0], [0.5, 0.625, 0.5])
    np.testing.assert_allclose(region.step(1, 0.0)[0], [0.5, 0.625 - 0.25 * 0.625, 0.5])
    assert region.record() == (-0.625,)
    posneg = _bound(DeltaPosNegValues("PFC", DeltaPosNegValues.Params(alpha_pos=0.5, alpha_neg=0.1)))
    np.testing.assert_allclose(posneg.step(0, 1.0)[0], [0.5, 0.0, 0.0])  # positive error: alpha_pos
    np.testing.assert_allclose(posneg.step(0, 0.0)[0], [0.45, 0.0, 0.0])  # negative error: alpha_neg


@pytest.mark.parametrize("cls,key,value", [
    (DeltaValues, "alpha", 1.2), (DeltaPosNegValues, "alpha_neg", -0.1), (OptionChoice, "beta", 60.0),
    (OptionChoice, "kappa", 6.0), (OptionChoice, "lapse", 1.0), (DeltaValues, "q0", 11.0)])
def test_every_parameter_has_a_declared_domain(cls, key, value):
    with pytest.raises(ConfigError, match=key):
        cls.Params(**{key: value})


def test_the_world_pays_at_the_declared_rates_and_replays_recorded_trials():
    world = OptionsWorld(OptionsParams(options=("A", "B"), p_reward=(0.8, 0.1)))
    world.np_random = np.random.default_rng(1)
    world.begin()
    n = 10_000
    paid = np.array([[world.step(o)[0].reward for o in (0, 1)] for _ in range(n)])
    assert np.all(np.abs(paid.mean(axis=0) - (0.8, 0.1)) < 4 * np.sqrt(0.16 / n))
    recorded = world.recorded([1, 0], [3.0, -1.0])
    recorded.begin()
    assert [recorded.step(1)[1], recorded.step(0)[1]] == [3.0, -1.0]
    recorded.begin()
    with pytest.raises(ValueError, match="expected option 1 at trial 0"):
        recorded.step(0)
    with pytest.raises(ConfigError, match="p_reward"):
        OptionsParams(options=("A", "B", "C"), p_reward=(0.5, 0.5))


def test_the_bandit_circuit_learns_to_prefer_the_better_option():
    circuit = Circuit.from_toml("bandit", {"LC.beta": 5.0, "PFC.alpha": 0.2})
    episodes = circuit.build(OptionsWorld(OptionsParams(p_reward=(0.9, 0.1))), seed=5).run(400).episodes()
    assert (episodes["next_context"] == episodes["context"]).all()  # the task visits this trial's choice
    assert (episodes["context"].to_numpy()[200:] == 0).mean() > 0.8
