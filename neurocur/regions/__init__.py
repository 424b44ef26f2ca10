"""Brain regions of CD-MISFA (paper section 3), registered by type name.

One region per module: ``sensory`` (the world as a region), ``ec`` (entorhinal slow
features), ``hpc`` (hippocampal clusterers and familiarity), ``vta`` (dopamine), ``pfc``
(prefrontal values), ``lc`` (locus coeruleus, noradrenaline). Importing this package
imports every module in it, so each ``@register``-decorated region class in a new file
here is available by its type name without further wiring. See docs/regions.md.
"""

import importlib
import pkgutil

from .base import REGIONS, NoParams, Probe, Region, Signal, register

for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_module.name}")

__all__ = ["REGIONS", "NoParams", "Probe", "Region", "Signal", "register"]
