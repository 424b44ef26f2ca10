"""Driving forces ("sources") of the synthetic world (paper section 4.1, Figure 4A).

A source is a float64 array of shape ``(n_steps, n_dims)``: rows are the local time
steps of a context (1000 in the paper, replayed cyclically), columns the dimensions
of the driving force (two in the paper).

**Dimension 0 is the slow dimension** of every learnable source: it is what the
slowest feature of a well-learned module should extract, and what the analysis
scores a module's quality against (``SLOW_DIM``).

The paper's sources:

* S-A, S-B, S-C (learnable): ``[sin(2π t/1000), cos(2π k t/1000)]`` with k = 57, 24
  and 12 fast cycles per 1000 steps. Their learning cost Ω (eq 15/40) at η = 0.05 is
  0.99332, 0.99881 and 0.99970, the paper's 0.9933, 0.9988 and 0.9997. The fast
  dimension is a cosine (not a sine) so that no time step has both dimensions at
  zero (a blank frame that could not be value-normalised on its own).
* S-D (unlearnable): an irregular *isotropic random walk*, drawn per run by
  :func:`isotropic_random_walk`. Its two dimensions are the real and imaginary parts
  of a closed complex random walk (random Fourier coefficients with amplitude ∝ 1/k,
  k = 1..n/2−1). Such a pair is exactly as slow in every direction of the plane:
  the derivative of its whitened signal has two equal eigenvalues, so Ω = 1 (up
  to the one wrap-around step), the white-noise value of section 4.1.1. IncSFA
  therefore has no unique slowest direction to converge to, and its features keep
  wandering with each visit's local statistics: unlearnable, while the signal
  itself changes irregularly. (i.i.d. white noise would not do: with 1000 samples
  its two derivative eigenvalues differ by sampling error and Ω ≈ 0.994, as cheap
  as S-A.)

Noise kinds (:data:`NOISE_KINDS`, :func:`noise_source`), the built-in noise of an
experiment file's ``[world.sources]`` (:mod:`.user_sources`):

* ``"white"``: i.i.d. standard normal samples, :func:`white_noise`;
* ``"random_walk"``: cumulative standard normal steps, :func:`random_walk` (not closed:
  the wrap from the last step back to the first is a jump);
* ``"isotropic_walk"``: the closed isotropic walk of S-D, :func:`isotropic_random_walk`
  (two dimensions only).

The expected derivative covariance of the whitened signal of each is isotropic, so Ω of the
process is 1; a finite draw has an Ω below 1 by sampling error (white noise: about 0.994
for 1000 steps and two dimensions), which is why noise is redrawn every epoch.

:func:`graded_sinusoids` picks sinusoid pairs of graded learnability (a Goldilocks
family, from trivially easy to practically unlearnable) by their Ω.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from neurocur.config.checks import check_positive_int, check_random_state
from neurocur.learn.omega import omega

__all__ = [
    "SLOW_DIM",
    "N_STEPS",
    "PAPER_FAST_CYCLES",
    "LEARNABLE",
    "UNLEARNABLE",
    "sinusoid_pair",
    "isotropic_random_walk",
    "paper_source",
    "NOISE_KINDS",
    "white_noise",
    "random_walk",
    "noise_source",
    "graded_sinusoids",
]

SLOW_DIM = 0
"""Column of a learnable source holding its slow dimension (one cycle per 1000 steps)."""

N_STEPS = 1000
"""Local time steps per source (the length of one epoch)."""

PAPER_FAST_CYCLES = {"S-A": 57, "S-B": 24, "S-C": 12}
"""Fast-dimension cycles per epoch of the learnable sources (their slow dimension has one)."""

LEARNABLE = tuple(PAPER_FAST_CYCLES)
UNLEARNABLE = ("S-D",)


def sinusoid_pair(fast_cycles: int, n_steps: int = N_STEPS, slow_cycles: int = 1) -> np.ndarray:
    """``[sin(2π·slow·t/n), cos(2π·fast·t/n)]`` for t = 0..n−1, shape (n, 2); dim 0 is slow.

    Parameters
    ----------
    fast_cycles : int
        The cycles of dim 1 over the n steps.
    n_steps : int
        The samples (one pass of a context's local clock).
    slow_cycles : int
        The cycles of dim 0 over the n steps.

    Returns
    -------
    array of shape (n_steps, 2)
        The source.
    """
    n_steps = check_positive_int(n_steps, "n_steps", source="sinusoid_pair")
    fast_cycles = check_positive_int(fast_cycles, "fast_cycles", source="sinusoid_pair")
    slow_cycles = check_positive_int(slow_cycles, "slow_cycles", source="sinusoid_pair")
    if fast_cycles <= slow_cycles:
        raise ValueError(f"fast_cycles must exceed slow_cycles={slow_cycles}; got {fast_cycles}")
    phase = 2.0 * np.pi * np.arange(n_steps, dtype=np.float64) / n_steps
    return np.column_stack([np.sin(slow_cycles * phase), np.cos(fast_cycles * phase)])


def isotropic_random_walk(random_state=None, n_steps: int = N_STEPS) -> np.ndarray:
    """An irregular 2-d closed random walk with equal slowness in every direction, (n, 2).

    Complex Fourier coefficients ``c_k ~ CN(0, 1) / k`` for k = 1..n/2−1 (positive
    frequencies only, an analytic signal) give ``z(t) = Σ c_k e^{2πikt/n}``; the source
    is ``[Re z, Im z]`` scaled to unit variance per dimension. Because only positive
    frequencies are present, the two columns and their circular differences have
    equal variances and zero covariance exactly, so the whitened derivative's
    eigenvalues are equal (Ω = 1 in eq 40) and no direction is slower than another.

    Parameters
    ----------
    random_state : int or numpy.random.Generator or None
        The draw's seed or generator.
    n_steps : int
        The samples (one pass of a context's local clock).

    Returns
    -------
    array of shape (n_steps, 2)
        The walk.
    """
    rng = check_random_state(random_state, source="isotropic_random_walk")
    n_steps = check_positive_int(n_steps, "n_steps", source="isotropic_random_walk")
    if n_steps < 8:
        raise ValueError(f"n_steps must be at least 8 for a random walk source; got {n_steps}")
    k = np.arange(1, n_steps // 2, dtype=np.float64)
    coef = (rng.standard_normal(k.size) + 1j * rng.standard_normal(k.size)) / k
    spectrum = np.zeros(n_steps, dtype=np.complex128)
    spectrum[1 : k.size + 1] = coef
    z = np.fft.ifft(spectrum) * n_steps
    walk = np.column_stack([z.real, z.imag])
    return walk / _column_std(walk)


@njit(cache=True)
def _column_std(a):  # pragma: no cover - compiled
    """``a.std(axis=0)`` of a C-contiguous (n, d) array with d > 1, bit-identical: numpy sums each
    column row by row (the mean, then the squared deviations) and divides by n."""
    n, d = a.shape
    mean, var = a[0].copy(), np.empty(d)
    for t in range(1, n):
        for f in range(d):
            mean[f] += a[t, f]
    for f in range(d):
        mean[f] = mean[f] / n
        dev = a[0, f] - mean[f]
        var[f] = dev * dev
    for t in range(1, n):
        for f in range(d):
            dev = a[t, f] - mean[f]
            var[f] += dev * dev
    for f in range(d):
        var[f] = np.sqrt(var[f] / n)
    return var


def paper_source(name: str, random_state=None, n_steps: int = N_STEPS) -> np.ndarray:
    """The paper's source ``name`` ("S-A", "S-B", "S-C" or "S-D"), shape (n_steps, 2).

    Only S-D uses ``random_state`` (it is drawn per run).

    Parameters
    ----------
    name : str
        ``"S-A"``, ``"S-B"``, ``"S-C"`` or ``"S-D"``.
    random_state : int or numpy.random.Generator or None
        The draw's seed or generator.
    n_steps : int
        The samples (one pass of a context's local clock).

    Returns
    -------
    array of shape (n_steps, 2)
        The source.
    """
    if name in PAPER_FAST_CYCLES:
        return sinusoid_pair(PAPER_FAST_CYCLES[name], n_steps)
    if name == "S-D":
        return isotropic_random_walk(random_state, n_steps)
    raise ValueError(f"unknown built-in source {name!r}; expected one of {', '.join(LEARNABLE + UNLEARNABLE)}")

NOISE_KINDS = ("white", "random_walk", "isotropic_walk")
"""The built-in noise kinds of :func:`noise_source`."""


def white_noise(random_state=None, n_steps: int = N_STEPS, dims: int = 2) -> np.ndarray:
    """i.i.d. standard normal samples, shape (n_steps, dims).

    Parameters
    ----------
    random_state : int or numpy.random.Generator or None
        The draw's seed or generator.
    n_steps : int
        The samples (one pass of a context's local clock).
    dims : int
        The dimensions.

    Returns
    -------
    array of shape (n_steps, dims)
        The draw.
    """
    rng = check_random_state(random_state, source="white_noise")
    shape = (check_positive_int(n_steps, "n_steps", source="white_noise"),
             check_positive_int(dims, "dims", source="white_noise"))
    return rng.standard_normal(shape)


def random_walk(random_state=None, n_steps: int = N_STEPS, dims: int = 2) -> np.ndarray:
    """Cumulative standard normal steps, shape (n_steps, dims); row 0 is the first step.

    Parameters
    ----------
    random_state : int or numpy.random.Generator or None
        The draw's seed or generator.
    n_steps : int
        The samples (one pass of a context's local clock).
    dims : int
        The dimensions.

    Returns
    -------
    array of shape (n_steps, dims)
        The draw.
    """
    return np.cumsum(white_noise(random_state, n_steps, dims), axis=0)


def noise_source(kind: str, random_state=None, n_steps: int = N_STEPS, dims: int = 2) -> np.ndarray:
    """One draw of the noise ``kind`` (one of :data:`NOISE_KINDS`), shape (n_steps, dims).

    ``"isotropic_walk"`` is :func:`isotropic_random_walk` and has two dimensions only.

    Parameters
    ----------
    kind : str
        One of :data:`NOISE_KINDS`.
    random_state : int or numpy.random.Generator or None
        The draw's seed or generator.
    n_steps : int
        The samples (one pass of a context's local clock).
    dims : int
        The dimensions.

    Returns
    -------
    array of shape (n_steps, dims)
        The draw.
    """
    if kind == "white":
        return white_noise(random_state, n_steps, dims)
    if kind == "random_walk":
        return random_walk(random_state, n_steps, dims)
    if kind == "isotropic_walk":
        if dims != 2:
            raise ValueError(f"an isotropic walk has 2 dimensions; got dims={dims!r}")
        return isotropic_random_walk(random_state, n_steps)
    raise ValueError(f"unknown noise kind {kind!r}; expected one of {', '.join(NOISE_KINDS)}")


def graded_sinusoids(targets, eta: float = 0.05, n_steps: int = N_STEPS) -> dict[int, float]:
    """Sinusoid pairs whose Ω (eq 40, MCA rate ``eta``) is nearest each target Ω.

    Ω of :func:`sinusoid_pair` rises towards 1 as its fast-cycle count k falls (about
    1 − 2·10⁻⁶ (k² − 1) at η = 0.05 over 1000 steps), so each target picks the k in
    2..n_steps/2 − 1 whose Ω is closest. Returns ``{k: Ω}``, k descending (easiest first);
    a k chosen for two targets is listed once.

    Parameters
    ----------
    targets : sequence of float
        The target Ω values.
    eta : float
        The MCA rate of eq 40.
    n_steps : int
        The samples (one pass of a context's local clock).

    Returns
    -------
    dict of int to float
        ``{k: Ω}``, k descending.
    """
    cycles = np.arange(2, n_steps // 2)
    values = np.array([omega(sinusoid_pair(int(k), n_steps), eta) for k in cycles])
    chosen = {int(cycles[np.argmin(np.abs(values - t))]) for t in targets}
    return {k: float(values[k - 2]) for k in sorted(chosen, reverse=True)}
