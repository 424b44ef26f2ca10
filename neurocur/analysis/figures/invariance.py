"""Figure 5 A–F: the invariance demonstration of section 4.1.5 (:mod:`neurocur.experiments.invariance`)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from neurocur.contexts.sources import SLOW_DIM

from .style import caption, figure, save_figure, style

__all__ = ["INVARIANCE_FIGURE", "fig_invariance", "save_invariance"]

INVARIANCE_FIGURE = "invariance.png"


def fig_invariance(demo, *, frame_shape=None, n_frames: int = 4) -> Figure:
    """Figure 5 A–F: source, frames, first feature; noisy source, noisy frames, feature after the swap.

    ``demo``: an :class:`~neurocur.experiments.invariance.InvarianceDemo`.

    ``frame_shape`` (height, width) defaults to the square the frames' pixel count
    makes; ``n_frames`` evenly spaced frames are shown side by side in B and E.

    Parameters
    ----------
    demo : InvarianceDemo
        The demonstration's result (``neurocur.experiments.invariance.InvarianceDemo``).
    frame_shape : (int, int) or None
        A frame's (height, width); None for the square its pixel count makes.
    n_frames : int
        Frames shown in B and E, from 1 to the demonstration's length.

    Returns
    -------
    matplotlib.figure.Figure
        Six panels: A–C learned, D–F with dimension 1 replaced by noise.

    Raises
    ------
    ValueError
        When the frames are not square and ``frame_shape`` is None, ``frame_shape`` does not hold a frame's
        pixels, or ``n_frames`` is out of range.
    """
    T, n_pixels = demo.frames.shape
    if frame_shape is None:
        side = math.isqrt(n_pixels)
        if side * side != n_pixels:
            raise ValueError(f"frames of {n_pixels} pixels are not square; give frame_shape=(height, width)")
        frame_shape = (side, side)
    if int(np.prod(frame_shape)) != n_pixels:
        raise ValueError(f"frame_shape {tuple(frame_shape)} does not hold {n_pixels} pixels")
    if not 1 <= n_frames <= T:
        raise ValueError(f"n_frames must be between 1 and {T}; got {n_frames}")
    shown = np.linspace(0, T - 1, n_frames + 2).round().astype(int)[1:-1]
    t = np.arange(T)
    with style():
        fig, axes = figure(2, 3, figsize=(11.0, 5.5), gridspec_kw={"width_ratios": [1.0, 1.2, 1.0]})
        for row, (source, frames, output, label) in enumerate((
            (demo.source, demo.frames, demo.output, "learned"),
            (demo.noisy_source, demo.noisy_frames, demo.noisy_output, "dimension 1 replaced by noise"),
        )):
            ax_s, ax_f, ax_y = axes[row]
            ax_s.plot(t, source[:, 0], color="tab:blue", lw=1.0, label="dimension 0 (slow)")
            ax_s.plot(t, source[:, 1], color="tab:red", lw=0.8, ls=":", label="dimension 1")
            ax_s.set_title(f"{'AD'[row]}  source ({label})", loc="left")
            tiles = [np.pad(frames[i].reshape(frame_shape), ((0, 0), (0, 1)), constant_values=np.nan) for i in shown]
            ax_f.imshow(np.hstack(tiles)[:, :-1], cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
            ax_f.set_xticks([(i + 0.5) * (frame_shape[1] + 1) - 1 for i in range(n_frames)], [f"t={i}" for i in shown])
            ax_f.set_yticks([])
            ax_f.grid(False)
            ax_f.set_title(f"{'BE'[row]}  frames", loc="left")
            if row == 1:
                ax_y.plot(t, demo.output, color="0.6", lw=2.5, label="before the swap (C)")
            ax_y.plot(t, output, color="tab:green", lw=1.0, label="first feature")
            ax_y.set_title(f"{'CF'[row]}  first (slowest) feature", loc="left")
        axes[0, 0].legend(loc="upper right", fontsize="x-small")
        axes[1, 2].legend(loc="upper right", fontsize="x-small")
        axes[0, 2].text(0.02, 0.04, f"|corr| with source dim {SLOW_DIM}: {demo.quality:.4f}", fontsize="small",
                        transform=axes[0, 2].transAxes)
        axes[1, 2].text(0.02, 0.04, f"corr with C: {demo.corr:.4f}", fontsize="small", transform=axes[1, 2].transAxes)
        for ax in (axes[1, 0], axes[1, 2]):
            ax.set_xlabel("local time step")
    return caption(fig, "Figure 5 A-F (section 4.1.5)",
                   f"The slowest feature learned on a source (C) stays as it was when the source's other "
                   f"dimension is replaced by noise (F): corr {demo.corr:.4f}, invariant to it.")


def save_invariance(demo, out_dir, *, dpi: int = 120) -> Path:
    """Draw ``demo`` (:func:`fig_invariance`) into ``out_dir/invariance.png``, with its caption
    (:func:`~neurocur.analysis.figures.style.save_figure`).

    Parameters
    ----------
    demo : InvarianceDemo
        The demonstration's result.
    out_dir : str or path
        The folder written into (created when missing).
    dpi : int
        Resolution in dots per inch.

    Returns
    -------
    path
        The PNG file written.
    """
    path = Path(out_dir) / INVARIANCE_FIGURE
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig_invariance(demo), path, dpi)
