"""Results folders: the store that owns their layout, ``config.toml``, resume and loading.

:class:`ResultsStore` is the only code that knows where a run's files go; the experiment
runner writes through it and :mod:`neurocur.analysis` reads through it (``load``).
"""

from .store import ResultsStore, RunResult, load, run_dirs
from .tomlio import dumps_toml, first_difference

__all__ = ["ResultsStore", "RunResult", "dumps_toml", "first_difference", "load", "run_dirs"]
