"""One line on standard error when numba compiles neurocur's kernels: the first run's silence explained.

The kernels are compiled with ``cache=True``: the first run after an install, or after a
kernel's source or numba itself changed, compiles them (10–20 s with nothing printed), and
every later run loads them from numba's on-disk cache. numba broadcasts its ``"numba:compile"``
event (``numba.core.event``) only for a real compilation, after the dispatcher found no
usable cache entry (a cache hit loads the kernel and broadcasts nothing), so a listener on it
prints :data:`MESSAGE` exactly when a kernel of neurocur starts compiling, once per process.
It reads no file and adds nothing to start-up or to a cache hit.

Once per command, too: ``neurocur run`` starts the workers' fork server, which compiles the
same kernels while the command's own pre-flight does. The command names itself in the
environment its children inherit (:data:`ANNOUNCER`, its process id); a process whose
environment names another process stays silent.
"""

from __future__ import annotations

import os
import sys

from numba.core import event

__all__ = ["ANNOUNCER", "MESSAGE", "announce_compiling"]

#: printed to standard error when the first of neurocur's kernels compiles in a process
MESSAGE = "compiling kernels (first run only)"
#: the environment variable naming the process (its id) that prints :data:`MESSAGE` for its children too
ANNOUNCER = "NEUROCUR_COMPILING_ANNOUNCER"


class _Announcer(event.Listener):
    """Prints :data:`MESSAGE` at the first compilation of a function of neurocur's."""

    def __init__(self):
        self.said = False

    def on_start(self, ev):
        dispatcher = (ev.data or {}).get("dispatcher")
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        if not self.said and module.startswith("neurocur."):
            self.said = True
            if os.environ.get(ANNOUNCER, str(os.getpid())) == str(os.getpid()):
                print(MESSAGE, file=sys.stderr, flush=True)

    def on_end(self, ev):
        pass


_ANNOUNCER = _Announcer()
_listening = False


def announce_compiling() -> None:
    """Listen for numba's compilations (once per process; called again, does nothing):
    :data:`MESSAGE` at the first of neurocur's."""
    global _listening
    if not _listening:
        event.register("numba:compile", _ANNOUNCER)
        _listening = True
