"""The invariance demonstration of section 4.1.5 (paper Figure 5), from a TOML file to a figure.

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
file and key), :meth:`InvarianceSpec.run` calls
:func:`invariance_demo`, :func:`fig_invariance` draws
Figure 5 A–F and :func:`write_invariance` saves ``invariance.png`` and
``invariance.json`` (the spec, ``corr`` and ``quality``).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from neurocur.analysis.style import figure, style
from neurocur.config import ConfigError, describe
from neurocur.config.checks import check_positive_int
from neurocur.contexts.sources import LEARNABLE, SLOW_DIM, UNLEARNABLE
from neurocur.contexts.synthetic import NORMALISATIONS, SyntheticWorld, mix_frames
from neurocur.learn.correlation import abs_corr
from neurocur.learn.incsfa import IncSFA
from neurocur.tables import check_keys, load_toml, require

__all__ = ["InvarianceDemo", "InvarianceSpec", "invariance_demo", "load_invariance", "fig_invariance",
           "write_invariance"]

KEYS = ("name", "description", "source", "epochs", "seed", "normalise", "incsfa")
INCSFA_KEYS = tuple(k for k in IncSFA().get_params() if k != "random_state")
FIGURE, RESULT = "invariance.png", "invariance.json"


@dataclass(frozen=True)
class InvarianceDemo:
    """Result of :func:`invariance_demo` (paper Figure 5), arrays of length n_steps.

    ``source``/``frames``: the learned driving force and its frames (5A, 5B);
    ``output``: the first (slowest) feature on them (5C); ``noisy_source``/
    ``noisy_frames``: the same with dimension 1 replaced by noise (5D, 5E);
    ``noisy_output``: the first feature on the noisy frames (5F); ``corr``: their
    correlation; ``quality``: |corr| of ``output`` with the slow source dimension.
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
    """A validated invariance file: the arguments of :func:`invariance_demo`."""

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
    """Read and validate an invariance file (see the module docstring)."""
    path = Path(path)
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
            IncSFA(**{key: value})
        except (TypeError, ValueError) as exc:
            raise ConfigError(path, f"incsfa.{key}", f"a valid IncSFA parameter ({exc})", describe(value)) from None
    try:
        IncSFA(**incsfa)
    except ValueError as exc:
        raise ConfigError(path, "incsfa", "consistent IncSFA parameters", f"an error: {exc}") from None
    return InvarianceSpec(name, description, source, epochs, seed, normalise, dict(incsfa))


def fig_invariance(demo: InvarianceDemo, *, frame_shape=None, n_frames: int = 4) -> Figure:
    """Figure 5 A–F: source, frames, first feature; noisy source, noisy frames, feature after the swap.

    ``frame_shape`` (height, width) defaults to the square the frames' pixel count
    makes; ``n_frames`` evenly spaced frames are shown side by side in B and E.
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
    return fig


def write_invariance(spec: InvarianceSpec, out_dir, *, dpi: int = 120) -> tuple[InvarianceDemo, list[Path]]:
    """Run ``spec`` and write ``invariance.png`` (Figure 5) and ``invariance.json`` into ``out_dir``."""
    demo = spec.run()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    png, result = out / FIGURE, out / RESULT
    fig_invariance(demo).savefig(png, dpi=dpi)
    payload = {**asdict(spec), "corr": demo.corr, "quality": demo.quality}
    result.write_text(json.dumps(payload, indent=2) + "\n", encoding="utf-8")
    return demo, [png, result]
