"""The synthetic world's declared sources (``[world.sources]``): files, sinusoid pairs and noise.

Each entry of an experiment file's ``[world.sources]`` table names a driving force (a
*source*, :mod:`.sources`) that contexts may show (``contexts = [...]``)::

    [world.sources]
    S-X = "data/x.npy"                                   # a file, replayed every epoch
    S-Y = { file = "data/y.npy", nonstationary = true }  # a file re-sampled every epoch
    G3  = { sinusoid = 24 }                              # a sinusoid pair, 24 fast cycles per epoch
    TV  = { noise = "white", scale = 1.0, dims = 2 }     # noise, redrawn every epoch

An entry (:class:`SourceParams`) gives exactly one of ``file`` (a ``.npy`` array, rows are
time, column :data:`~.sources.SLOW_DIM` the slow dimension; a plain path is the short form),
``sinusoid`` (:func:`~.sources.sinusoid_pair` with that many fast cycles per epoch) or
``noise`` (a kind of :data:`~.sources.NOISE_KINDS`: ``"white"``, ``"random_walk"``,
``"isotropic_walk"``). ``scale`` (> 0, default 1) and ``dims`` (>= 2, default 2; an
isotropic walk has 2) belong to noise only: ``scale`` is the standard deviation of a white
sample, of a random-walk step, and of each dimension of an isotropic walk. The frames of a
source are normalised to [0, 1] (``normalise``), so ``scale`` changes the source signal
(:meth:`~.synthetic.SyntheticWorld.source_signal`), not the frames. A name equal to a
built-in source (S-A, S-B, S-C, S-D) replaces it.

**Noise frames.** Each draw of a declared noise source is centred (every dimension's mean
over the epoch removed) and, under ``normalise = "global"``, rendered with the symmetric
limits ``±max|raw|``, so every draw's frames are centred on 0.5. Min–max limits per draw
(as the built-in S-D keeps, the paper's reading) shift the frames' mean level from one draw
to the next: along the constant image, a direction outside the mixing's span that is
constant within an epoch and so perfectly slow. Joined over draws, white noise rendered
that way has Ω ≈ 0.897 (a slow direction to learn, though it says nothing about the
noise); centred, Ω of the draws joined is 0.998 (10 draws; 1 for the process). For the
built-in S-D the effect is small (0.9994 joined, 1.0000 per draw: :meth:`.synthetic.SyntheticWorld.omega`).

**Redrawn every epoch.** An epoch of a context is one pass of its local clock over the
source's time steps. A source that is redrawn gets a new draw each time the clock of a
context showing it wraps (as the built-in S-D); its frames are rendered with the run's
mixing matrix and normalised again. ``nonstationary`` decides it per source:

- **noise** is redrawn (a fresh draw of its kind) unless ``nonstationary = false``; by
  default it follows the world's ``nonstationary`` flag, as S-D does;
- **a file or a sinusoid pair** is replayed unless ``nonstationary = true``; then every
  epoch, the first included, shows its rows in a fresh uniformly random order (a random
  permutation of the time steps, drawn from the world's generator).

Why a permutation: rows of an i.i.d. process are exchangeable, so a permutation of a
recorded draw is another draw of the same process, conditioned on the same values. The
values' statistics (the whitening, the normalisation limits) stay those of the file,
while the statistics of the temporal derivative, which slow-feature learning follows, are
drawn afresh. Replayed, a file of 1000 i.i.d. rows has derivative eigenvalues that differ
by sampling error (Ω ≈ 0.994, eq 40), a fixed slowest direction that IncSFA converges to
and a module stores; permuted, that direction is a new random one every epoch. A random
circular shift would not do (the shifted sequence has the same derivatives but for the wrap
step), nor would phase randomisation (it keeps each dimension's power spectrum, hence its
derivative variance, and with it the sampling accident). A permutation removes all
temporal order, so a learnable file made non-stationary becomes noise with its values.

By default (``learnable`` not given) a replayed file or sinusoid pair counts as learnable;
noise and re-sampled sources do not.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from neurocur.config import ConfigError, ParamSpec, check_params, describe, param, spec_param
from neurocur.config.checks import check_block, check_nonconstant
from neurocur.config.npy import load_npy

from .sources import LEARNABLE, N_STEPS, NOISE_KINDS, PAPER_FAST_CYCLES, UNLEARNABLE, noise_source, sinusoid_pair

__all__ = ["BUILTIN", "Source", "SourceParams", "check_sources", "load_source", "make_sources"]

#: The built-in source names (section 4.1).
BUILTIN = LEARNABLE + UNLEARNABLE


@dataclass(frozen=True)
class SourceParams:
    """One entry of ``[world.sources]`` (the module docstring); a plain path or array is ``file``.

    Parameters
    ----------
    file : str or array, optional
        A ``.npy`` file (relative to the experiment file) or an array, shape (n_steps, n_dims), rows
        are time.
    sinusoid : int, optional
        A sinusoid pair with this many fast cycles per epoch (at least 2).
    noise : {"white", "random_walk", "isotropic_walk"}, optional
        A noise kind.
    scale : float, optional
        Noise only: the standard deviation (> 0) of a white sample, of a random-walk step, or of each
        dimension of an isotropic walk's step (default 1).
    dims : int, optional
        Noise only: its dimensions (at least 2; default 2, and an isotropic walk has 2).
    nonstationary : bool, optional
        Redrawn (noise) or re-sampled (a file, a sinusoid pair: its rows permuted) every epoch; None:
        noise follows the world's flag, files and sinusoid pairs are replayed.
    """

    file: str | np.ndarray | None = spec_param(None, ParamSpec(str, path=True, optional=True, classes=(np.ndarray,)),
                                               doc=".npy file (relative to the experiment file) or array")
    sinusoid: int | None = param(None, int, low=2, optional=True, doc="a sinusoid pair: fast cycles per epoch")
    noise: str | None = param(None, str, choices=NOISE_KINDS, optional=True, doc="a noise kind")
    scale: float | None = param(None, float, low=0.0, low_open=True, optional=True,
                                doc="noise only: standard deviation of a sample or step (default 1)")
    dims: int | None = param(None, int, low=2, optional=True, doc="noise only: dimensions (default 2)")
    nonstationary: bool | None = param(None, bool, optional=True,
                                       doc="redrawn / re-sampled every epoch (default: noise follows the world's "
                                           "flag, files and sinusoids are replayed)")

    def __post_init__(self):
        check_params(self)


#: The spec of the ``sources`` table: entries of :class:`SourceParams`, a plain path or array as ``file``.
SOURCES_SPEC = ParamSpec.table(ParamSpec.nested(SourceParams, shorthand="file"))


def load_source(value, name: str) -> np.ndarray:
    """A user source: a ``.npy`` file path or an array, checked as (n_steps >= 2, n_dims), finite,
    not constant; a :class:`~neurocur.config.ConfigError` names the source (and file) and what was expected.

    Parameters
    ----------
    value : str or array
        A ``.npy`` file path (written by ``numpy.save``) or an array.
    name : str
        The source's name, for the message.

    Returns
    -------
    array of float64, shape (n_steps, n_dims)
        A read-only copy.

    Raises
    ------
    ConfigError
        A missing or unreadable file, or an array that is not finite, not 2-d with at least two
        rows, or constant.
    """
    label, file = f"source {name!r}", f" in {value}" if isinstance(value, str) else ""
    if isinstance(value, str):
        if not Path(value).is_file():
            raise ConfigError(label, None, "an existing .npy file", f"{value!r} (no such file)")
        try:
            value = load_npy(value)
        except (ValueError, OSError) as exc:
            raise ConfigError(label, None, "a .npy file written by numpy.save", f"{file[4:]!r} ({exc})") from None
    try:
        arr = check_block(value, name=label, min_rows=2)
        check_nonconstant(arr, name=label)
    except ValueError as err:
        raise ConfigError(label, None, "a finite, non-constant array of shape (n_steps, n_dims), rows are time",
                          f"{err}{file}") from None
    arr = arr.copy()
    arr.flags.writeable = False
    return arr


def check_sources(sources: Mapping[str, SourceParams], contexts: Sequence[str], where: str) -> int:
    """Check the declared ``sources`` and the ``contexts`` that show them; return the number of
    time steps (context-states): the common length of the files and built-in sources shown,
    1000 if only sinusoid pairs and noise are. Errors are ConfigErrors naming the key.

    Parameters
    ----------
    sources : mapping of str to SourceParams
        The declared sources by name.
    contexts : sequence of str
        The source shown by each context (and by each after a swap).
    where : str
        The parameter class, named by the errors.

    Returns
    -------
    int
        The number of time steps (context-states).

    Raises
    ------
    ConfigError
        An entry without exactly one of ``file``, ``sinusoid``, ``noise``; ``scale`` or ``dims``
        outside noise; a bad file; an unknown source name in ``contexts``; sources of unequal
        lengths; a sinusoid of at least ``n_states / 2`` fast cycles.
    """
    lengths = {}
    for name, p in sources.items():
        key = f"sources.{name}"
        given = [k for k in ("file", "sinusoid", "noise") if getattr(p, k) is not None]
        if len(given) != 1:
            raise ConfigError(where, key, "exactly one of file, sinusoid or noise", ", ".join(given) or "none")
        if p.noise is None and (p.scale is not None or p.dims is not None):
            raise ConfigError(where, key, "scale and dims only for a noise source", f"a {given[0]} source with them")
        if p.noise == "isotropic_walk" and p.dims not in (None, 2):
            raise ConfigError(where, f"{key}.dims", "2 (an isotropic walk is 2-d)", describe(p.dims))
        if p.file is not None:
            try:
                lengths[name] = load_source(p.file, name).shape[0]
            except ConfigError as exc:
                raise ConfigError(where, key, exc.expected, exc.got) from None
    for name in contexts:
        if name not in sources and name not in BUILTIN:
            known = ", ".join(sorted(set(BUILTIN) | set(sources)))
            raise ConfigError(where, "contexts", f"source names among {known}", f"{name!r} (give it in sources)")
    shown = {name: lengths.get(name, N_STEPS) for name in contexts if name in lengths or name not in sources}
    if len(set(shown.values())) > 1:
        detail = ", ".join(f"{k}: {v}" for k, v in shown.items())
        raise ConfigError(where, "sources", "sources of equal length (rows are time steps)", detail)
    n_states = next(iter(shown.values()), N_STEPS)
    for name in contexts:
        k = sources[name].sinusoid if name in sources else None
        if k is not None and 2 * k >= n_states:
            raise ConfigError(where, f"sources.{name}.sinusoid", f"fewer than {n_states} / 2 fast cycles "
                              f"(the sources have {n_states} time steps)", describe(k))
    return n_states


@dataclass(frozen=True)
class Source:
    """One source of a run of the synthetic world: a fixed ``signal`` (a file, a sinusoid pair,
    S-A, S-B, S-C) or a ``noise`` kind; ``redraws``: drawn again at every epoch (module docstring).

    Parameters
    ----------
    name : str
        The source's name.
    signal : array of float64, shape (n_steps, n_dims), optional
        The fixed signal (a file, a sinusoid pair, S-A, S-B, S-C); None for noise.
    noise : str, optional
        The noise kind (``neurocur.contexts.sources.NOISE_KINDS``) when there is no ``signal``.
    scale : float
        Noise only: the factor on each draw.
    dims : int
        Noise only: its dimensions.
    redraws : bool
        Drawn again at every epoch: a fresh noise draw, or the fixed signal's rows permuted.
    centred : bool
        Each noise draw centred (every dimension's mean removed) and rendered with symmetric limits
        (declared noise; not the built-in S-D).
    """

    name: str
    signal: np.ndarray | None = None
    noise: str | None = None
    scale: float = 1.0
    dims: int = 2
    redraws: bool = False
    #: each draw centred and rendered with symmetric limits (declared noise; not the built-in S-D)
    centred: bool = False

    @property
    def learnable(self) -> bool:
        """A fixed signal, replayed: there is one slowest direction to learn."""
        return self.signal is not None and not self.redraws

    def draw(self, rng: np.random.Generator, n_steps: int) -> np.ndarray:
        """This epoch's signal, (n_steps, n_dims): the fixed signal (its rows permuted if it
        ``redraws``) or a fresh draw of the noise, times ``scale``."""
        if self.signal is None:
            draw = self.scale * noise_source(self.noise, rng, n_steps, self.dims)
            return draw - draw.mean(axis=0) if self.centred else draw
        if self.redraws:
            return self.signal[rng.permutation(len(self.signal))]
        return self.signal


def make_sources(names: Sequence[str], sources: Mapping[str, SourceParams], n_states: int,
                 nonstationary: bool) -> dict[str, Source]:
    """The :class:`Source` of each distinct name in ``names``, declared or built in.

    ``nonstationary`` is the world's flag: S-D and noise without their own flag are redrawn
    every epoch when it is true.

    Parameters
    ----------
    names : sequence of str
        The sources shown, repeats allowed (each distinct name once, in order of first appearance).
    sources : mapping of str to SourceParams
        The declared sources; a name not declared is built in.
    n_states : int
        Time steps of a sinusoid pair (the world's context-states).
    nonstationary : bool
        The world's flag.

    Returns
    -------
    dict of str to Source
        The sources by name.
    """
    out = {}
    for name in dict.fromkeys(names):
        p = sources.get(name)
        if p is None:
            out[name] = (Source(name, signal=sinusoid_pair(PAPER_FAST_CYCLES[name], n_states)) if name in LEARNABLE
                         else Source(name, noise="isotropic_walk", redraws=nonstationary))
        elif p.noise is not None:
            redraws = nonstationary if p.nonstationary is None else p.nonstationary
            out[name] = Source(name, noise=p.noise, scale=p.scale or 1.0, dims=p.dims or 2, redraws=redraws,
                               centred=True)
        else:
            signal = load_source(p.file, name) if p.file is not None else sinusoid_pair(p.sinusoid, n_states)
            out[name] = Source(name, signal=signal, redraws=bool(p.nonstationary))
    return out
