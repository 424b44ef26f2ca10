"""Every figure of a results folder, written as PNG files (``neurocur figures DIR``).

The figures themselves are :mod:`~neurocur.analysis.figures` (the paper's Figures 4D–G),
:mod:`~neurocur.analysis.figures_neuro` (the neuromodulator and behaviour analyses) and
:mod:`~neurocur.analysis.icub` (the iCub experiment); this module picks those that fit the
folder, with each condition's own parameters read from its ``config.toml``.
"""

from __future__ import annotations

from pathlib import Path

from neurocur.analysis.efficiency import efficiency_per_run
from neurocur.analysis.figures import (
    fig_cumulative_error,
    fig_intrinsic_reward,
    fig_learning_time,
    fig_neuromodulators,
    fig_order_counts,
    fig_reward_function,
)
from neurocur.analysis.figures_neuro import fig_efficiency
from neurocur.analysis.io import load, source_specs
from neurocur.analysis.style import save_figures
from neurocur.regions.pfc import PFCParams
from neurocur.results import ResultsStore

__all__ = ["pfc_alphas", "write_all"]


def pfc_alphas(results_dir: str | Path) -> dict[str, float | str]:
    """Eq 14's learning rate of each condition's PFC, read from the results folder's config.toml
    (``conditions.<name>.resolved_circuit.regions.PFC.params.alpha``); a condition whose
    config does not record one is left out."""
    conditions = (ResultsStore(results_dir).config() or {}).get("conditions", {})
    alphas = {}
    for name, condition in conditions.items():
        pfc = condition.get("resolved_circuit", {}).get("regions", {}).get("PFC", {})
        if "alpha" in pfc.get("params", {}):
            alpha = pfc["params"]["alpha"]
            alphas[name] = alpha if isinstance(alpha, str) else float(alpha)  # a rate, or "sample_average"
    return alphas


def write_all(results_dir: str | Path, out_dir: str | Path | None = None, *, dpi: int = 120) -> list[Path]:
    """Draw every figure of a results folder and save them as PNG in ``out_dir``.

    ``out_dir`` defaults to ``results_dir/figures``. Writes ``order_counts.png``,
    ``learning_time.png`` and, per condition, ``cumulative_error_<condition>.png``,
    ``intrinsic_reward_<condition>.png``, ``reward_function_<condition>.png`` and
    ``neuromodulators_<condition>.png`` (the latter two for the condition's first run), and
    ``efficiency.png`` when the folder has the conditions ``curious`` and ``random_switching``
    (:func:`~neurocur.analysis.figures_neuro.fig_efficiency`).
    The reward function uses the condition's own PFC ``alpha`` (:func:`pfc_alphas`; the
    :class:`~neurocur.regions.pfc.PFCParams` default when config.toml records none).
    A results folder of the iCub world (``world.type = "icub"`` in its config.toml) gets
    the iCub figures instead (:func:`neurocur.analysis.icub.write_icub_figures`).
    Returns the written paths.
    """
    from neurocur.analysis.icub import results_world_type, write_icub_figures

    if results_world_type(results_dir) == "icub":
        return write_icub_figures(results_dir, out_dir, dpi=dpi)
    episodes, modules = load(results_dir)
    alphas = pfc_alphas(results_dir)
    out = Path(results_dir) / "figures" if out_dir is None else Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {
        "order_counts": fig_order_counts(modules, episodes),
        "learning_time": fig_learning_time(episodes, modules),
    }
    for condition in sorted(episodes["condition"].unique()):
        alpha = alphas.get(condition, PFCParams().alpha)
        figures[f"cumulative_error_{condition}"] = fig_cumulative_error(episodes, condition)
        figures[f"intrinsic_reward_{condition}"] = fig_intrinsic_reward(episodes, condition)
        figures[f"reward_function_{condition}"] = fig_reward_function(episodes, condition=condition, alpha=alpha)
        figures[f"neuromodulators_{condition}"] = fig_neuromodulators(episodes, condition=condition)
    if {"curious", "random_switching"} <= set(episodes["condition"]):
        figures["efficiency"] = fig_efficiency(efficiency_per_run(episodes, modules, source_specs(results_dir)))
    return save_figures(figures, out, dpi)
