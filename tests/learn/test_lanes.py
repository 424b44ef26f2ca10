"""The SIMD ``dot4`` of the exact kernels keeps the scalar summation order to the bit."""

import numpy as np
import pytest

from neurocur.learn._kernels import dot4


def two_lane_sums(v, r, x):
    """The order ``dot4`` defines, in plain Python floats (IEEE double, no fused multiply-add):
    even and odd indices summed separately in order, an odd last element joining the even sum."""
    sums = [[0.0, 0.0] for _ in range(4)]
    n = len(v)
    for d in range(n):
        lane = d % 2 if d < n - n % 2 else 0
        for acc, (p, q) in zip(sums, ((v[d], r[d]), (r[d], r[d]), (v[d], x[d]), (r[d], x[d]))):
            acc[lane] += float(p) * float(q)
    return tuple(a + b for a, b in sums)


@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 7, 64, 7499, 7500])
def test_dot4_equals_the_two_lane_order_bitwise(n):
    rng = np.random.default_rng(n)
    # magnitudes over ten decades, so any reordering of the sums would show in the last bits
    v, r, x = rng.standard_normal((3, n)) * 10.0 ** rng.integers(-5, 6, (3, n))
    got = dot4(np.ascontiguousarray(v), np.ascontiguousarray(r), np.ascontiguousarray(x))
    assert got == two_lane_sums(v, r, x)


def test_a_reordered_sum_differs():
    """The data above tell orders apart: one sequential sum differs from the two-lane one."""
    rng = np.random.default_rng(7500)
    v, r, x = rng.standard_normal((3, 7500)) * 10.0 ** rng.integers(-5, 6, (3, 7500))
    sequential = 0.0
    for a, b in zip(v, r):
        sequential += float(a) * float(b)
    assert sequential != dot4(v, r, x)[0]
