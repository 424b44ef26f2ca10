"""What the runners share about processes: the workers' environment, and lines to the user."""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager

__all__ = ["note", "single_threaded_children"]

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


@contextmanager
def single_threaded_children():
    """Processes started in the block (local workers, a Dask LocalCluster's) inherit
    single-threaded BLAS/numba settings; the environment is restored afterwards."""
    saved = {k: os.environ.get(k) for k in _THREAD_VARS}
    os.environ.update({k: "1" for k in _THREAD_VARS})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def note(text: str) -> None:
    """One line to the user on stderr, above any progress bar."""
    from tqdm import tqdm

    tqdm.write(f"neurocur: {text}", file=sys.stderr)
