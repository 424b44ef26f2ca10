"""The look of every figure of the analysis, and saving them.

Each figure function of :mod:`neurocur.analysis` draws on a :func:`figure` inside
:func:`style`::

    with style():
        fig, axes = figure(1, 2, figsize=(8.0, 3.5), sharey=True)
        axes[0, 0].plot(x, y)

A :func:`figure` is a :class:`matplotlib.figure.Figure` on its own Agg canvas: no pyplot
state, no window, nothing to close. :func:`save_figure` writes one as PNG, :func:`save_figures` a batch.
"""

from __future__ import annotations

import io
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import seaborn as sns
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...results.safeio import atomic_bytes

__all__ = ["style", "figure", "save_figure", "save_figures"]


@contextmanager
def style() -> Iterator[None]:
    """Seaborn's ``whitegrid`` axes style and ``notebook`` context (font scale 0.9) for the
    figures drawn inside the ``with`` block."""
    with sns.axes_style("whitegrid"), sns.plotting_context("notebook", font_scale=0.9):
        yield


def figure(nrows: int = 1, ncols: int = 1, *, figsize=(7.0, 4.0), **kwargs) -> tuple[Figure, np.ndarray]:
    """A Figure with constrained layout on an Agg canvas, and its ``nrows`` × ``ncols`` axes as a
    2-D array (also for a single axes). ``kwargs`` go to :meth:`~matplotlib.figure.Figure.subplots`
    (``sharex``, ``sharey``, ``gridspec_kw``, ...)."""
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes


def save_figure(fig: Figure, path: str | Path, dpi: int = 120) -> Path:
    """Write ``fig`` as a PNG file at ``path``, whole (:func:`~neurocur.results.safeio.atomic_bytes`: a
    temporary file renamed into place, no link followed)."""
    png = io.BytesIO()
    fig.savefig(png, dpi=dpi, format="png")
    atomic_bytes(Path(path), png.getvalue())
    return Path(path)


def save_figures(figures: Mapping[str, Figure], out: str | Path, dpi: int = 120) -> list[Path]:
    """Write each ``{name: Figure}`` as ``out/<name>.png`` (``out`` must exist; :func:`save_figure`);
    return the paths in order."""
    return [save_figure(fig, Path(out) / f"{name}.png", dpi) for name, fig in figures.items()]
