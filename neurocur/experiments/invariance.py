"""The invariance demonstration of section 4.1.5 (paper Figure 5), from a TOML file to its result.

An invariance file (``neurocur/experiments_data/invariance.toml``)::

    name = "invariance"
    source = "S-A"            # a built-in source (S-A, S-B, S-C, S-D)
    epochs = 30               # passes of IncSFA over the source's frames
    seed = 2013
    normalise = "global"      # or "image"
    [incsfa]                  # neurocur.learn.incsfa.IncSFA parameters (not random_state)
    n_components = 2
    mca_rate = 0.05

:func:`load_invariance` validates it (a :class:`~neurocur.config.ConfigError` names the
file and key), :meth:`InvarianceSpec.run` calls :func:`invariance_demo`, and
:func:`write_invariance` runs it and saves ``invariance.json`` (the spec, ``corr`` and
``quality``). Figure 5 A–F is :func:`neurocur.analysis.figures.invariance.fig_invariance`
(``neurocur invariance`` draws it beside the JSON).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from neurocur.config import ConfigError, describe
from neurocur.config.checks import check_positive_int
from neurocur.contexts.sources import LEARNABLE, SLOW_DIM, UNLEARNABLE
from neurocur.contexts.synthetic import NORMALISATIONS, SyntheticWorld, mix_frames
from neurocur.learn.correlation import abs_corr
from neurocur.learn.incsfa import IncSFA
from neurocur.results.safeio import atomic_text
from neurocur.tables import check_keys, load_toml, require, resolve_file

__all__ = ["InvarianceDemo", "InvarianceSpec", "invariance_demo", "load_invariance", "write_invariance"]

KEYS = ("name", "description", "source", "epochs", "seed", "normalise", "incsfa")
INCSFA_KEYS = tuple(k for k in IncSFA().get_params() if k != "random_state")
RESULT = "invariance.json"


@dataclass(frozen=True)
class InvarianceDemo:
    """Result of :func:`invariance_demo` (paper Figure 5), arrays of length n_steps.

    Parameters
    ----------
    source : array
        The learned driving force (5A).
    frames : array
        Its frames (5B).
    output : array
        The first (slowest) feature on them (5C).
    noisy_source : array
        The source with dimension 1 replaced by noise (5D).
    noisy_frames : array
        Its frames (5E).
    noisy_output : array
        The first feature on the noisy frames (5F).
    corr : float
        The correlation of ``output`` and ``noisy_output``.
    quality : float
        |corr| of ``output`` with the slow source dimension.
    """

    source: np.ndarray
    frames: np.ndarray
    output: np.ndarray
    noisy_source: np.ndarray
    noisy_frames: np.ndarray
    noisy_output: np.ndarray
    corr: float
    quality: float


def invariance_demo(source: str = "S-A", *, epochs: int = 30, seed=0, normalise: str = "global",
                    **incsfa_params) -> InvarianceDemo:
    """Section 4.1.5 / Figure 5: a learned slow feature is invariant to the other source dimension.

    IncSFA (``n_components=2`` by default, other parameters as given) learns from
    ``epochs`` passes over one context's frames; then source dimension 1 (the fast one)
    is replaced by uniform noise over its range and the frames are rendered again
    with the *same* mixing (and, globally normalised, the same limits, so a few noisy
    pixels may leave [0, 1] slightly). The first feature's output should not change.

    Global normalisation is the default: per-image scaling (``normalise="image"``)
    divides every pixel by a quantity that depends on both source dimensions, so the
    frames are no longer linear in the source and the invariance is only approximate.

    Parameters
    ----------
    source : str
        The paper's source learned (``"S-A"`` ...).
    epochs : int
        The passes over the context's frames.
    seed : int or numpy.random.Generator
        The world's and IncSFA's seed.
    normalise : str
        ``"global"`` or ``"image"``.
    **incsfa_params
        Further :class:`~neurocur.learn.incsfa.IncSFA` parameters.

    Returns
    -------
    InvarianceDemo
        The arrays of Figure 5, ``corr`` and ``quality``.
    """
    epochs = check_positive_int(epochs, "epochs")
    world = SyntheticWorld([source], normalise=normalise, clock_offsets="zero")
    world.reset(seed=seed)
    frames = world.context_frames(0)
    params = {"n_components": 2, "random_state": np.random.default_rng(seed)} | incsfa_params
    sfa = IncSFA(**params)
    for epoch in range(epochs):
        sfa.partial_fit(frames, continues=epoch > 0)
    signal = world.source_signal(source)
    noisy = signal.copy()
    low, high = signal[:, 1].min(), signal[:, 1].max()
    noisy[:, 1] = world.np_random.uniform(low, high, size=len(noisy))
    noisy_frames, _ = mix_frames(noisy, world.mixing(source), normalise, limits=world.normalisation_limits(source))
    output = sfa.transform(frames)[:, 0]
    noisy_output = sfa.transform(noisy_frames)[:, 0]
    return InvarianceDemo(
        source=signal,
        frames=frames,
        output=output,
        noisy_source=noisy,
        noisy_frames=noisy_frames,
        noisy_output=noisy_output,
        corr=float(np.corrcoef(output, noisy_output)[0, 1]),
        quality=abs_corr(output, signal[:, SLOW_DIM]),
    )


@dataclass(frozen=True)
class InvarianceSpec:
    """A validated invariance file: the arguments of :func:`invariance_demo`.

    Parameters
    ----------
    name : str
        The demo's name (the file's, else its stem).
    description : str
        What it shows.
    source : str
        The paper's source learned.
    epochs : int
        The passes over the context's frames.
    seed : int
        The world's and IncSFA's seed.
    normalise : str
        ``"global"`` or ``"image"``.
    incsfa : dict
        Further IncSFA parameters.
    """

    name: str
    description: str
    source: str
    epochs: int
    seed: int
    normalise: str
    incsfa: dict

    def run(self) -> InvarianceDemo:
        return invariance_demo(self.source, epochs=self.epochs, seed=self.seed, normalise=self.normalise,
                               **self.incsfa)


def load_invariance(path) -> InvarianceSpec:
    """Read and validate an invariance file (see the module docstring).

    Parameters
    ----------
    path : path or str
        The invariance file, or the name of one shipped in ``neurocur/experiments_data/``
        (``"invariance"``; ``neurocur.tables.resolve_file``, as for experiments).

    Returns
    -------
    InvarianceSpec
        The validated file.
    """
    path = resolve_file(path, Path(), "invariance", source=path, key=None)
    data = load_toml(path)
    check_keys(data, KEYS, source=path, required=("source",))
    text = dict(source=path, expected="a string")
    name = require(data, "name", str, default=path.stem, **text)
    description = require(data, "description", str, default="", **text)
    sources = LEARNABLE + UNLEARNABLE
    source = require(data, "source", str, source=path, expected=f"one of {', '.join(sources)}")
    if source not in sources:
        raise ConfigError(path, "source", f"one of the built-in sources {', '.join(sources)}", describe(source))
    epochs = require(data, "epochs", int, source=path, expected="a positive integer", default=30)
    if epochs < 1:
        raise ConfigError(path, "epochs", "a positive integer", describe(epochs))
    seed = require(data, "seed", int, source=path, expected="an integer >= 0", default=0)
    if seed < 0:
        raise ConfigError(path, "seed", "an integer >= 0", describe(seed))
    normalise = require(data, "normalise", str, source=path, default="global",
                        expected=" or ".join(map(repr, NORMALISATIONS)))
    if normalise not in NORMALISATIONS:
        raise ConfigError(path, "normalise", " or ".join(map(repr, NORMALISATIONS)), describe(normalise))
    incsfa = require(data, "incsfa", dict, source=path, default={}, expected="a table of IncSFA parameters")
    check_keys(incsfa, INCSFA_KEYS, source=path, prefix="incsfa")
    for key, value in incsfa.items():
        try:
            IncSFA(**{key: value}).validate_params()
        except (TypeError, ValueError) as exc:
            raise ConfigError(path, f"incsfa.{key}", f"a valid IncSFA parameter ({exc})", describe(value)) from None
    try:
        IncSFA(**incsfa).validate_params()
    except ValueError as exc:
        raise ConfigError(path, "incsfa", "consistent IncSFA parameters", f"an error: {exc}") from None
    return InvarianceSpec(name, description, source, epochs, seed, normalise, dict(incsfa))


def write_invariance(spec: InvarianceSpec, out_dir) -> tuple[InvarianceDemo, Path]:
    """Run ``spec`` and write ``invariance.json`` (the spec, ``corr`` and ``quality``) into ``out_dir``.

    Parameters
    ----------
    spec : InvarianceSpec
        The demo.
    out_dir : path
        The output folder (created if needed).

    Returns
    -------
    (InvarianceDemo, path)
        The demo's result and the JSON file written.
    """
    demo = spec.run()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    result = out / RESULT
    payload = {**asdict(spec), "corr": demo.corr, "quality": demo.quality}
    atomic_text(result, json.dumps(payload, indent=2) + "\n")  # whole, and no link followed
    return demo, result
