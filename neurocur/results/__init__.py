"""Results folders: the store that owns their layout, ``config.toml``, resume and loading.

:class:`ResultsStore` is the only code that knows where a run's files go; the experiment
runner writes through it (holding the folder's lock, :mod:`.lock`) and
:mod:`neurocur.analysis` reads through it (``load``, which checks each run folder against its
path: :mod:`.reading`). :mod:`.fingerprint` records what determines a run besides its
configuration: its input files and the code.
"""

from .lock import FolderInUse
from .store import ResultsError, ResultsStore, RunResult, load, run_dirs
from .tomlio import dumps_toml, first_difference

__all__ = ["FolderInUse", "ResultsError", "ResultsStore", "RunResult", "dumps_toml", "first_difference", "load",
           "run_dirs"]
