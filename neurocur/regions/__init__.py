"""Brain regions of CD-MISFA (paper section 3), registered by type name.

Importing this package registers the built-in region types:
``sensory.world``, ``ec.incsfa``, ``hpc.roc``, ``vta.learning_progress``,
``vta.novelty``, ``pfc.lspi``, ``lc.epsilon_greedy``. See docs/regions.md.
"""

from . import ec, hpc, lc, pfc, sensory, vta  # noqa: F401  (registration side effect)
from .base import Probe, Region, Signal

__all__ = ["Region", "Signal", "Probe"]
