"""Loaded by the fork server after the runner: numba's compiled kernels, loaded once for every worker.

A compiled kernel is read from numba's cache on its first call in a process, and the first
such call also imports numba's typing and lowering registries: about 0.3 s in each worker's
first run of the synthetic experiment (a run itself takes about 0.9 s). Importing this module
runs the first episode of the shipped synthetic experiment's curious condition (one episode of
100 frames, the pre-flight's :func:`~neurocur.experiments.run.dry_run` without its memory
measurement), so that the fork server holds the kernels and the workers fork with them loaded.
Kernels that this episode does not call (the float32 IncSFA path, the FitzHugh–Nagumo LC) are
still loaded on first use. Nothing here changes a result: a loaded kernel is the same code.

Then the objects alive are frozen (:func:`gc.freeze`, as Python's documentation advises before
forking without exec), so that no garbage collection walks them again: not the workers' (they
inherit the frozen state), and not the fork server's own at its exit, the interpreter's final
collection, which took 0.3-0.4 s after every sweep (the fork server holds the command's standard
output, so whatever reads that output waited for it).
"""

from __future__ import annotations

import gc

from .run import warm_up

warm_up()
gc.freeze()  # no collection first: it would cost 0.1 s of the fork server's start for a few hundred objects
