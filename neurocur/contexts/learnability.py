"""The learning cost Ω (eqs 15, 40) of every context of a world, as a tidy table.

:func:`learnability` measures each context's frames after a :meth:`~.base.World.reset`:

* a synthetic context whose source is replayed: Ω of its frames (one epoch);
* a synthetic context whose source is redrawn every epoch (S-D, noise, re-sampled files):
  Ω of ``draws`` fresh draws joined, and each draw's Ω
  (:meth:`~.synthetic.SyntheticWorld.omega`);
* an episodic (iCub) context: Ω of its cached episodes, derivatives within episodes, and the
  PCA dimensions that keep 98 % of their variance, where Ω is measured (column ``pca_dims``,
  :func:`~.icub.omega_and_dims`; empty for a synthetic context, which is not reduced).

The ``level`` column orders the contexts by learnability for analyses against it (the
Goldilocks curve, :mod:`neurocur.analysis.stats.goldilocks`): the dense rank of Ω, where a
redrawn source counts as Ω = 1. It has no fixed slowest direction to converge to: the
expected derivative covariance of its whitened signal is isotropic, so the Ω of the
process is 1, while a finite sample of it measures below 1 by sampling error alone
(white noise: about 0.993 per draw).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from .base import World

__all__ = ["LEARNABILITY_COLUMNS", "learnability"]

LEARNABILITY_COLUMNS = ("context", "context_name", "source", "redrawn", "omega", "omega_draw_mean",
                        "omega_draw_min", "omega_draw_max", "pca_dims", "level")


def learnability(world: World, eta: float = 0.05, *, draws: int = 10, seed=0,
                 contexts: Sequence[str] | None = None) -> pd.DataFrame:
    """Ω of each context of ``world`` (reset first), one row per context (all, or the names in
    ``contexts``); columns :data:`LEARNABILITY_COLUMNS` (the ``omega_draw_*`` columns equal
    ``omega`` for a source that is not redrawn). ``draws`` and ``seed``: the fresh draws of a
    redrawn source. A world that is neither synthetic nor episodic is a ``ValueError``.

    Parameters
    ----------
    world : World
        A synthetic world (with ``omega`` and ``redraws``) or an episodic one (with ``episodes``, the
        iCub), already reset: the contexts of its current run are measured.
    eta : float
        The MCA learning rate η of Ω (eq 40), in (0, 0.5].
    draws : int
        The fresh draws of a redrawn source whose joined frames give its Ω.
    seed : int or numpy.random.SeedSequence
        Seed of the generator of those draws (``numpy.random.default_rng(seed)``; the world's own
        stream is left alone).
    contexts : sequence of str, optional
        The context names to measure, in the table's order (default: all, in the world's order); an
        unknown name is a ``ValueError``.

    Returns
    -------
    pandas.DataFrame
        One row per context, columns ``LEARNABILITY_COLUMNS``.
    """
    names = list(world.context_names) if contexts is None else list(contexts)
    rows = []
    for name in names:
        if name not in world.context_names:
            raise ValueError(f"unknown context {name!r}; expected one of {', '.join(world.context_names)}")
        index = world.context_names.index(name)
        redrawn, dims = False, None
        if hasattr(world, "redraws"):  # synthetic: one frame sequence per context (or per draw)
            value, per_draw = world.omega(index, eta, draws=draws, seed=seed)
            redrawn = world.redraws(index)
        elif hasattr(world, "episodes"):  # episodic (iCub): derivatives within episodes only
            from .icub import omega_and_dims

            value, dims = omega_and_dims(world.episodes(index), eta)
            per_draw = np.array([value])
        else:
            raise ValueError(f"Omega needs the frames of each context; {type(world).__name__} does not expose them")
        rows.append({"context": index, "context_name": name, "source": world.source_names[index],
                     "redrawn": redrawn, "omega": value, "omega_draw_mean": per_draw.mean(),
                     "omega_draw_min": per_draw.min(), "omega_draw_max": per_draw.max(), "pca_dims": dims})
    table = pd.DataFrame(rows, columns=LEARNABILITY_COLUMNS[:-1])
    table["pca_dims"] = table["pca_dims"].astype("Int64")
    cost = table["omega"].where(~table["redrawn"], 1.0)
    table["level"] = cost.rank(method="dense").astype(np.int64)
    return table
