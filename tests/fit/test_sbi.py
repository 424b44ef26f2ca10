"""Simulation-based inference: the summaries, the training experiment, and NPE on a problem with a known answer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.fit.data import Behaviour
from neurocur.fit.sbi import draw_experiments, n_draws, posterior_table, prior_draws, summaries


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


def test_the_draws_make_the_simulations_and_every_draw_has_its_own_seed():
    assert n_draws(200, 5) == 40
    for simulations, runs in ((20, 3), (5, 5), (1, 1)):
        with pytest.raises(ConfigError, match="--simulations: expected a multiple of --runs"):
            n_draws(simulations, runs)
    prior = {"a": (0.1, 0.5), "b": (1.0, 2.0)}
    draws = prior_draws(prior, 20, np.random.SeedSequence([7, 0]))
    assert draws == prior_draws(prior, 20, np.random.SeedSequence([7, 0]))
    assert draws[:5] == prior_draws(prior, 5, np.random.SeedSequence([7, 0]))  # more draws extend the set
    held_out = prior_draws(prior, 20, np.random.SeedSequence([7, 1]))
    seeds = [s for s, _ in draws + held_out]
    assert len(set(seeds)) == 40 and all(0 <= s < 2**63 for s in seeds)
    a, b = np.array([[t["a"], t["b"]] for _, t in draws]).T
    assert a.min() >= 0.1 and a.max() <= 0.5 and b.min() >= 1 and b.max() <= 2 and abs(np.corrcoef(a, b)[0, 1]) < 0.5


def test_each_draw_is_an_experiment_written_whole(tmp_path):
    free_choice = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "free_choice.toml"
    paths = draw_experiments(free_choice, {"HPC.rate": (0.05, 0.5)}, n=3, runs=2, steps=50, seed=3, out=tmp_path)
    assert [p.name for p in paths] == ["d000.toml", "d001.toml", "d002.toml"] and paths[0].parent.name == "sbi_training"
    exps = [load_experiment(p) for p in paths]
    points = [[c.sweep["HPC.rate"] for c in e.select(["learning_progress"])] for e in exps]
    assert all(len(v) == 1 and 0.05 <= v[0] <= 0.5 for v in points) and len({v[0] for v in points}) == 3
    assert all(e.runs == 2 and e.steps == 50 for e in exps) and len({e.seed for e in exps}) == 3
    text = paths[0].read_text()
    (tmp_path / "elsewhere.toml").write_text("x = 1\n")
    paths[0].unlink()
    paths[0].symlink_to(tmp_path / "elsewhere.toml")  # a link planted at the file's name is replaced, not followed
    draw_experiments(free_choice, {"HPC.rate": (0.05, 0.5)}, n=3, runs=2, steps=50, seed=3, out=tmp_path)
    assert paths[0].read_text() == text and (tmp_path / "elsewhere.toml").read_text() == "x = 1\n"
    (held,) = draw_experiments(free_choice, {"HPC.rate": (0.05, 0.5)}, n=1, runs=1, steps=50, seed=3, out=tmp_path,
                               held_out=True)
    assert held.relative_to(tmp_path).as_posix() == "sbi_test/t00.toml"
    assert load_experiment(held).seed not in {e.seed for e in exps}


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
