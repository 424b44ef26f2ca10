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
"""

from __future__ import annotations

import numpy as np

from neurocur.learn._validation import check_positive_int, check_random_state

__all__ = [
    "SLOW_DIM",
    "N_STEPS",
    "PAPER_FAST_CYCLES",
    "LEARNABLE",
    "UNLEARNABLE",
    "sinusoid_pair",
    "isotropic_random_walk",
    "paper_source",
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
    """``[sin(2π·slow·t/n), cos(2π·fast·t/n)]`` for t = 0..n−1, shape (n, 2); dim 0 is slow."""
    n_steps = check_positive_int(n_steps, "n_steps")
    fast_cycles = check_positive_int(fast_cycles, "fast_cycles")
    slow_cycles = check_positive_int(slow_cycles, "slow_cycles")
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
    """
    rng = check_random_state(random_state)
    n_steps = check_positive_int(n_steps, "n_steps")
    if n_steps < 8:
        raise ValueError(f"n_steps must be at least 8 for a random walk source; got {n_steps}")
    k = np.arange(1, n_steps // 2, dtype=np.float64)
    coef = (rng.standard_normal(k.size) + 1j * rng.standard_normal(k.size)) / k
    spectrum = np.zeros(n_steps, dtype=np.complex128)
    spectrum[1 : k.size + 1] = coef
    z = np.fft.ifft(spectrum) * n_steps
    walk = np.column_stack([z.real, z.imag])
    return walk / walk.std(axis=0)


def paper_source(name: str, random_state=None, n_steps: int = N_STEPS) -> np.ndarray:
    """The paper's source ``name`` ("S-A", "S-B", "S-C" or "S-D"), shape (n_steps, 2).

    Only S-D uses ``random_state`` (it is drawn per run).
    """
    if name in PAPER_FAST_CYCLES:
        return sinusoid_pair(PAPER_FAST_CYCLES[name], n_steps)
    if name == "S-D":
        return isotropic_random_walk(random_state, n_steps)
    raise ValueError(f"unknown built-in source {name!r}; expected one of {', '.join(LEARNABLE + UNLEARNABLE)}")
