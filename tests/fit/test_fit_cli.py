"""neurocur fit and neurocur recover: files written, estimates near the truth, bad data exits 2 in one line."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.experiments import load_experiment
from neurocur.fit.recovery import simulate


def test_fit_a_table_by_signal_replay(tmp_path):
    condition = load_experiment("free_choice").conditions["learning_progress"]
    tables = []
    for i, gain in enumerate((10.0, 30.0)):
        behaviour, episodes = simulate(condition, {"LC.gain": gain}, 100 + i, 200, signal=("HPC", "error"))
        tables.append(pd.DataFrame({"dataset": f"s{i}", "episode": episodes["episode"],
                                    "context": [("easy", "medium", "hard", "impossible")[c] for c in episodes["context"]],
                                    "decision": episodes["next_context"], "error": episodes["error"]}))
    data = tmp_path / "choices.csv"
    pd.concat(tables).to_csv(data, index=False)
    out = tmp_path / "fit"
    status = main(["fit", str(data), "--experiment", "free_choice", "--condition", "learning_progress",
                   "--fit", "LC.gain", "--bounds", "LC.gain=0:100", "--signal", "HPC=error", "--out", str(out),
                   "--starts", "2"])
    assert status == 0
    fit = pd.read_csv(out / "fit.csv")
    assert list(fit.columns) == ["dataset", "param", "estimate", "ci_low", "ci_high"]
    assert list(fit["dataset"]) == ["s0", "s1", "pooled"]
    for dataset, gain in (("s0", 10.0), ("s1", 30.0)):
        row = fit[fit["dataset"] == dataset].iloc[0]
        assert row["ci_low"] < gain < row["ci_high"], (dataset, row)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_params"] == 2 and summary["n_obs"] == 400
    assert abs(summary["aic"] - (4 - 2 * summary["loglik"])) < 1e-9


def test_bad_data_exits_2_with_one_line(tmp_path, capsys):
    data = tmp_path / "bad.csv"
    pd.DataFrame({"dataset": "s", "episode": [0, 1], "context": ["easy", "nowhere"], "decision": [1, 1]}).to_csv(data)
    status = main(["fit", str(data), "--experiment", "free_choice", "--fit", "LC.gain", "--bounds", "LC.gain=0:9"])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err and str(data) in err and "'context'" in err and "'nowhere'" in err


def test_recover_writes_its_tables_and_figures(tmp_path):
    out = tmp_path / "rec"
    status = main(["recover", "free_choice", "--condition", "learning_progress", "--fit", "LC.gain",
                   "--bounds", "LC.gain=2:40", "--signal", "HPC=error", "--datasets", "4", "--episodes", "80",
                   "--starts", "1", "--models", "learning_progress", "random", "--out", str(out)])
    assert status == 0
    for name in ("recovery.csv", "recovery_summary.csv", "recovery.png", "model_recovery.csv", "confusion_bic.csv",
                 "confusion.png"):
        assert (out / name).is_file(), name
    assert len(pd.read_csv(out / "recovery.csv")) == 4


def test_a_results_folders_runs_replay_exactly_with_their_own_seeds(tmp_path):
    """A results folder is a data set: each run is replayed with its seed, and its log-likelihood at the
    run's own parameters is the sum of the log-probabilities of the choices it made."""
    import numpy as np

    from neurocur.experiments import load_experiment, run_experiment
    from neurocur.fit.study import condition_of, load_data, make_replays
    from neurocur.results import ResultsStore

    out = tmp_path / "results"
    experiment, condition = condition_of(load_experiment("free_choice", runs=2, steps=70), "learning_progress")
    run_experiment(experiment, out, jobs=1, conditions=["learning_progress"], progress=False)
    episodes, _ = ResultsStore(out).load()
    data = load_data(out, condition)
    assert [b.name for b in data] == ["learning_progress/0", "learning_progress/1"]
    for run, replay in enumerate(make_replays(experiment, condition, data, ["LC.gain"])):
        chosen = episodes.loc[episodes["run"] == run, "p_chosen"]
        assert len(chosen) == replay.n_obs
        assert abs(replay.loglik({"LC.gain": 20.0}) - np.log(chosen).sum()) < 1e-9


def test_impossible_decisions_and_unknown_parameters_are_named():
    """A data set no theta in the bounds can explain (log-likelihood -inf everywhere) is a one-line error
    naming the data set and the episode (from the replay); an unknown parameter names the region's."""
    import numpy as np

    from neurocur.config import ConfigError
    from neurocur.fit.study import condition_of, default_bounds, fit_data

    class Impossible:
        n_obs = 3
        behaviour = type("B", (), {"name": "s1", "source": "data.csv"})()

        def loglik(self, theta, mask=None):
            return np.full(len(theta), -np.inf) if isinstance(theta, list) else -np.inf

        def episode_logp(self, theta):
            return np.array([0.0, -np.inf, 0.0])

        def first_impossible(self, logp):
            return f"data set 's1', episode {int(np.flatnonzero(np.isneginf(logp))[0])}: probability 0"

    with pytest.raises(ConfigError, match=r"data.csv: key 'decision'.*-inf: data set 's1', episode 1"):
        fit_data([Impossible()], {"LC.epsilon0": (0.0, 0.1)}, ci=None)
    _, condition = condition_of("free_choice", "learning_progress")
    with pytest.raises(ConfigError, match="no parameter 'gian' of region 'LC'"):
        default_bounds(condition, ["LC.gian"], {})


def test_fit_and_recover_with_bootstrap_intervals(tmp_path, capsys):
    """--ci bootstrap: each data set's interval is the percentile interval of its replicates in bootstrap.csv,
    the pooled fit has none; a bad --bootstrap is one line and exit 2."""
    import numpy as np

    condition = load_experiment("free_choice").conditions["learning_progress"]
    tables = []
    for i in range(2):
        behaviour, episodes = simulate(condition, {"LC.gain": 20.0}, 200 + i, 60, signal=("HPC", "error"))
        tables.append(pd.DataFrame({"dataset": f"s{i}", "episode": episodes["episode"], "context": episodes["context"],
                                    "decision": episodes["next_context"], "error": episodes["error"]}))
    data = tmp_path / "choices.csv"
    pd.concat(tables).to_csv(data, index=False)
    args = ["fit", str(data), "--experiment", "free_choice", "--condition", "learning_progress", "--fit", "LC.gain",
            "--bounds", "LC.gain=1:60", "--signal", "HPC=error", "--starts", "1", "--ci", "bootstrap"]
    out = tmp_path / "fit"
    assert main(args + ["--bootstrap", "6", "--out", str(out)]) == 0
    fit, boot = pd.read_csv(out / "fit.csv"), pd.read_csv(out / "bootstrap.csv")
    assert list(boot.columns) == ["dataset", "replicate", "param", "estimate"] and len(boot) == 12
    assert list(fit["dataset"]) == ["s0", "s1", "pooled"] and fit.iloc[2][["ci_low", "ci_high"]].isna().all()
    for _, row in fit.iloc[:2].iterrows():
        values = boot.loc[boot["dataset"] == row["dataset"], "estimate"]
        np.testing.assert_allclose([row["ci_low"], row["ci_high"]], np.quantile(values, [0.025, 0.975]))
    assert json.loads((out / "summary.json").read_text())["intervals"] == "bootstrap (6 replicates)"
    capsys.readouterr()
    with pytest.raises(SystemExit) as info:
        main(args + ["--bootstrap", "0", "--out", str(tmp_path / "bad")])
    err = capsys.readouterr().err
    assert info.value.code == 2 and "argument --bootstrap: expected a number of bootstrap replicates of at least 2, " \
        "got '0'" in err
    assert not (tmp_path / "bad").exists()  # refused before any folder is made
    rec = tmp_path / "rec"
    assert main(["recover", "free_choice", "--condition", "learning_progress", "--fit", "LC.gain", "--bounds",
                 "LC.gain=2:40", "--signal", "HPC=error", "--datasets", "3", "--episodes", "50", "--starts", "1",
                 "--ci", "bootstrap", "--bootstrap", "4", "--out", str(rec)]) == 0
    table = pd.read_csv(rec / "recovery.csv")
    assert (table["ci_low"] < table["ci_high"]).all() and len(table) == 3
