"""ACh as the expected uncertainty of hippocampal retrieval, context by context (a variant, not in the paper).

Yu & Dayan (2005, Neuron 46:681) read ACh as expected uncertainty: the known unreliability of
the predictive relation currently believed in, one minus the estimated validity gamma* of the
cue believed relevant (:mod:`.ach`, Y1-Y2). In the curiosity circuit the prediction HPC believes
in, in context c, is retrieval: the best frozen module's eq-10 error on the episode
(``min_frozen_error``) below the familiarity threshold says "this context is explained; gate
learning" (section 2.6). Its validity gamma*_c is the estimated probability, from the
previous visits of c, that the retrieved module explains the visit; ACh is one minus it.

After each visit of context c on which some frozen module responds, with v = 1 when the best
one's error is below HPC's threshold (HPC's ``retrieved`` output) and v = 0 when it is not,
the leaky counts of c are

    (R1)  k_c <- (1 - lambda) k_c + v,      n_c <- (1 - lambda) n_c + 1

(a visit with no frozen module to judge, ``retrieved`` NaN, leaves them), and at the next
visit of c the released ACh is

    (R2)  gamma*_c = (k_c + a) / (n_c + a + b),       (R3)  ACh = 1 - gamma*_c,

Yu & Dayan's Y2 with a Beta(a, b) prior; ``lambda`` (``leak``) lets the estimate follow a
context whose retrieval stops or starts to hold (lambda = 0: Y2's plain counts; Yu & Dayan
restart the counts when the context is believed to change, of which this circuit has no
signal). With k = sum_i (1 - lambda)^(N - i) v_i and n = sum_i (1 - lambda)^(N - i) over the
N judged visits so far, a context never judged releases ACh = b / (a + b).

What ACh does with it is :class:`~neurocur.regions.hpc_ach.HPCACh`'s switch, in the spirit of
Hasselmo (2006, Curr Opin Neurobiol 16:710; Hasselmo & McGaughy 2004, Prog Brain Res
145:207; Hasselmo 1999, Trends Cogn Sci 3:351): high ACh favours encoding (HPC learns the
episode), low ACh lets retrieval gate it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import check_params, param
from .base import Probe, Region, Signal, register

__all__ = ["RetrievalUncertaintyACh"]


@dataclass(frozen=True)
class RetrievalACHParams:
    prior_valid: float = param(1.0, float, low=0.0, low_open=True, doc="a, Beta prior pseudo-count of explained visits")
    prior_invalid: float = param(1.0, float, low=0.0, low_open=True, doc="b, Beta prior pseudo-count of unexplained visits")
    leak: float = param(0.1, float, low=0.0, high=1.0, high_open=True,
                        doc="lambda, the share of the counts forgotten at each judged visit of the context")

    def __post_init__(self):
        check_params(self)


@register("ach.retrieval_uncertainty")
class RetrievalUncertaintyACh(Region):
    """ACh = 1 - gamma*_c, the expected uncertainty of HPC's retrieval in the visited context (module
    docstring, R1-R3).

    Step: ACh of the visited ``context`` from the counts of its previous visits, through the drugs
    (``modulator`` ``"ach"``). Learn (after HPC has stepped): HPC's ``retrieved`` of this visit (1 the
    best frozen module's error is below threshold, 0 above, NaN no frozen module responds) updates
    the context's counts (R1). Recorded: ``ach`` (released), ``gamma_star`` (before the drugs) and
    ``retrieved``.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"RetrievalUncertaintyACh"``); the constructor is ``Region``'s.
    params : RetrievalACHParams, optional
        ``prior_valid`` (a) and ``prior_invalid`` (b), the Beta prior's pseudo-counts of explained and
        unexplained visits (each > 0, default 1), and ``leak`` (lambda, in [0, 1), default 0.1), the
        share of a context's counts forgotten at each judged visit of it (R1-R2).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = RetrievalACHParams
    modulator = "ach"
    inputs = (Signal("context", "int64", (), "the visited context"),)
    learn_inputs = (
        Signal("context", "int64", (), "the same context"),
        Signal("retrieved", "float64", (), "HPC: 1 a frozen module explains the visit, 0 it does not, NaN none responds"),
    )
    outputs = (Signal("ach", "float64", (), "expected uncertainty of retrieval in the context, 1 - gamma*_c (after the drugs)"),)
    probes = (
        Probe("ach", "float", "probability", "released ACh, 1 - gamma*_c through the drugs"),
        Probe("gamma_star", "float", "probability", "gamma*_c, the estimated probability that retrieval explains the context"),
        Probe("retrieved", "float", "", "1: a frozen module explained the visit, 0: none did, NaN: none responded"),
    )

    def bind(self, world) -> None:
        self.n_contexts = world.n_contexts

    def reset(self, rng) -> None:
        self.valid = np.zeros(self.n_contexts)
        self.judged = np.zeros(self.n_contexts)
        self._rec = (float("nan"),) * 3

    def gamma_star(self, context: int) -> float:
        """R2: the estimated probability that retrieval explains ``context``, from its leaky counts."""
        p = self.params
        return float((self.valid[context] + p.prior_valid) / (self.judged[context] + p.prior_valid + p.prior_invalid))

    def step(self, context):
        gamma = self.gamma_star(int(context))
        ach = self.modulate(1.0 - gamma)
        self._rec = (ach, gamma, float("nan"))
        return (ach,)

    def learn(self, context, retrieved):
        self._rec = self._rec[:2] + (float(retrieved),)
        if retrieved != retrieved:  # NaN: no frozen module to judge
            return
        c, keep = int(context), 1.0 - self.params.leak
        self.valid[c] = keep * self.valid[c] + float(retrieved)
        self.judged[c] = keep * self.judged[c] + 1.0

    def record(self):
        return self._rec
