"""Simulation-based inference: the summaries, the training experiment, and NPE on a problem with a known answer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.fit.data import Behaviour
from neurocur.fit.sbi import held_out_draws, n_values, posterior_table, summaries, training_experiment


def test_summaries_of_a_hand_made_sequence():
    b = Behaviour("s", np.array([0, 0, 1, 1, 1, 0, 2, 2]), np.zeros(8, np.int64), {}, "<test>")
    x = summaries(b, 3)
    # 3 switches in 7 decisions; halves of 3 and 4 decisions; 4 stays in 8 episodes; shares 3/8, 3/8, 2/8
    share = np.array([3, 3, 2]) / 8
    head = [3 / 7, 1 / 3, 2 / 4, np.log(2.0), -(share * np.log2(share)).sum(), *share]
    # quarters [0 0] [1 1] [1 0] [2 2]; stays 0:(2, 1) 1:(3) 2:(2)
    quarters = [1, 0, 0, 0, 1, 0, 0.5, 0.5, 0, 0, 0, 1]
    np.testing.assert_allclose(x, [*head, *quarters, 1.5, 3, 2])


def test_summaries_of_a_context_never_visited_and_a_short_sequence():
    x = summaries(Behaviour("s", np.array([1, 1]), np.zeros(2, np.int64), {}, "<test>"), 3)
    # one stay of 2; quarters [1] [1] [] []: an empty quarter has no shares; context 0 and 2: stay 0
    np.testing.assert_allclose(x, [0, 0, 0, np.log(2.0), 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, *[0] * 6, 0, 2, 0])


def test_the_draws_make_the_simulations_and_the_held_out_seeds_are_new():
    assert n_values({"a": (0, 1)}, 200, 5) == 40 and n_values({"a": (0, 1), "b": (0, 1)}, 50, 2) == 5
    with pytest.raises(ConfigError, match="--simulations.*e.g. 18"):
        n_values({"a": (0, 1), "b": (0, 1)}, 20, 2)
    draws = held_out_draws({"a": (0.1, 0.5)}, 20, seed=7)
    assert draws == held_out_draws({"a": (0.1, 0.5)}, 20, seed=7)
    seeds = [s for s, _ in draws]
    assert len(set(seeds)) == 20 and 7 not in seeds and all(0 <= s < 2**63 for s in seeds)
    assert all(0.1 <= t["a"] <= 0.5 for _, t in draws) and np.std([t["a"] for _, t in draws]) > 0.05


def test_the_training_experiment_sweeps_prior_draws(tmp_path):
    free_choice = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "free_choice.toml"
    path = training_experiment(free_choice, {"HPC.rate": (0.05, 0.5)}, n_values=6, runs=2, steps=50, seed=3, out=tmp_path)
    exp = load_experiment(path)
    points = [c.sweep["HPC.rate"] for c in exp.select(["learning_progress"])]
    assert len(points) == 6 and all(0.05 <= v <= 0.5 for v in points) and exp.runs == 2 and exp.steps == 50
    assert exp.seed == 3 and training_experiment(free_choice, {"HPC.rate": (0.05, 0.5)}, n_values=6, runs=2,
                                                 steps=50, seed=3, out=tmp_path).read_text() == path.read_text()
    (tmp_path / "elsewhere.toml").write_text("x = 1\n")
    path.unlink()
    path.symlink_to(tmp_path / "elsewhere.toml")  # a link planted at the file's name is replaced, not followed
    training_experiment(free_choice, {"HPC.rate": (0.05, 0.5)}, n_values=6, runs=2, steps=50, seed=3, out=tmp_path)
    assert not path.is_symlink() and (tmp_path / "elsewhere.toml").read_text() == "x = 1\n"


def test_npe_recovers_the_mean_of_a_gaussian():
    """x = theta + N(0, 0.05^2): the posterior at x = 0.3 is close to N(0.3, 0.05^2)."""
    pytest.importorskip("sbi")
    import torch

    from neurocur.fit.sbi import train

    torch.set_num_threads(1)
    rng = np.random.default_rng(0)
    theta = rng.uniform(0, 1, (300, 1))
    x = theta + 0.05 * rng.standard_normal(theta.shape)
    sample = train(theta, x, {"a": (0.0, 1.0)}, max_epochs=30)
    s = sample([0.3], 2000)
    assert abs(np.median(s) - 0.3) < 0.03 and 0.02 < s.std() < 0.1
    table = posterior_table(s, {"a": (0.0, 1.0)}, "obs")
    assert table.loc[0, "ci_low"] < 0.3 < table.loc[0, "ci_high"]
