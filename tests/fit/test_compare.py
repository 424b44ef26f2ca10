"""Model comparison on data: scores against closed forms and a refit by hand; BMS on the table; the command."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.experiments import load_experiment
from neurocur.fit.compare import bms_table, compare_models, totals
from neurocur.fit.mle import fit_ml
from neurocur.fit.study import make_replays, model_bounds, simulate

SIGNAL = ("HPC", "error")
N = 80


@pytest.fixture(scope="module")
def choices():
    """Three data sets of 80 free choices by the learning-progress model (gain 20), each with its own seed."""
    exp = load_experiment("free_choice")
    data = [simulate(exp.conditions["learning_progress"], {}, exp.run_seed(i), N, signal=SIGNAL, name=f"s{i}")[0]
            for i in range(3)]
    return exp, data


def test_every_model_on_every_data_set_against_closed_forms_and_a_refit(choices):
    exp, data = choices
    models, bounds = model_bounds(exp, ["learning_progress", "random"], ["learning_progress:LC.gain"],
                                  {"LC.gain": (0.0, 60.0)})
    assert bounds == {"learning_progress": {"LC.gain": (0.0, 60.0)}, "random": {}}
    table = compare_models(exp, data, models, bounds, signal=SIGNAL, starts=2)
    assert list(table.columns) == ["dataset", "model", "loglik", "n_params", "n_obs", "aic", "bic", "heldout", "loo"]
    assert len(table) == 6
    rand = table[table["model"] == "random"].set_index("dataset")
    # random choice among 4 tasks: log L = n log(1/4), no parameter, the same on every split
    np.testing.assert_allclose(rand["loglik"], N * np.log(0.25))
    np.testing.assert_allclose(rand["aic"], -2 * N * np.log(0.25))
    np.testing.assert_allclose(rand["heldout"], (N - N // 2) * np.log(0.25))
    np.testing.assert_allclose(rand["loo"], N * np.log(0.25))
    lp = table[table["model"] == "learning_progress"].set_index("dataset")
    np.testing.assert_allclose(lp["bic"], np.log(N) - 2 * lp["loglik"])
    assert (lp["bic"] < rand["bic"]).all() and (lp["loo"] > rand["loo"]).all()
    # leave one data set out: the pooled fit to the other two scores the first
    replays = make_replays(exp, models["learning_progress"], data, ["LC.gain"], signal=SIGNAL)
    pooled = fit_ml(replays[1:], bounds["learning_progress"], starts=2, seed=0, ci=None)
    assert abs(lp.loc["s0", "loo"] - replays[0].loglik(pooled.estimate)) < 1e-9
    assert lp.loc["s0", "loo"] <= lp.loc["s0", "loglik"] + 1e-9  # the data set's own fit is at least as good

    selection = bms_table(table)
    assert list(selection["model"]) == ["learning_progress", "random"]
    np.testing.assert_allclose([selection["xp"].sum(), selection["pxp"].sum(), selection["expected"].sum()], 1.0)
    assert selection.loc[0, "expected"] > 0.7 and selection.loc[0, "pxp"] > selection.loc[1, "pxp"]
    summed = totals(table, selection)  # what the figure draws and the command prints
    assert list(summed.index) == ["learning_progress", "random"]
    np.testing.assert_allclose(summed.loc["random", ["loglik", "heldout", "loo"]],
                               [3 * N * np.log(0.25), 3 * (N - N // 2) * np.log(0.25), 3 * N * np.log(0.25)])
    np.testing.assert_allclose(summed["pxp"], selection["pxp"])


def test_a_model_prefix_must_name_a_compared_model(choices):
    exp, _ = choices
    with pytest.raises(ConfigError, match="MODEL one of learning_progress, random"):
        model_bounds(exp, ["learning_progress", "random"], ["novelty:LC.gain"], {})


def test_the_compare_command_writes_its_tables_and_figure(choices, tmp_path):
    exp, data = choices
    rows = [pd.DataFrame({"dataset": b.name, "episode": np.arange(N), "context": b.contexts, "decision": b.decisions,
                          "error": b.signals["error"]}) for b in data[:2]]
    path = tmp_path / "choices.csv"
    pd.concat(rows).to_csv(path, index=False)
    out = tmp_path / "compare"
    assert main(["compare", str(path), "--experiment", "free_choice", "--models", "learning_progress", "random",
                 "--fit", "learning_progress:LC.gain", "--bounds", "LC.gain=0:60", "--signal", "HPC=error",
                 "--starts", "1", "--out", str(out)]) == 0
    table = pd.read_csv(out / "compare.csv")
    assert len(table) == 4 and set(table["model"]) == {"learning_progress", "random"}
    assert list(pd.read_csv(out / "bms.csv").columns) == ["model", "expected", "xp", "pxp", "bor"]
    assert (out / "comparison.png").stat().st_size > 10_000
