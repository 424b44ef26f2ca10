"""The opt-in float32 fast path of IncSFA (``IncSFA(dtype="float32")``).

``incsfa_fit_fast`` is ``incsfa_fit`` compiled again from the same source with LLVM's
fast-math flags ``FAST_MATH`` (reassociation and contraction, so the sums vectorise and
multiply-adds fuse), with CCIPCA's passes ``sums``/``update_sums`` replaced by plain
one-accumulator loops in float32 that the compiler splits into SIMD lanes itself, and
the update of component i fused with the sums of component i + 1 (K + 1 passes over
the frame instead of 2K). IncSFA uses it for ``dtype="float32"``: the directions, the
residual and the derivative are stored in float32 and the D-length passes compute in
float32; the mean, the eigenvalues, the whitening and CIMCA stay in float64. Its
results differ from ``incsfa_fit``'s by float32 round-off (about 1e-7 relative) in every
pass, and so drift apart over a run; it is never the default.
"""

from __future__ import annotations

import types

import numpy as np
from numba import njit

from . import _kernels

#: LLVM fast-math flags of the fast path: no ``nnan``/``ninf``, so tests for NaN,
#: infinity and zero stay exact
FAST_MATH = {"reassoc", "contract", "nsz", "arcp"}


@njit(cache=True, fastmath=FAST_MATH)
def plain_sums(row, res, dx, project):
    """``sums`` as plain float32 sums, for the fast path (the compiler orders them)."""
    a = b = c = e = np.float32(0.0)
    if project:
        for d in range(res.shape[0]):
            r = res[d]
            a += row[d] * r
            b += r * r
            c += row[d] * dx[d]
            e += r * dx[d]
    else:
        for d in range(res.shape[0]):
            r = res[d]
            a += row[d] * r
            b += r * r
    return a, b, c, e


@njit(cache=True, fastmath=FAST_MATH)
def fused_update_sums(row, res, a, b, inv, c, nxt, dx, project, more):
    """``update_sums`` in one pass and in float32: the next component's sums are taken
    as r is deflated; the update is written row ← (a/‖·‖) row + (b/‖·‖) r."""
    a, b, c = np.float32(a * inv), np.float32(b * inv), np.float32(c)
    s0 = s1 = s2 = s3 = np.float32(0.0)
    if not more:
        for d in range(res.shape[0]):
            v = a * row[d] + b * res[d]
            row[d] = v
            res[d] -= c * v
    elif project:
        for d in range(res.shape[0]):
            v = a * row[d] + b * res[d]
            row[d] = v
            r = res[d] - c * v
            res[d] = r
            w, x = nxt[d], dx[d]
            s0 += w * r
            s1 += r * r
            s2 += w * x
            s3 += r * x
    else:
        for d in range(res.shape[0]):
            v = a * row[d] + b * res[d]
            row[d] = v
            r = res[d] - c * v
            res[d] = r
            s0 += nxt[d] * r
            s1 += r * r
    return s0, s1, s2, s3


def _fast_math_twin(names, replace):
    """Recompile the kernels ``names`` (callees first) with ``FAST_MATH``; return the last.

    Each twin is built from the same Python code with globals in which the earlier twins
    and ``replace`` stand for the originals, and gets its own qualified name, so that
    numba's on-disk cache keeps it apart from the exact kernel.
    """
    scope = {**vars(_kernels), **replace}
    for name in names:
        exact = getattr(_kernels, name).py_func
        twin = types.FunctionType(exact.__code__, scope, name, exact.__defaults__)
        twin.__qualname__ = f"{name}_fast_math"
        twin.__doc__ = exact.__doc__
        scope[name] = njit(cache=True, fastmath=FAST_MATH)(twin)
    return scope[names[-1]]


incsfa_fit_fast = _fast_math_twin(
    ("amnesic_rate", "ccipca_step", "active_mask", "cimca_step", "incsfa_fit"),
    {"sums": plain_sums, "update_sums": fused_update_sums},
)
