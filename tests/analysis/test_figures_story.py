"""What the figures tell a reader: the index of the files, one colour per source and per condition,
and the paper's numbers drawn beside the model's."""

from __future__ import annotations

import json

import matplotlib.colors as mcolors
import pandas as pd
import pytest
from fake_runs import CURIOUS, CYCLE, RANDOM, make_run
from PIL import Image

from neurocur.analysis import Results, order_tables
from neurocur.analysis.figures import (
    fig_cumulative_error,
    fig_intrinsic_reward,
    fig_learning_time,
    fig_neuromodulators,
    fig_order_counts,
    fig_reward_function,
)
from neurocur.analysis.figures.learning import PAPER_GID
from neurocur.analysis.figures.sets import FIGURE_5, INDEX
from neurocur.analysis.figures.style import condition_colours, source_colours
from neurocur.cli import main
from neurocur.contexts.synthetic import SYNTHETIC
from neurocur.experiments.invariance import load_invariance


def _hex(colour) -> str:
    return mcolors.to_hex(colour, keep_alpha=False)


def test_the_index_names_every_png_written_and_only_those(results_dir, tmp_path, capsys):
    out = tmp_path / "figs"
    out.mkdir()
    (out / "stale.png").write_bytes(b"\x89PNG\r\n\x1a\n")          # an earlier file the command did not write
    assert main(["figures", str(results_dir), "--out", str(out)]) == 0
    printed = capsys.readouterr().out.splitlines()
    index = pd.read_csv(out / INDEX)
    assert list(index.columns) == ["file", "paper_figure", "what_it_shows"]
    written = {line.rsplit("/", 1)[1] for line in printed if line.endswith(".png")}
    assert set(index["file"]) == written and len(index) == len(written)
    assert set(index["file"]) == {p.name for p in out.glob("*.png")} - {"stale.png"}
    assert FIGURE_5 not in printed                                   # Figure 5 is drawn, not named
    assert index.set_index("file").loc["invariance.png", "paper_figure"].startswith("Figure 5")
    demo = load_invariance("invariance").run()
    result = json.loads((out / "invariance.json").read_text())
    assert (result["corr"], result["quality"]) == (demo.corr, demo.quality)  # the shipped demo, seeded
    assert f"corr {demo.corr:.4f}" in index.set_index("file").loc["invariance.png", "what_it_shows"]
    paper_figure = index.set_index("file")["paper_figure"]
    assert paper_figure["cumulative_error_curious.png"].startswith("Figure 4D")
    assert paper_figure["intrinsic_reward_random_switching.png"].startswith("Figure 4E")
    assert paper_figure["learning_time.png"].startswith("Figure 4F")
    assert paper_figure["reward_function_curious.png"].startswith("Figure 4G")
    assert paper_figure["neuromodulators_curious.png"].startswith("none")
    # each PNG carries the caption the index gives it
    for row in index.itertuples(index=False):
        with Image.open(out / row.file) as png:
            assert png.text["Title"] == row.paper_figure and png.text["Description"] == row.what_it_shows


def test_without_the_invariance_demo_figure_5_is_named_instead(results_dir, tmp_path, capsys):
    out = tmp_path / "figs"
    assert main(["figures", str(results_dir), "--out", str(out), "--no-invariance"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == FIGURE_5     # how to get it, in one line
    assert not (out / "invariance.png").exists() and not (out / "invariance.json").exists()
    assert "invariance.png" not in set(pd.read_csv(out / INDEX)["file"])


def test_a_source_and_a_condition_keep_their_colour_across_figures(results):
    episodes = results.episodes
    sources, conditions = source_colours(SYNTHETIC.context_sources), condition_colours(results.conditions)
    # S-A: the order figure's bars, the reward function's C1 and C2, Figure 4D's S-A line
    order = fig_order_counts(results).axes[0]
    bars = {c.get_label(): _hex(c.patches[0].get_facecolor()) for c in order.containers}
    reward = {line.get_label(): _hex(line.get_color()) for line in fig_reward_function(results, run=1).axes[0].lines}
    error = fig_cumulative_error(episodes, "curious", spec=SYNTHETIC, min_runs=1).axes[1]
    lines = {line.get_label(): _hex(line.get_color()) for line in error.lines}
    for source in ("S-A", "S-B", "S-C"):
        assert bars[source] == reward[f"C{1 + SYNTHETIC.context_sources.index(source)} ({source})"] == sources[source]
    modules = {label.split("'s module")[0]: colour for label, colour in lines.items() if "'s module" in label}
    assert "S-A" in modules and all(colour == sources[source] for source, colour in modules.items())
    assert reward["C2 (S-A)"] == sources["S-A"]
    # curious: the learning-time bars, the intrinsic reward line, the neuromodulator traces
    learning = fig_learning_time(results).axes[0]
    handles, labels = learning.get_legend_handles_labels()
    bar = {label: _hex(h.patches[0].get_facecolor()) for h, label in zip(handles, labels) if hasattr(h, "patches")}
    reward_line = _hex(fig_intrinsic_reward(episodes, "curious").axes[0].lines[0].get_color())
    traces = {_hex(line.get_color()) for ax in fig_neuromodulators(episodes, run=2).axes for line in ax.lines
              if line.get_gid() != "module_learned"}
    assert bar["curious"] == reward_line == conditions["curious"] and traces == {conditions["curious"]}
    assert bar["random_switching"] == conditions["random_switching"]
    # a colour means a source or a condition, never both
    assert not set(sources.values()) & set(conditions.values())


def test_the_learning_time_figure_draws_the_papers_epochs(results):
    ax = fig_learning_time(results).axes[0]
    marks = [line for line in ax.lines if line.get_gid() == PAPER_GID]
    spans = sorted((min(m.get_ydata()), max(m.get_ydata())) for m in marks)
    assert spans == [(2.0, 3.0), (15.0, 15.0), (40.0, 40.0)]        # S-A 2–3, S-B ≈15, S-C ≈40 (section 4.1.1)
    other = Results.of(results.episodes, results.modules, SYNTHETIC, {"name": "my_world"})
    assert not [line for line in fig_learning_time(other).axes[0].lines if line.get_gid() == PAPER_GID]


def test_the_order_figure_marks_the_papers_counts_scaled_to_the_runs(results):
    fig = fig_order_counts(results)
    for ax in fig.axes:
        n = int(ax.get_title().split("n=")[1].rstrip(")"))
        heights = sorted(float(m.get_ydata()[0]) for m in ax.lines if m.get_gid() == PAPER_GID)
        # S-A first 25/25, S-B second 18/25, S-C third 18/25 of the panel's n runs
        assert heights == pytest.approx(sorted([n * 1.0, n * 18 / 25, n * 18 / 25]))
    other = Results.of(results.episodes, results.modules, SYNTHETIC, {"name": "my_world"})
    assert not [m for ax in fig_order_counts(other).axes for m in ax.lines if m.get_gid() == PAPER_GID]


def test_figure_4d_shows_the_error_of_the_module_being_learned_on_a_log_axis(results):
    fig = fig_cumulative_error(results.episodes, "curious", spec=SYNTHETIC, threshold=0.3)
    left, right = fig.axes[:2]
    assert left.get_yscale() == right.get_yscale() == "log"
    assert any(line.get_label() == "freeze threshold 0.3" for line in right.lines)
    legend = right.get_legend()
    fig.canvas.draw()
    # the legend stands right of the axes, over no data
    assert legend.get_window_extent().x0 >= right.get_window_extent().x1


def test_a_sweep_writes_its_order_table_beside_its_figures(write_folder, tmp_path):
    runs = {}
    for value in (0.5, 2.0):
        runs[f"curious@LC.gain={value:g}"] = [make_run(CYCLE, s, seed=i) for i, s in enumerate(CURIOUS)]
        runs[f"random_switching@LC.gain={value:g}"] = [make_run(CYCLE, s, seed=10 + i) for i, s in enumerate(RANDOM)]
    runs = {name: [(e.assign(**{"LC.gain": float(name.split("=")[1])}), m) for e, m in tables]
            for name, tables in runs.items()}
    root = write_folder(tmp_path / "sweep", runs, alphas={}, control=None)
    out = tmp_path / "figs"
    assert main(["figures", str(root), "--out", str(out)]) == 0
    written = pd.read_csv(out / "order_table.csv")
    expected = order_tables(root).reset_index()
    assert list(written.columns) == list(expected.columns)
    assert written.astype(str).values.tolist() == expected.astype(str).values.tolist()
    assert "order_table.csv" not in set(pd.read_csv(out / INDEX)["file"])     # the index lists the PNGs


def test_the_icub_order_figure_marks_the_papers_14_of_15_and_15_of_15():
    from neurocur.analysis.figures.icub import fig_order

    # three runs: topple then roll, topple only, roll then topple
    episodes = pd.DataFrame({"condition": "curious", "run": [0, 1, 2], "episode": 0, "n_frames": 100})
    modules = pd.DataFrame({"condition": "curious", "run": [0, 0, 1, 2, 2], "module": [0, 1, 0, 0, 1],
                            "source": ["topple", "roll", "topple", "roll", "topple"], "gates": ""})
    fig = fig_order(modules, episodes)
    ax = fig.axes[0]
    marks = sorted((round(float(m.get_xdata()[0])), float(m.get_ydata()[0])) for m in ax.lines
                   if m.get_gid() == PAPER_GID)
    assert marks == [(1, pytest.approx(3 * 14 / 15)), (2, 0.0)]   # topple first 14/15; no run without a second
    assert "14/15" in fig.get_suptitle() and "15/15" in fig.get_suptitle()
    from neurocur.analysis.figures.style import caption_of

    assert caption_of(fig).paper_figure.startswith("Figure 6D")
