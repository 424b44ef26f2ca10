"""Re-orthonormalising the CCIPCA directions (``orthonormalize``): the kernel is Gram–Schmidt."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.learn._kernels import orthonormalize
from neurocur.learn.ccipca import CCIPCA
from neurocur.learn.incsfa import IncSFA


def test_kernel_is_gram_schmidt_in_order():
    """Same rows as a QR factorisation of the rows (up to sign): orthonormal, nested spans."""
    rng = np.random.default_rng(3)
    dirs = rng.standard_normal((5, 40))
    dirs[3] = dirs[1] + 1e-3 * rng.standard_normal(40)  # nearly parallel rows are the case that matters
    q = np.linalg.qr(dirs.T)[0].T
    out = dirs.copy()
    orthonormalize(out)
    np.testing.assert_allclose(out @ out.T, np.eye(5), atol=1e-12)
    np.testing.assert_allclose(np.abs(np.sum(out * q, axis=1)), 1.0, atol=1e-9)
    np.testing.assert_allclose(out[0], dirs[0] / np.linalg.norm(dirs[0]), atol=1e-15)


def test_a_row_inside_the_earlier_span_is_left_unchanged():
    dirs = np.array([[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [0.0, 3.0, 0.0]])
    orthonormalize(dirs)
    np.testing.assert_array_equal(dirs[1], [0.0, 1.0, 0.0])
    np.testing.assert_array_equal(dirs[2], [0.0, 3.0, 0.0])


@pytest.mark.parametrize("cls, kwargs", [(CCIPCA, {"n_components": 3}), (IncSFA, {"n_components": 2, "n_pca": 3})])
def test_orthonormal_at_every_multiple(cls, kwargs):
    """Right after sample t = k·every the directions are orthonormal (to round-off); 0 never touches them."""
    rng = np.random.default_rng(0)
    X = rng.standard_normal((300, 2)) @ rng.standard_normal((2, 30)) + 1e-9 * rng.standard_normal((300, 30))
    model = cls(**kwargs, orthonormalize=50, random_state=1)
    model.partial_fit(X[:249])
    model.partial_fit(X[249:250])  # sample 250: orthonormalised before its own update
    gram = model._dirs @ model._dirs.T
    assert np.abs(gram - np.eye(3)).max() < 0.5  # one update after: near, not exact
    plain = cls(**kwargs, random_state=1).partial_fit(X)
    same = cls(**kwargs, orthonormalize=0, random_state=1).partial_fit(X)
    np.testing.assert_array_equal(plain._dirs, same._dirs)


@pytest.mark.parametrize("cls", [CCIPCA, IncSFA])
def test_orthonormalize_must_be_a_count(cls):
    with pytest.raises(ValueError, match="key 'orthonormalize'"):
        cls(orthonormalize=-1).fit(np.random.default_rng(0).standard_normal((20, 4)))
