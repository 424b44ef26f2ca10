"""Every figure function returns a Figure with the expected axes and lines."""

from __future__ import annotations

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from neurocur.analysis import (
    Results,
    fig_cumulative_error,
    fig_intrinsic_reward,
    fig_learning_time,
    fig_neuromodulators,
    fig_order_counts,
    fig_reward_function,
    reward_estimates,
    write_all,
)
from neurocur.analysis.figures import sets as sets_module
from neurocur.analysis.figures.learning import EVENT_GID
from neurocur.contexts.synthetic import SYNTHETIC
from neurocur.regions.pfc import DISENGAGE, ENGAGE, PFCLSPI, PFCParams, reward_update


def _data_lines(ax):
    return [line for line in ax.lines if line.get_gid() != EVENT_GID]


def test_cumulative_error(tables):
    episodes, modules = tables
    fig = fig_cumulative_error(episodes, run=2)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    left, right = fig.axes
    # left: run 2 per episode, its four storages marked
    assert len(_data_lines(left)) == 1 and len(_data_lines(left)[0].get_xdata()) == 60
    assert len([line for line in left.lines if line.get_gid() == EVENT_GID]) == 4
    # right: one line per cycle, aligned to storage; the last bin before the first storage is
    # the storing episode and the 9 before it (1000 frames), averaged per run, then over runs
    curious = episodes[episodes["condition"] == "curious"]
    first = modules[(modules["condition"] == "curious") & (modules["module"] == 0)].set_index("run")["episode"]
    expected = np.mean([curious[(curious["run"] == r) & curious["episode"].between(e - 9, e)]["error"].mean()
                        for r, e in first.items()])
    module_1 = [line for line in _data_lines(right) if len(line.get_xdata())][0]      # the lines in cycle order
    assert module_1.get_xdata()[-1] == -500.0 and module_1.get_ydata()[-1] == pytest.approx(expected)
    assert {"module 1", "module 2", "module 3"} == {t.get_text() for t in right.get_legend().get_texts()}
    # a bin is drawn where at least min_runs runs have it: all four curious runs have cycles 1 and 2, three have 3
    assert {t.get_text() for t in fig_cumulative_error(episodes, min_runs=4).axes[1].get_legend().get_texts()} == {
        "module 1", "module 2"}


def test_intrinsic_reward(tables):
    episodes, _ = tables
    fig = fig_intrinsic_reward(episodes, "random_switching", window=1, ylim=(-60, 5))
    ax = fig.axes[0]
    assert len(fig.axes) == 1 and len(ax.lines) == 2  # the reward and the zero line
    table = episodes[episodes["condition"] == "random_switching"]
    last = table[table["step"] >= 5000].groupby("run")["da"].mean().mean()
    assert ax.lines[0].get_ydata()[-1] == pytest.approx(last)
    assert ax.get_ylim() == (-60, 5) and "clipped" in ax.get_title()
    no_boredom = fig_intrinsic_reward(episodes, include_boredom=False).axes[0].lines[0].get_ydata()
    assert no_boredom.min() > -1.0


def test_learning_time(results):
    fig = fig_learning_time(results)
    ax = fig.axes[0]
    assert len(fig.axes) == 1
    bars = [p for p in ax.patches if p.get_height() > 0]
    # curious learned S-A, S-B, S-C; random_switching learned S-A and S-B
    assert len(bars) == 5
    only = fig_learning_time(results, condition="curious").axes[0]
    assert len([p for p in only.patches if p.get_height() > 0]) == 3


def _eq14_by_hand(run, n_contexts, alpha):
    """R_c after each episode: eq 14 (reward_update) on every episode but the first, from 0."""
    estimate, out = np.zeros(n_contexts), []
    for i, (context, da) in enumerate(zip(run["context"], run["da"])):
        if i > 0:
            estimate[context] = reward_update(estimate[context], da, alpha)
        out.append(estimate.copy())
    return np.array(out)


def test_reward_function(tables):
    episodes, modules = tables
    in_memory = Results.of(episodes, modules, SYNTHETIC)  # no config.toml: no recorded alpha
    fig = fig_reward_function(in_memory, run=1)
    ax = fig.axes[0]
    assert len(fig.axes) == 1 and len(ax.lines) == 5
    assert ax.lines[2].get_label() == "C3 (S-B)"
    assert f"α={PFCParams().alpha:g}" in ax.get_title()  # the PFC's default learning rate
    run = episodes[(episodes["condition"] == "curious") & (episodes["run"] == 1)].sort_values("episode")
    expected = _eq14_by_hand(run, 5, PFCParams().alpha)
    for c, line in enumerate(ax.lines):
        np.testing.assert_array_equal(line.get_ydata(), expected[:, c])
        np.testing.assert_array_equal(line.get_xdata(), run["step"] + run["n_frames"])
    last = fig_reward_function(in_memory, run=1, alpha=1.0).axes[0].lines[4].get_ydata()
    assert last[-1] == pytest.approx(run.loc[run["context"] == 4, "da"].iloc[-1])  # alpha = 1: the last reward


def test_write_all_draws_the_reward_function_with_the_folders_alpha(results_dir, results, tables, pfc_alpha,
                                                                    tmp_path, monkeypatch):
    # the value estimator is found by its region type (pfc.lspi), not by its name in the circuit
    assert results.region_param(PFCLSPI, "alpha") == pfc_alpha
    drawn, save = {}, sets_module.save_figures

    def keep(figs, out, dpi):
        drawn.update(figs)
        return save(figs, out, dpi)

    monkeypatch.setattr(sets_module, "save_figures", keep)
    write_all(results_dir, tmp_path / "figs")
    episodes, _ = tables
    for condition, alpha in pfc_alpha.items():
        ax = drawn[f"reward_function_{condition}"].axes[0]
        assert f"α={alpha:g}" in ax.get_title()
        run = episodes[(episodes["condition"] == condition) & (episodes["run"] == 0)].sort_values("episode")
        expected = _eq14_by_hand(run, 5, alpha)
        for c, line in enumerate(ax.lines):
            np.testing.assert_array_equal(line.get_ydata(), expected[:, c])
        assert not np.allclose(expected, _eq14_by_hand(run, 5, PFCParams().alpha))  # the alpha matters here


def test_order_counts(results):
    fig = fig_order_counts(results)
    assert len(fig.axes) == 2
    heights = sorted(p.get_height() for p in fig.axes[0].patches if p.get_height() > 0)
    # curious: position 1 S-A 4; 2: S-B 3, S-C 1; 3: S-C 2, S-B 1, none 1
    assert heights == [1, 1, 1, 2, 3, 4]
    assert "n=4" in fig.axes[0].get_title()


def test_neuromodulators(tables):
    episodes, _ = tables
    fig = fig_neuromodulators(episodes, run=2)
    assert len(fig.axes) == 4
    for ax in fig.axes:
        assert len(_data_lines(ax)) == 1
        assert len([line for line in ax.lines if line.get_gid() == EVENT_GID]) == 4  # 4 modules stored
    assert fig.axes[0].get_yscale() == "symlog"
    assert [ax.get_ylabel() for ax in fig.axes][-1] == "ε"


def test_neuromodulators_without_epsilon(tables):
    # an LC other than the epsilon-greedy one (e.g. lc.softmax) records no epsilon: no ε panel
    episodes = tables[0].drop(columns="epsilon")
    fig = fig_neuromodulators(episodes, run=2)
    assert [ax.get_ylabel() for ax in fig.axes] == ["DA (intrinsic reward)", "NE tonic", "NE phasic"]


def test_figures_name_the_missing_column_and_its_role(tables):
    episodes, modules = tables
    with pytest.raises(ValueError, match=r"fig_neuromodulators needs the column\(s\) 'ne_tonic' \(from LC\)"):
        fig_neuromodulators(episodes.drop(columns="ne_tonic"))
    with pytest.raises(ValueError, match=r"fig_reward_function needs the column\(s\) 'da' \(from VTA\)"):
        fig_reward_function(Results.of(episodes.drop(columns="da"), modules, SYNTHETIC))
    with pytest.raises(ValueError, match=r"fig_cumulative_error needs the column\(s\) 'error' \(from HPC\)"):
        fig_cumulative_error(episodes.drop(columns="error"))
    with pytest.raises(ValueError, match=r"fig_learning_time \(modules table\) needs the column\(s\) 'source'"):
        fig_learning_time(Results.of(episodes, modules.drop(columns="source"), SYNTHETIC))
    with pytest.raises(ValueError, match=r"fig_order_counts \(modules table\) needs the column\(s\) 'gates'"):
        fig_order_counts(Results.of(episodes, modules.drop(columns="gates"), SYNTHETIC))


def test_unknown_condition_or_run(tables):
    episodes, _ = tables
    with pytest.raises(ValueError, match="not in the results"):
        fig_cumulative_error(episodes, "lesion")
    with pytest.raises(ValueError, match="run 9 not in"):
        fig_neuromodulators(episodes, run=9)


def test_write_all(results_dir, tmp_path):
    paths = write_all(results_dir, tmp_path / "figs")
    names = sorted(p.name for p in paths)
    per_condition = ["cumulative_error", "intrinsic_reward", "neuromodulators", "reward_function"]
    expected = sorted(["order_counts.png", "learning_time.png", "efficiency.png", "index.csv"]
                      + [f"{k}_{c}.png" for k in per_condition for c in ("curious", "random_switching")])
    assert names == expected
    for path in paths:
        if path.suffix == ".png":
            assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert plt.get_fignums() == []  # no pyplot figure left open


def test_the_efficiency_figure_compares_the_reference_with_the_declared_control(tables, write_folder, tmp_path):
    """The first condition against the experiment's ``control``, whatever they are called; no
    declared control, no efficiency figure."""
    episodes, modules = tables
    runs = {name: [(e.drop(columns=["condition", "run"]), modules[(modules["condition"] == c) & (modules["run"] == r)]
                    .drop(columns=["condition", "run"])) for (c, r), e in episodes.groupby(["condition", "run"])
                   if c == old]
            for name, old in (("agent", "curious"), ("lesioned", "random_switching"))}
    declared = write_folder(tmp_path / "declared", runs, alphas={}, control="lesioned")
    figures = sets_module.figure_set(Results.load(declared)).draw(Results.load(declared))
    assert [t.get_text() for t in figures["efficiency"].axes[0].get_xticklabels()] == ["agent", "lesioned"]
    undeclared = write_folder(tmp_path / "undeclared", runs, alphas={}, control=None)
    assert "efficiency" not in sets_module.figure_set(Results.load(undeclared)).draw(Results.load(undeclared))


def test_figure_sets_are_registered_per_world_type(results, monkeypatch):
    assert {"synthetic", "icub"} <= set(sets_module.FIGURE_SETS.names())
    assert isinstance(sets_module.figure_set(results), sets_module.StandardFigures)  # no world.type: synthetic

    class Only(sets_module.FigureSet):
        def draw(self, results):
            return {"only": fig_order_counts(results)}

    monkeypatch.setitem(sets_module.FIGURE_SETS._types, "toy", Only)
    config = {**results.config, "conditions": {c: {"world": {"type": "toy"}} for c in results.conditions}}
    toy = Results(results.episodes, results.modules, results.specs, config)
    assert isinstance(sets_module.figure_set(toy), Only)
    mixed = {**config, "conditions": {**config["conditions"], "other": {"world": {"type": "icub"}}}}
    assert isinstance(sets_module.figure_set(Results(results.episodes, results.modules, results.specs, mixed)),
                      sets_module.StandardFigures)


def test_reward_estimates_by_hand():
    # eq 14 from R = 0, alpha 0.5; the first episode is skipped (the PFC has no previous
    # context yet): C2 0.5 * 1 = 0.5, C1 0.5 * 2 = 1, then 0.5 * 1 + 0.5 * 4 = 2.5
    run = pd.DataFrame({"context": [0, 1, 0, 0], "da": [9.0, 1.0, 2.0, 4.0]})
    np.testing.assert_allclose(reward_estimates(run, 2, 0.5), [[0.0, 0.0], [0.0, 0.5], [1.0, 0.5], [2.5, 0.5]])
    with pytest.raises(ValueError, match="alpha must be in"):
        reward_estimates(run, 2, 0.0)
    # as a sample average: C1 is the mean of 2 and 4, C2 of its one sample
    np.testing.assert_allclose(reward_estimates(run, 2, "sample_average")[-1], [3.0, 1.0])


def test_reward_estimates_are_the_pfc_model_pooled_over_previous_context_and_action():
    # contexts of 7 episodes and the decision at the end of each; every update into C1 goes to
    # R[C1, engage, C1], so the figure's R_C1 is that entry of the PFC's own model, bit for bit
    contexts = [0, 0, 0, 1, 1, 2, 2]
    actions = [ENGAGE, ENGAGE, DISENGAGE, ENGAGE, DISENGAGE, ENGAGE, ENGAGE]
    da = [0.7, 0.3, -0.2, 0.9, 0.4, -100.0, 0.05]
    pfc = PFCLSPI(alpha=0.3)
    pfc.bind(SimpleNamespace(n_contexts=3))
    pfc.reset(np.random.default_rng(0))
    model = []
    for t, (context, reward) in enumerate(zip(contexts, da)):
        pfc.step(context, reward, None if t == 0 else actions[t - 1])
        model.append(pfc.model.R3.copy())
    estimates = reward_estimates(pd.DataFrame({"context": contexts, "da": da}), 3, 0.3)
    np.testing.assert_array_equal(estimates[:, 0], [m[0, ENGAGE, 0] for m in model])
    # C2 is entered by disengaging from C1, then by engaging: the figure pools the two entries
    assert estimates[-1, 1] == reward_update(model[-1][0, DISENGAGE, 1], da[4], 0.3)
    assert model[-1][1, ENGAGE, 1] == reward_update(0.0, da[4], 0.3)


def test_a_figure_replaces_a_link_planted_at_its_name_and_never_writes_through_it(tmp_path):
    """save_figures writes each PNG whole into a temporary file renamed into place: a symbolic link at the
    figure's name is replaced by the figure, and the file it pointed to is left as it was."""
    from neurocur.analysis.figures.style import figure, save_figures

    outside = tmp_path / "outside.txt"
    outside.write_text("keep me")
    out = tmp_path / "figures"
    out.mkdir()
    (out / "order.png").symlink_to(outside)
    fig, axes = figure()
    axes[0, 0].plot([0, 1], [1, 0])
    (path,) = save_figures({"order": fig}, out)
    assert outside.read_text() == "keep me"
    assert not path.is_symlink() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.iterdir()) == ["order.png"]  # no temporary file left
