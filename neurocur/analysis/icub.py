"""Figures and statistics of the simulated iCub experiment (paper section 4.2, Figures 6–7).

A results folder of an iCub experiment (``world.type = "icub"``) holds, besides the usual
episodes and modules tables, a ``features.parquet`` per run: every stored module's slow
outputs on the reference episodes of both contexts, with the object's displacement
(written by :meth:`neurocur.contexts.icub.ICubWorld.module_report`). The modules table has the
columns ``quality`` (|corr| of the slowest output y₀ with the object's displacement in the
module's own context), ``arm_corr`` (|corr| of y₀ with the arm's joint state there),
``other_quality`` (with the displacement in the other context) and ``context_corr``
(with the context index over both contexts).

Figures (each a :class:`matplotlib.figure.Figure` in the style of :mod:`neurocur.analysis.style`):

- :func:`fig_module_error` — Figures 6B (``module=0``) and 6C (``module=1``): the
  adaptive module's estimation error while the k-th module learns;
- :func:`fig_order` — Figure 6D: which object was learned first and second;
- :func:`fig_frames` — a strip of frames from both contexts (Figure 6A);
- :func:`fig_feature_output` — the slowest output over reference episodes against the
  object's displacement (Figure 7).

:func:`write_icub_figures` draws them all; :func:`neurocur.analysis.write.write_all`
calls it when a results folder's world type is ``icub``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import seaborn as sns
from matplotlib.figure import Figure

from neurocur.analysis.figures import _condition, fig_neuromodulators, fig_order_counts, fig_reward_function
from neurocur.analysis.order import order_counts, require_order_columns
from neurocur.analysis.paper import ICUB_CURIOUS
from neurocur.analysis.style import figure, save_figures, style
from neurocur.analysis.write import pfc_alphas
from neurocur.contexts import build_world
from neurocur.contexts.icub import ICUB
from neurocur.contract import require_columns
from neurocur.learn.correlation import abs_corr
from neurocur.regions.pfc import PFCParams
from neurocur.results import ResultsStore, load

__all__ = [
    "ICUB",
    "results_world_type",
    "load_features",
    "learning_segments",
    "encoding_table",
    "arm_invariance",
    "first_module_counts",
    "fig_module_error",
    "fig_order",
    "fig_frames",
    "fig_feature_output",
    "write_icub_figures",
]

def results_world_type(results_dir: str | Path) -> str:
    """The world type of a results folder, read from its ``config.toml`` ("synthetic" by default)."""
    config = ResultsStore(results_dir).config() or {}
    types = {c.get("world", {}).get("type", "synthetic") for c in config.get("conditions", {}).values()}
    return "icub" if "icub" in types else "synthetic"


def load_features(results_dir: str | Path) -> pd.DataFrame:
    """Every run's ``features.parquet`` as one table (condition, run, module, context, ...)."""
    return ResultsStore(results_dir).load_table("features", ["condition", "run", "module", "context", "episode_index",
                                                             "frame", "state", "displacement", "contact_frame", "y0"])


def learning_segments(episodes: pd.DataFrame) -> pd.DataFrame:
    """The episodes with ``learning_module`` and ``frames_in`` added.

    ``learning_module`` (0-based) is the adaptive module during the episode: the library
    size before it (``n_modules`` minus the module stored at this episode). ``frames_in``
    counts the frames since that module started learning (its first episode's ``step``).
    """
    require_columns(episodes, ["condition", "run", "step", "n_modules", "module_learned"],
                    needed_by="learning_segments")
    table = episodes.copy()
    table["learning_module"] = table["n_modules"] - table["module_learned"].astype(int)
    start = table.groupby(["condition", "run", "learning_module"])["step"].transform("min")
    table["frames_in"] = table["step"] - start
    return table


def encoding_table(modules: pd.DataFrame) -> pd.DataFrame:
    """What the slowest output of the first module of each object encodes, per condition.

    Columns: condition, source, n (runs with such a module), and the mean ± sd over those
    modules of ``quality`` (|corr| with the displacement), ``arm_corr``, ``other_quality``
    and ``context_corr`` (see the module docstring).
    """
    require_columns(modules, ["condition", "run", "module", "source"], needed_by="encoding_table")
    metrics = ["quality", "arm_corr", "other_quality", "context_corr"]
    first = modules.sort_values("module").drop_duplicates(["condition", "run", "source"])
    rows = []
    for (condition, source), table in first.groupby(["condition", "source"], sort=True):
        row = {"condition": condition, "source": source, "n": len(table)}
        for m in metrics:
            values = table[m].astype(float).dropna() if m in table else pd.Series(dtype=float)
            row[f"{m}_mean"] = values.mean() if len(values) else math.nan
            row[f"{m}_sd"] = values.std(ddof=1) if len(values) > 1 else math.nan
        rows.append(row)
    return pd.DataFrame(rows)


def arm_invariance(features: pd.DataFrame, modules: pd.DataFrame) -> pd.DataFrame:
    """How much of each module's slowest output follows the arm rather than the object.

    The arm and the object are confounded over a whole episode (the hand is past the
    object once it has moved it), so ``arm_corr`` of the modules table mixes the two.
    Here, on the reference episodes of the module's own context (``features``):
    ``corr_displacement`` = |corr(y₀, displacement)| over all frames; ``corr_arm_at_rest``
    = |corr(y₀, arm state)| over the frames before the first contact, when only the arm
    moves; ``rest_sd_ratio`` = sd(y₀) before contact / sd(y₀) over all frames (0: y₀
    ignores the arm, 1: the arm moves y₀ as much as the object does); ``jump`` = |mean
    y₀ from 10 frames after contact on − mean y₀ before contact| / sd(y₀).
    One row per stored module: condition, run, module, source and those four columns.
    """
    require_columns(features, ["condition", "run", "module", "context", "frame", "contact_frame", "state",
                               "displacement", "y0"], needed_by="arm_invariance (features table)")
    require_columns(modules, ["condition", "run", "module", "source"], needed_by="arm_invariance (modules table)")
    info = modules.set_index(["condition", "run", "module"])
    rows = []
    for (condition, run, m), table in features.groupby(["condition", "run", "module"], sort=True):
        row = info.loc[(condition, run, m)]
        own = table[table["context"] == ICUB.context_names.index(row["source"])]
        rest = own[own["frame"] < own["contact_frame"]]
        after = own[own["frame"] >= own["contact_frame"] + 10]
        sd = own["y0"].std()
        rows.append({
            "condition": condition, "run": run, "module": m, "source": row["source"],
            "corr_displacement": abs_corr(own["y0"], own["displacement"]),
            "corr_arm_at_rest": abs_corr(rest["y0"], rest["state"]),
            "rest_sd_ratio": rest["y0"].std() / sd if sd > 0 else math.nan,
            "jump": abs(after["y0"].mean() - rest["y0"].mean()) / sd if sd > 0 else math.nan,
        })
    columns = ["condition", "run", "module", "source", "corr_displacement", "corr_arm_at_rest", "rest_sd_ratio", "jump"]
    return pd.DataFrame(rows, columns=columns)


def first_module_counts(episodes: pd.DataFrame, modules: pd.DataFrame) -> pd.DataFrame:
    """Order outcomes per condition ("topple first", "roll second", ...) with 95 % intervals."""
    require_order_columns(episodes, modules, needed_by="first_module_counts")
    return order_counts(episodes, modules, ICUB)


def fig_module_error(
    episodes: pd.DataFrame,
    module: int = 0,
    *,
    bin_frames: int = 2000,
    threshold: float | None = None,
    min_runs: int = 3,
) -> Figure:
    """Figures 6B (``module=0``) and 6C (``module=1``): the error while module ``module+1`` learns.

    The adaptive module's context error (column ``error``: the mean of the context's stored
    eq-10 errors, eq 11 / M) on its unfamiliar episodes, against the frames since it started
    learning (:func:`learning_segments`), averaged per run over bins of ``bin_frames``, then
    over runs (mean ± sd band), one line per condition; bins that fewer than ``min_runs``
    runs reach are left out (a module learns for a different time in each run).
    ``threshold`` draws the freeze threshold (dashed). Runs that never reached this module
    do not count.
    """
    if module < 0:
        raise ValueError(f"module must be >= 0, got {module}")
    if bin_frames <= 0:
        raise ValueError(f"bin_frames must be a positive number of frames, got {bin_frames}")
    require_columns(episodes, ["condition", "run", "step", "n_modules", "module_learned", "error"],
                    needed_by="fig_module_error")
    table = learning_segments(episodes)
    table = table[(table["learning_module"] == module) & table["error"].notna()]
    table = table.assign(frames_in=table["frames_in"] // bin_frames * bin_frames + bin_frames / 2)
    binned = table.groupby(["condition", "run", "frames_in"], as_index=False)["error"].mean()
    reached = binned.groupby(["condition", "frames_in"])["run"].transform("nunique")
    binned = binned[reached >= min(min_runs, binned["run"].nunique())]
    conditions = sorted(episodes["condition"].unique())
    label = "6B" if module == 0 else "6C" if module == 1 else ""
    with style():
        fig, axes = figure()
        ax = axes[0, 0]
        if binned.empty:
            ax.text(0.5, 0.5, f"no run reached module {module + 1}", ha="center", va="center", transform=ax.transAxes)
        else:
            runs = binned.groupby("condition")["run"].nunique()
            binned["condition"] = binned["condition"].map(lambda c: f"{c} ({runs.get(c, 0)} runs)")
            order = [f"{c} ({runs.get(c, 0)} runs)" for c in conditions if c in runs]
            sns.lineplot(data=binned, x="frames_in", y="error", hue="condition", hue_order=order,
                         errorbar="sd", ax=ax, palette="colorblind")
        if threshold is not None:
            ax.axhline(threshold, color="0.3", ls="--", lw=0.9, label=f"freeze threshold {threshold:g}")
            ax.legend(loc="upper right")
        ax.set(xlabel=f"frames since module {module + 1} started learning",
               ylabel="estimation error (mean over states)",
               title=f"Figure {label}: estimation error while module {module + 1} learns (mean ± sd)".replace(
                   "Figure : ", ""))
    return fig


def fig_order(modules: pd.DataFrame, episodes: pd.DataFrame) -> Figure:
    """Figure 6D: which object was stored first and second, counted over runs, per condition.

    The paper: the easier topple representation was learned first in 14 of 15 runs
    (:data:`neurocur.analysis.paper.ICUB_CURIOUS`).
    """
    require_order_columns(episodes, modules, needed_by="fig_order")
    fig = fig_order_counts(modules, episodes, spec=ICUB)
    fig.suptitle(f"Figure 6D: storage order (paper: topple first {ICUB_CURIOUS['topple first'].value})")
    return fig


def fig_frames(world, episode_index: int = 0, n_frames: int = 5) -> Figure:
    """A strip of frames of episode ``episode_index`` of each context (Figure 6A).

    Rows: contexts; columns: ``n_frames`` frames evenly spaced from the first to the last,
    each titled with its frame number, arm state and the object's displacement (cm).
    """
    if n_frames < 2:
        raise ValueError(f"n_frames must be >= 2, got {n_frames}")
    with style():
        fig, axes = figure(world.n_contexts, n_frames, figsize=(2.2 * n_frames, 2.0 * world.n_contexts))
        for c, name in enumerate(world.context_names):
            ep = world.episode(c, episode_index)
            d = world.displacement(c, episode_index)
            for ax, t in zip(axes[c], np.linspace(0, len(d) - 1, n_frames).round().astype(int)):
                ax.imshow(ep.frames[t].reshape(world.frame_shape), cmap="gray", vmin=0.0, vmax=1.0)
                ax.set_title(f"{name} t={t} s={ep.states[t]}\nmoved {100 * d[t]:.1f} cm", fontsize=8)
                ax.set_axis_off()
        fig.suptitle(f"Episode {episode_index} of each context (contact at "
                     + ", ".join(f"t={world.contact_frame(c, episode_index)}" for c in range(world.n_contexts)) + ")")
    return fig


def _feature_run(features: pd.DataFrame, condition: str, run: int | None) -> int:
    table = features[features["condition"] == condition]
    if table.empty:
        raise ValueError(f"condition {condition!r} stored no module (no slow-feature outputs)")
    if run is not None:
        if run not in set(table["run"]):
            raise ValueError(f"run {run} of condition {condition!r} stored no module; have {sorted(set(table['run']))}")
        return int(run)
    n = table.groupby("run")["module"].nunique()
    return int(n.idxmax())  # the first run with the most modules


def fig_feature_output(
    features: pd.DataFrame,
    modules: pd.DataFrame,
    condition: str | None = None,
    run: int | None = None,
) -> Figure:
    """Figure 7: each stored module's slowest output y₀ against the object's displacement.

    One run (default: the condition's first run with the most modules); one row per stored
    module, one column per context. Each panel shows y₀ (left axis) and the object's
    displacement in cm (right axis, dashed) over the reference episodes, laid end to end
    (vertical lines separate episodes; dots mark the hand's first contact), and |corr|
    between the two over every cached episode of the module's own context (``quality``).
    """
    require_columns(features, ["condition", "run", "module", "context", "episode_index", "frame", "contact_frame",
                               "displacement", "y0"], needed_by="fig_feature_output (features table)")
    require_columns(modules, ["condition", "run", "module", "source", "quality", "other_quality"],
                    needed_by="fig_feature_output (modules table)")
    condition = _condition(features, condition)
    run = _feature_run(features, condition, run)
    table = features[(features["condition"] == condition) & (features["run"] == run)]
    mods = modules[(modules["condition"] == condition) & (modules["run"] == run)].set_index("module")
    ranks = sorted(table["module"].unique())
    contexts = sorted(table["context"].unique())
    palette = sns.color_palette("deep", 2)
    with style():
        fig, axes = figure(len(ranks), len(contexts), figsize=(5.0 * len(contexts), 2.6 * len(ranks)), sharex="col")
        for r, m in enumerate(ranks):
            for k, c in enumerate(contexts):
                ax = axes[r, k]
                part = table[(table["module"] == m) & (table["context"] == c)].sort_values(["episode_index", "frame"])
                x = np.arange(len(part))
                ax.plot(x, part["y0"].to_numpy(), color=palette[0], lw=1.0)
                twin = ax.twinx()
                twin.plot(x, 100 * part["displacement"].to_numpy(), color=palette[1], lw=1.0, ls="--")
                twin.grid(False)
                bounds = np.flatnonzero(np.diff(part["episode_index"].to_numpy())) + 0.5
                for b in bounds:
                    ax.axvline(b, color="0.6", lw=0.8)
                contact = x[(part["frame"] == part["contact_frame"]).to_numpy()]
                ax.plot(contact, part["y0"].to_numpy()[contact], "o", color="0.2", ms=3)
                name = ICUB.context_names[c]
                info = mods.loc[m] if m in mods.index else None
                learned = f"learned in {info['source']}" if info is not None else ""
                own = info is not None and info["source"] == name
                corr = info["quality"] if own else (info["other_quality"] if info is not None else math.nan)
                ax.set_title(f"module {m + 1} ({learned}) on {name}: |corr(y₀, displacement)| = {corr:.2f}",
                             fontsize=9)
                ax.set_ylabel("y₀", color=palette[0])
                twin.set_ylabel("displacement (cm)", color=palette[1])
                if r == len(ranks) - 1:
                    ax.set_xlabel("frame (reference episodes end to end)")
        fig.suptitle(f"Slowest feature vs the object's displacement — {condition}, run {run}")
    return fig


def _thresholds(config: dict) -> dict[str, float]:
    out = {}
    for name, cond in config.get("conditions", {}).items():
        hpc = cond.get("resolved_circuit", {}).get("regions", {}).get("HPC", {}).get("params", {})
        if "threshold" in hpc:
            out[name] = float(hpc["threshold"])
    return out


def write_icub_figures(results_dir: str | Path, out_dir: str | Path | None = None, *, dpi: int = 120) -> list[Path]:
    """Draw the iCub figures of a results folder as PNG in ``out_dir`` (default ``results_dir/figures``).

    Writes ``module_error_1.png`` (6B), ``module_error_2.png`` (6C), ``order_counts.png``
    (6D), ``frames.png`` (the world's episode 0 of each context; the world is rebuilt from
    ``config.toml``, reading the episode cache), per condition ``feature_output_<condition>.png``
    (when it stored a module), ``reward_function_<condition>.png`` and
    ``neuromodulators_<condition>.png``. The reward function uses the condition's own PFC
    ``alpha``, as in :func:`neurocur.analysis.write.write_all`. Returns the written paths.
    """
    results_dir = Path(results_dir)
    episodes, modules = load(results_dir)
    features = load_features(results_dir)
    config = ResultsStore(results_dir).config()
    alphas = pfc_alphas(results_dir)
    thresholds = set(_thresholds(config).values())
    threshold = thresholds.pop() if len(thresholds) == 1 else None
    out = results_dir / "figures" if out_dir is None else Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {
        "module_error_1": fig_module_error(episodes, 0, threshold=threshold),
        "module_error_2": fig_module_error(episodes, 1, threshold=threshold),
        "order_counts": fig_order(modules, episodes),
    }
    world_table = next(iter(config["conditions"].values()))["world"]
    figures["frames"] = fig_frames(build_world(world_table))
    for condition in sorted(episodes["condition"].unique()):
        if (features["condition"] == condition).any():
            figures[f"feature_output_{condition}"] = fig_feature_output(features, modules, condition)
        alpha = alphas.get(condition, PFCParams().alpha)
        figures[f"reward_function_{condition}"] = fig_reward_function(episodes, condition=condition, alpha=alpha,
                                                                      spec=ICUB)
        figures[f"neuromodulators_{condition}"] = fig_neuromodulators(episodes, condition=condition)
    return save_figures(figures, out, dpi)
