"""The look of every figure of the analysis, and saving them.

Each figure function of :mod:`neurocur.analysis` draws on a :func:`figure` inside
:func:`style`::

    with style():
        fig, axes = figure(1, 2, figsize=(8.0, 3.5), sharey=True)
        axes[0, 0].plot(x, y)

A :func:`figure` is a :class:`matplotlib.figure.Figure` on its own Agg canvas: no pyplot
state, no window, nothing to close. :func:`save_figure` writes one as PNG, :func:`save_figures` a batch.

**Colours.** A colour means one thing in every figure: a source (:func:`source_colours`: S-A blue,
S-B orange, S-C green, the unlearnable S-D grey; Okabe & Ito 2008's colour-blind-safe set) or a
condition (:func:`condition_colours`: curious wine, random switching near-black, literal purple;
dark hues none of the sources uses), never both.

**Captions.** :func:`caption` records on a figure the paper figure it reproduces and what it
shows; :func:`save_figures` writes them into the PNG's metadata and
:func:`~neurocur.analysis.figures.sets.write_all` into ``index.csv``.
"""

from __future__ import annotations

import io
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import seaborn as sns
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...results.safeio import atomic_bytes

__all__ = ["SOURCE_COLOURS", "CONDITION_COLOURS", "source_colours", "condition_colours", "Caption", "caption",
           "caption_of", "style", "figure", "save_figure", "save_figures"]

#: The colour of each source of the paper's synthetic world (section 4.1), in every figure.
SOURCE_COLOURS = {"S-A": "#0072b2", "S-B": "#e69f00", "S-C": "#009e73", "S-D": "#999999"}
#: The colours of any other source, given in the order of the world's sources.
_MORE_SOURCES = ("#56b4e9", "#d55e00", "#cc79a7", "#f0e442", "#8c613c")
#: The colour of each shipped condition of the synthetic experiment, in every figure.
CONDITION_COLOURS = {"curious": "#882255", "random_switching": "#222222", "literal": "#aa4499"}
#: The colours of any other condition, given in the order of the folder's conditions.
_MORE_CONDITIONS = ("#6b3e26", "#dc267f", "#332288", "#5b5b2e", "#a5466b")


def _colours(names: Iterable[str], fixed: Mapping[str, str], more: tuple[str, ...]) -> dict[str, str]:
    names = list(dict.fromkeys(names))
    others = [n for n in names if n not in fixed]
    return {n: fixed[n] if n in fixed else more[others.index(n) % len(more)] for n in names}


def source_colours(sources: Iterable[str]) -> dict[str, str]:
    """The colour of each of ``sources`` (a world's sources, in its order): :data:`SOURCE_COLOURS`
    for the paper's, the others in turn from a set of their own.

    Parameters
    ----------
    sources : iterable of str
        The source names, in the world's order (a repeated name counts once).

    Returns
    -------
    dict of str to str
        Each source's colour (a hex string), in the order of its first appearance.
    """
    return _colours(sources, SOURCE_COLOURS, _MORE_SOURCES)


def condition_colours(conditions: Iterable[str]) -> dict[str, str]:
    """The colour of each of ``conditions`` (a folder's conditions, in its order):
    :data:`CONDITION_COLOURS` for the shipped ones, the others in turn from dark hues no source uses.

    Parameters
    ----------
    conditions : iterable of str
        The condition names, in the folder's order (a repeated name counts once).

    Returns
    -------
    dict of str to str
        Each condition's colour (a hex string), in the order of its first appearance.
    """
    return _colours(conditions, CONDITION_COLOURS, _MORE_CONDITIONS)


@dataclass(frozen=True)
class Caption:
    """What a figure file is: the ``paper_figure`` it reproduces (e.g. "Figure 4D (section 4.1.4)", or
    "none: ..." for an analysis the paper has no figure of) and ``what_it_shows``, one sentence.

    Parameters
    ----------
    paper_figure : str
        The paper figure reproduced, with its section ("Figure 4D (section 4.1.4)"), or "none: ..." saying
        why there is none.
    what_it_shows : str
        What the figure shows, one sentence.
    """

    paper_figure: str
    what_it_shows: str


def caption(fig: Figure, paper_figure: str, what_it_shows: str) -> Figure:
    """Record on ``fig`` the paper figure it reproduces and what it shows (:class:`Caption`); returns ``fig``.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure; its caption is set in place (an earlier one is replaced).
    paper_figure : str
        The paper figure it reproduces (``Caption.paper_figure``).
    what_it_shows : str
        What it shows, one sentence (``Caption.what_it_shows``).

    Returns
    -------
    matplotlib.figure.Figure
        ``fig`` itself, so a figure function can end with ``return caption(fig, ...)``.
    """
    fig.neurocur_caption = Caption(paper_figure, what_it_shows)
    return fig


def caption_of(fig: Figure) -> Caption:
    """The :class:`Caption` of ``fig``; a figure drawn without one is "none" and its title.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.

    Returns
    -------
    Caption
        The caption recorded by ``caption``; else "none" and the first non-empty of the figure's suptitle
        and its axes' titles ("" when it has none).
    """
    found = getattr(fig, "neurocur_caption", None)
    if found is not None:
        return found
    titles = [fig.get_suptitle(), *(ax.get_title() for ax in fig.axes)]
    return Caption("none", next((t for t in titles if t), ""))


@contextmanager
def style() -> Iterator[None]:
    """Seaborn's ``whitegrid`` axes style and ``notebook`` context (font scale 0.9) for the
    figures drawn inside the ``with`` block."""
    with sns.axes_style("whitegrid"), sns.plotting_context("notebook", font_scale=0.9):
        yield


def figure(nrows: int = 1, ncols: int = 1, *, figsize=(7.0, 4.0), **kwargs) -> tuple[Figure, np.ndarray]:
    """A Figure with constrained layout on an Agg canvas, and its ``nrows`` × ``ncols`` axes as a
    2-D array (also for a single axes). ``kwargs`` go to :meth:`~matplotlib.figure.Figure.subplots`
    (``sharex``, ``sharey``, ``gridspec_kw``, ...).

    Parameters
    ----------
    nrows : int
        Rows of axes.
    ncols : int
        Columns of axes.
    figsize : (float, float)
        Width and height in inches.
    **kwargs
        Passed to ``Figure.subplots`` (``squeeze`` is always False).

    Returns
    -------
    fig : matplotlib.figure.Figure
        The figure, with an Agg canvas attached.
    axes : numpy.ndarray of matplotlib.axes.Axes
        Its axes, shape (``nrows``, ``ncols``).
    """
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes


def save_figure(fig: Figure, path: str | Path, dpi: int = 120) -> Path:
    """Write ``fig`` as a PNG file at ``path``, whole (:func:`~neurocur.results.safeio.atomic_bytes`: a
    temporary file renamed into place, no link followed), its :func:`caption_of` in the PNG's
    ``Title`` and ``Description`` text chunks.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or path
        The PNG file written (its folder must exist; an existing file is replaced).
    dpi : int
        Resolution in dots per inch.

    Returns
    -------
    path
        ``path``, as a ``Path``.
    """
    png = io.BytesIO()
    found = caption_of(fig)
    fig.savefig(png, dpi=dpi, format="png",
                metadata={"Title": found.paper_figure, "Description": found.what_it_shows})
    atomic_bytes(Path(path), png.getvalue())
    return Path(path)


def save_figures(figures: Mapping[str, Figure], out: str | Path, dpi: int = 120) -> list[Path]:
    """Write each ``{name: Figure}`` as ``out/<name>.png`` (``out`` must exist; :func:`save_figure`);
    return the paths in order.

    Parameters
    ----------
    figures : mapping of str to matplotlib.figure.Figure
        The figures by file name, without the ``.png``.
    out : str or path
        The existing folder written into.
    dpi : int
        Resolution in dots per inch.

    Returns
    -------
    list of path
        The files written, in the order of ``figures``.
    """
    return [save_figure(fig, Path(out) / f"{name}.png", dpi) for name, fig in figures.items()]
