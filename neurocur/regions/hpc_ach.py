"""HPC whose switch between learning and gating reads ACh (a variant, not in the paper).

Hasselmo (2006, Curr Opin Neurobiol 16:710; Hasselmo 1999, Trends Cogn Sci 3:351): in the
hippocampus high ACh sets the circuit for encoding (recurrent retrieval suppressed, plasticity
enhanced) and low ACh for retrieval (recurrent feedback dominates, consolidation). CD-MISFA's HPC
has the same switch (section 2.6): an episode whose best frozen module's eq-10 error is below the
threshold is *familiar*, retrieval gates learning (EC and HPC learn nothing, VTA pays boredom);
otherwise the adaptive module learns it. Here the switch also reads ACh, the expected uncertainty
of retrieval in the visited context (:mod:`.ach_retrieval`, R1-R3):

    (H1)  familiar = gating  and  min_frozen_error < threshold  and  ACh < ach_threshold,

so a frozen module gates only a context where it has been found reliable; where retrieval has
been unreliable (ACh high), the episode is encoded. Everything else is :class:`~.hpc.HPCROC`'s.
HPC also sends ACh what retrieval found, before the gate:

    (H2)  retrieved = 1 if min_frozen_error < threshold, 0 if not, NaN if no frozen module responds.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..config import param
from .base import Signal, register
from .hpc import HPCROC, HPCParams

__all__ = ["HPCACh"]


@dataclass(frozen=True)
class HPCAChParams(HPCParams):
    ach_threshold: float = param(0.5, float, low=0.0, high=1.0, high_open=True,
                                 doc="retrieval may gate only while ACh is below this (H1)")


@register("hpc.roc_ach")
class HPCACh(HPCROC):
    """:class:`~.hpc.HPCROC` whose gating needs ACh below ``ach_threshold`` (module docstring, H1-H2).

    Inputs: HPC's and ``ach`` (this visit's, :class:`~neurocur.regions.ach_retrieval.RetrievalUncertaintyACh`).
    Outputs: HPC's and ``retrieved`` (H2). With ACh always below the threshold it is HPC.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"HPCACh"``); the constructor is ``Region``'s.
    params : HPCAChParams, optional
        HPC's parameters (``HPCParams``, docs/regions.md) and ``ach_threshold`` (in [0, 1), default
        0.5): retrieval may gate only while ACh is below it (H1).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = HPCAChParams
    inputs = HPCROC.inputs + (Signal("ach", "float64", (), "expected uncertainty of retrieval in this context"),)
    outputs = HPCROC.outputs + (Signal("retrieved", "float64", (), "1: a frozen module's error is below threshold, "
                                       "0: above, NaN: no frozen module responds (before the ACh gate)"),)

    def step(self, episode, features, library_features, ach):
        self.ach = float(ach)
        out = super().step(episode, features, library_features)
        min_err = self._rec[4]
        retrieved = float("nan") if min_err != min_err else float(min_err < self.params.threshold)
        return out + (retrieved,)

    def retrieval_allowed(self) -> bool:
        return self.ach < self.params.ach_threshold
