"""Hypothesis run 17's code (neurocur.fit.ten2021_models, ten2021_checks, ten2021_study): the vectorised likelihood
against the circuit's replay, the simulator against the circuit, the raw/rescaled coefficients, recovery on
simulated sessions, and the statistics against hand-made answers; the command on simulated files in the posted
columns (never the real data)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.analysis.stats.choice_shares import share_array
from neurocur.experiments import load_experiment
from neurocur.fit.replay import Replay
from neurocur.fit.ten2021 import COLUMNS
from neurocur.fit.ten2021_checks import (
    choice_statistics,
    free_shares,
    learning_curves,
    parameter_recovery,
    recovery_figure,
    recovery_summary,
    true_coefficients,
)
from neurocur.fit.ten2021_models import (
    MODEL_SETS,
    MODELS,
    coefficients,
    model_bounds,
    session_features,
    simulate_sessions,
)
from neurocur.fit.ten2021_study import AIC_CONTRASTS, lp_verdict, main, mastered, paper_comparison
from neurocur.fit.trials import trials_from_table

OPTIONS = ["1D", "I1D", "2D", "R"]
P_CORRECT = (0.90, 0.82, 0.66, 0.50)
RAW = {"PFC.rescale": False, "PFC.unscored": 0}
#: raw coefficients of pc, lp, plays, repeat
COEFS = np.array([[-3.0, 4.0, -0.02, 0.7], [2.0, -1.0, 0.01, -0.5]])


@pytest.fixture(scope="module")
def experiment():
    return load_experiment("ten2021")


@pytest.fixture(scope="module")
def simulated():
    return simulate_sessions(np.random.default_rng(3), COEFS, P_CORRECT, n_free=120)


def trials_of(choices, outcomes):
    table = pd.DataFrame({"subject": "s", "trial": np.arange(len(choices)), "choice": choices, "outcome": outcomes})
    return trials_from_table(table, OPTIONS)[0]


def test_the_session_likelihood_equals_the_circuit_replay(experiment, simulated):
    choices, outcomes, _ = simulated
    session = session_features(choices[0], outcomes[0])
    assert session.n_obs == 119  # 120 free choices, the first not scored
    trials = trials_of(choices[0], outcomes[0])
    rng = np.random.default_rng(0)
    assert set(experiment.conditions) == {m for names, _ in MODEL_SETS.values() for m in names} | {"random"}
    for name, bounds in model_bounds(tuple(experiment.conditions)).items():  # every condition, runs 17, 19 and 20
        condition = experiment.conditions[name]
        replay = Replay(condition.circuit, condition.make_world(), None, trials, fitted=list(bounds))
        assert replay.n_obs == session.n_obs
        theta = {key: float(rng.uniform(-8, 8)) for key in bounds}
        expected = replay.loglik(theta) if theta else replay.logp.sum()
        got = session.subject(list(bounds)).loglik(theta) if theta else session.subject([]).evaluate([[]])[0]
        assert abs(got - expected) < 1e-9, name


def test_simulated_sessions_replay_through_the_circuit(experiment, simulated):
    """The simulator's choices have the log-probabilities the circuit gives them on raw signals (every free choice
    scored), and the forced phase is four blocks of 15 in a drawn order."""
    choices, outcomes, logp = simulated
    condition = experiment.conditions["pc_lp_time"]
    for s in range(len(COEFS)):
        theta = {"PFC.pc": COEFS[s, 0], "PFC.lp": COEFS[s, 1], "PFC.plays": COEFS[s, 2], "LC.kappa": COEFS[s, 3]}
        circuit = condition.circuit.with_params({**RAW, **theta}, source="test")
        replay = Replay(circuit, condition.make_world(), None, trials_of(choices[s], outcomes[s]), fitted=["LC.kappa"])
        np.testing.assert_allclose(replay.logp, logp[s], rtol=0, atol=1e-9)
        blocks = choices[s, :60].reshape(4, 15)
        assert (blocks == blocks[:, :1]).all() and sorted(blocks[:, 0]) == [0, 1, 2, 3]
        assert (logp[s, :60] == 0).all() and (logp[s, 60:] < 0).all()


def test_raw_coefficients_times_the_span_make_the_same_choices(simulated):
    """The rescaling is affine: the rescaled session scores the simulator's choices (from the second free one) with
    the log-probabilities it drew them with, at raw coefficient x span; at the raw coefficients it does not."""
    choices, outcomes, logp = simulated
    sessions = [session_features(c, o) for c, o in zip(choices, outcomes)]
    truth = true_coefficients(COEFS, sessions)
    for s, session in enumerate(sessions):
        np.testing.assert_allclose(session.logp(truth[s])[0], logp[s, 61:], rtol=0, atol=1e-9)
        assert np.abs(session.logp(COEFS[s])[0] - logp[s, 61:]).max() > 0.01
    assert truth[0, 2] == pytest.approx(COEFS[0, 2] * sessions[0].span[2])


def test_the_learning_curve_drives_the_outcomes():
    """A curve of 1 for the first 20 plays of every activity and 0 after: exactly the first 20 plays are correct."""
    curve = np.zeros((4, 300))
    curve[:, :20] = 1.0
    choices, outcomes, _ = simulate_sessions(np.random.default_rng(1), np.zeros((3, 4)), curve, n_free=40)
    for c, o in zip(choices, outcomes):
        for k in range(4):
            seen = o[c == k]
            assert (seen[:20] == 1).all() and (seen[20:] == 0).all()


def test_parameter_recovery_on_simulated_sessions():
    """Sessions simulated at known fitted-scale coefficients of `pc` are refitted close to them."""
    rng = np.random.default_rng(11)
    n = 16
    truth = rng.uniform(-12, 12, n)
    base = [session_features(c, o, name=f"s{i}") for i, (c, o, _) in
            enumerate(zip(*simulate_sessions(rng, np.zeros((n, 4)), P_CORRECT)))]
    maps = pd.DataFrame({"subject": [s.name for s in base], "param": "PFC.pc", "estimate": truth})
    table = parameter_recovery(base, maps, "pc", seed=5, starts=1, n_samples=50, max_iter=20)
    assert list(table["subject"]) == [s.name for s in base]
    raw = truth / np.array([s.span[0] for s in base])
    assert np.all(np.abs(table["true"] / raw - 1) < 0.6)  # raw x the simulated session's span, near the participant's
    summary = recovery_summary(table).iloc[0]
    assert summary["r_ml"] > 0.9 and summary["r_hierarchical"] > 0.9, summary
    assert summary["rmse_ml"] < 0.35 * table["true"].std(), summary
    hierarchical_only = parameter_recovery(base, maps, "pc", seed=5, starts=1, n_samples=50, max_iter=20, ml=False)
    assert hierarchical_only["ml"].isna().all()  # no per-participant fits: the column is empty, not an error
    np.testing.assert_array_equal(hierarchical_only["hierarchical"], table["hierarchical"])
    assert "r_ml" not in recovery_summary(hierarchical_only).columns


def test_mastered_counts_13_of_the_last_15_of_a_learnable_activity():
    forced = np.repeat(np.arange(4), 15)

    def session(k, correct_of_15):
        outcomes = np.zeros(60 + 20)
        choices = np.r_[forced, np.full(20, k)]
        outcomes[60 + 20 - 15:60 + 20 - 15 + correct_of_15] = 1.0
        return choices, outcomes
    assert mastered(*session(0, 13)) and mastered(*session(2, 14))
    assert not mastered(*session(1, 12))
    assert not mastered(*session(3, 15))  # R is not learnable
    choices, outcomes = session(0, 0)
    outcomes[:13] = 1.0  # 13 of 15 in the forced block: mastered at the end of the forced phase
    assert mastered(choices, outcomes)


def test_learning_curves_by_hand():
    a = ("a", np.array([0, 0, 1, 0]), np.array([1.0, 0.0, 1.0, 1.0]))
    b = ("b", np.array([0, 1, 1, 1]), np.array([0.0, 0.0, 1.0, 1.0]))
    curves = learning_curves([a, b], n_activities=2, minimum=2)
    # activity 0: plays 1 (a 1, b 0), 2 (a 0 only), 3 (a 1 only) -> 0.5, then carried
    np.testing.assert_allclose(curves[0], [0.5, 0.5, 0.5, 0.5])
    # activity 1: play 1 (a 1, b 0) -> 0.5; plays 2, 3 (b only) carried
    np.testing.assert_allclose(curves[1], [0.5, 0.5, 0.5, 0.5])
    np.testing.assert_allclose(learning_curves([a, b], n_activities=2, minimum=1)[0], [0.5, 0.0, 1.0, 1.0])


def test_shares_and_statistics_equal_the_descriptive_study():
    rng = np.random.default_rng(2)
    choices = rng.integers(0, 4, (6, 250))
    table = pd.DataFrame({"subject": np.repeat(np.arange(6), 250), "trial": np.tile(np.arange(250), 6),
                          "choice": np.array(OPTIONS)[choices.ravel()]})
    expected, _ = share_array(table, OPTIONS)
    np.testing.assert_allclose(free_shares(choices), expected, atol=1e-12)
    shares = np.zeros((2, 10, 4))
    shares[:, :, 3] = 1.0
    for k, b in enumerate((1, 4, 7)):  # subject 0 peaks 1D < I1D < 2D; subject 1 the reverse
        shares[0, b, :] = np.eye(4)[k]
        shares[1, 9 - b, :] = np.eye(4)[k]
    stats = choice_statistics(shares)
    assert stats["ordered_peaks"] == 1.0
    assert stats["share_R"] == pytest.approx(0.7)
    assert stats["change_R"] == pytest.approx(0.0)


def test_lp_verdict_by_hand():
    hierarchical = pd.DataFrame({"model": list(MODELS), "ibic": [900.0, 800, 700, 650, 600, 640]})
    pxp = pd.DataFrame({"model": list(MODELS), "pxp": [0.0, 0.0, 0.04, 0.01, 0.9, 0.05]})
    v = lp_verdict(hierarchical, pxp)
    assert v["best_ibic"] == "pc_lp" and v["lp_pxp"] == pytest.approx(0.96) and v["verdict"] == "supported"
    pxp.loc[2, "pxp"], pxp.loc[4, "pxp"] = 0.2, 0.74
    assert lp_verdict(hierarchical, pxp)["verdict"] == "partly supported"
    hierarchical.loc[2, "ibic"] = 500.0
    assert lp_verdict(hierarchical, pxp)["verdict"] == "not supported"
    names, lp_models = MODEL_SETS["persev"]  # run 19's set: perseveration itself is not an LP model
    hierarchical = pd.DataFrame({"model": list(names), "ibic": [600.0, 590, 620, 580, 585]})
    pxp = pd.DataFrame({"model": list(names), "pxp": [0.03, 0.01, 0.0, 0.9, 0.06]})
    v = lp_verdict(hierarchical, pxp, lp_models)
    assert v["best_ibic"] == "persev_pc_lp" and v["lp_pxp"] == pytest.approx(0.96) and v["verdict"] == "supported"
    hierarchical.loc[0, "ibic"] = 570.0
    assert lp_verdict(hierarchical, pxp, lp_models)["verdict"] == "partly supported"
    assert lp_verdict(hierarchical, pxp)["lp_pxp"] == 0.0  # run 17's LP models are not in this set


def test_the_aic_contrast_by_hand():
    """The paper's trio (PC + LP against the better of PC and LP) and run 20's pair (one simpler model)."""
    aic = {"s1": (100.0, 104, 99), "s2": (100.0, 95, 96), "s3": (90.0, 99, 87.5)}
    ml = pd.DataFrame([{"subject": s, "model": m, "aic": a} for s, row in aic.items()
                       for m, a in zip(("pc", "lp", "pc_lp"), row)])
    out = paper_comparison(ml)
    assert out["pc_lp_better"] == 2 and out["pc_lp_better_by_2"] == 1 and out["participants"] == 3
    assert out["mean_aic_lp"] == pytest.approx(298 / 3)
    pair = paper_comparison(ml[ml["model"] != "pc"].replace({"lp": "persev_pc_time", "pc_lp": "persev_pc_lp_time"}),
                            AIC_CONTRASTS["time"])
    assert pair["persev_pc_lp_time_better"] == 2 and pair["persev_pc_lp_time_better_by_2"] == 2  # 5, -1, 11.5
    assert set(pair) == {"mean_aic_persev_pc_time", "mean_aic_persev_pc_lp_time", "persev_pc_lp_time_better",
                         "persev_pc_lp_time_better_by_2", "participants"}


def posted_rows(sid, choices, outcomes, rng):
    """A simulated session in the posted columns (family = category, answers 1 or 2 at random)."""
    stage = np.r_[np.zeros(60, int), np.ones(len(choices) - 60, int)]
    return pd.DataFrame({"sid": sid, "trial": np.arange(1, len(choices) + 1), "condition": 0, "stage": stage,
                         "blockTrial": 0, "family": choices + 1, "D1": 1, "D2": 2, "category": choices + 1,
                         "choice": rng.integers(1, 3, len(choices)), "correct": outcomes.astype(int), "switch": 0,
                         "rt": 1000})[list(COLUMNS)]


def test_the_command_on_simulated_files(tmp_path):
    rng = np.random.default_rng(9)
    paths = {}
    for group in ("free", "strat"):
        coefs = np.c_[rng.uniform(-5, 0, 2), rng.uniform(0, 8, 2), np.zeros(2), np.zeros(2)]
        choices, outcomes, _ = simulate_sessions(rng, coefs, P_CORRECT)
        paths[group] = tmp_path / f"main_{group}.csv"
        pd.concat([posted_rows(i, c, o, rng) for i, (c, o) in enumerate(zip(choices, outcomes))]).to_csv(
            paths[group], index=False)
    fast = ["--evidence-samples", "20", "--em-iterations", "3", "--starts", "1"]
    files = [str(paths["free"]), str(paths["strat"])]
    assert main(["compare", *files, "--out", str(tmp_path / "c"), *fast]) == 0
    hierarchical = pd.read_csv(tmp_path / "c" / "hierarchical.csv")
    verdict = pd.read_csv(tmp_path / "c" / "verdict.csv")
    assert list(hierarchical["model"]) == list(MODELS) * 2
    assert (hierarchical["n_obs"] == 249 * verdict.set_index("group").loc[hierarchical["group"], "participants"].to_numpy()).all()
    ml = pd.read_csv(tmp_path / "c" / "ml.csv")
    assert (ml["n_obs"] == 249).all()
    assert ml["bic"].to_numpy() == pytest.approx(ml["n_params"] * np.log(249) - 2 * ml["loglik"])
    assert (tmp_path / "c" / "comparison.png").exists()
    assert main(["ppc", *files, "--fits", str(tmp_path / "c"), "--out", str(tmp_path / "p"), "--replicates", "3"]) == 0
    ppc = pd.read_csv(tmp_path / "p" / "ppc.csv")
    assert set(ppc["statistic"]) == {"share_1D", "share_I1D", "share_2D", "share_R", "ordered_peaks", "change_R"}
    assert (ppc["low"] <= ppc["high"]).all() and ppc["p"].between(0, 1).all()
    with pytest.raises(SystemExit):  # --fits is needed
        main(["ppc", *files, "--out", str(tmp_path / "q")])
    assert main(["compare", *files, "--models", "persev", "--out", str(tmp_path / "c19"), *fast]) == 0
    hierarchical = pd.read_csv(tmp_path / "c19" / "hierarchical.csv")
    assert list(hierarchical["model"]) == list(MODEL_SETS["persev"][0]) * 2
    assert set(hierarchical.loc[hierarchical["model"] == "persev_pc_lp", "n_params"]) == {6}  # 3 means, 3 sds
    verdict = pd.read_csv(tmp_path / "c19" / "verdict.csv")
    ml = pd.read_csv(tmp_path / "c19" / "ml.csv").pivot(index="subject", columns="model", values="aic")
    assert verdict["mean_aic_persev_pc_lp"].mean() == pytest.approx(ml["persev_pc_lp"].mean())  # both groups' means
    # run 19's recoveries and check read its fits and its five models: W the free group's winner among them
    assert main(["recover", *files, "--models", "persev", "--fits", str(tmp_path / "c19"), "--out", str(tmp_path / "r19"),
                 "--participants", "3", *fast]) == 0
    best = hierarchical.loc[hierarchical["group"] == "free"].set_index("model")["ibic"].idxmin()
    recovered = pd.read_csv(tmp_path / "r19" / "parameter_recovery.csv")
    assert set(recovered["model"]) == {best} and set(recovered["param"]) == set(model_bounds([best])[best])
    confusion = pd.read_csv(tmp_path / "r19" / "confusion.csv").set_index("generating")
    assert list(confusion.index) == list(confusion.columns) == list(MODEL_SETS["persev"][0])
    np.testing.assert_allclose(confusion.sum(axis=1), 1.0)
    assert main(["ppc", *files, "--models", "persev", "--fits", str(tmp_path / "c19"), "--out", str(tmp_path / "p19"),
                 "--replicates", "3"]) == 0
    ppc = pd.read_csv(tmp_path / "p19" / "ppc.csv")
    assert set(ppc["model"]) <= set(MODEL_SETS["persev"][0]) - {"random"}


def test_coefficients_read_the_named_subjects_only():
    maps = pd.DataFrame({"subject": ["a", "b", "c", "b"], "param": ["PFC.pc", "PFC.lp", "LC.kappa", "PFC.plays"],
                         "estimate": [1.0, 2.0, 3.0, 4.0]})
    np.testing.assert_array_equal(coefficients(maps, ["b", "a"]), [[0, 2, 4, 0], [1, 0, 0, 0]])


def test_the_recovery_figure_is_a_grid_of_parameters_by_groups():
    """A panel per (parameter, group): rows the parameters, columns the groups, each titled with its r (run 19's
    winner has up to four parameters, which a single row would stretch across the page); one parameter keeps entry
    17's row of two panels."""
    rng = np.random.default_rng(4)
    rows = []
    for group in ("free", "strat"):
        for param, slope in (("LC.kappa", 1.0), ("PFC.pc", 0.5), ("PFC.lp", -1.0)):
            true = rng.normal(size=12)
            rows.append(pd.DataFrame({"group": group, "param": param, "subject": np.arange(12), "true": true,
                                      "hierarchical": slope * true + 0.1 * rng.normal(size=12)}))
    table = pd.concat(rows, ignore_index=True)
    fig = recovery_figure(table)
    grid = np.array([[ax.get_subplotspec().rowspan.start, ax.get_subplotspec().colspan.start] for ax in fig.axes])
    assert grid.max(axis=0).tolist() == [2, 1]  # 3 rows (parameters) x 2 columns (groups)
    for ax, (row, column) in zip(fig.axes, grid):
        group, param = ("free", "strat")[column], ("LC.kappa", "PFC.pc", "PFC.lp")[row]
        part = table[(table["group"] == group) & (table["param"] == param)]
        r = np.corrcoef(part["true"], part["hierarchical"])[0, 1]
        assert ax.get_title() == f"{group} {param}: r = {r:.2f}"
    one = recovery_figure(table[table["param"] == "LC.kappa"])
    assert len(one.axes) == 2 and tuple(one.get_size_inches()) == (6.8, 3.4)
