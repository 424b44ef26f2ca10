"""The decision part: the regions of a circuit that a cached replay runs again for each theta (design section 7).

The *decision part* of a circuit, for a decision region and the fitted ``"REGION.param"`` keys, is the
decision region and every region on a path from a region with a fitted parameter to it, by edges that are
not delayed (e.g. PFC for eq 14's alpha). Everything else, the *learning part*, does not depend on the
fitted parameters, so a replay (:class:`~neurocur.fit.replay.Replay`) runs it once and records every
input of the decision part (:mod:`neurocur.fit.tape`). That holds only when the decision part feeds the
learning part nothing but the observed decision (:func:`observed_outputs`, which the replay emits in
place of the drawn one) and does not hold the clock region (the episode source, whose passes the replay
counts): :func:`decision_part` refuses such a circuit, to be fitted by simulation instead
(:mod:`neurocur.fit.sbi`).
"""

from __future__ import annotations

from collections.abc import Sequence

import networkx as nx

from ..circuit import Circuit
from ..config import ConfigError

__all__ = ["decision_part", "observed_outputs"]


def decision_part(circuit: Circuit, decision: str, fitted: Sequence[str]) -> tuple[str, ...]:
    """The regions that depend on the fitted ``"REGION.param"`` keys on their way to ``decision``.

    A fitted region with no path to the decision (by edges that are not delayed), a decision part
    that feeds the learning part with anything but the observed decision, or one that holds the
    clock region (the episode source) is a ConfigError (no cached replay).

    Parameters
    ----------
    circuit : Circuit
        The model's circuit.
    decision : str
        The decision region (an LC model, with probabilities and a ``next_context`` output).
    fitted : sequence of str
        The ``"REGION.param"`` keys to be varied.

    Returns
    -------
    tuple of str
        The decision part's regions, in the circuit's step order (the decision region among them).
    """
    graph = nx.DiGraph()
    graph.add_nodes_from(circuit.specs)
    graph.add_edges_from((k.src, k.dst) for k in circuit.links if not k.delayed)
    if decision not in circuit.specs:
        raise ConfigError(circuit.source, "decision", f"a region of the circuit ({', '.join(circuit.specs)})",
                          repr(decision))
    part = {decision}
    for key in fitted:
        region = key.split(".", 1)[0]
        if region not in circuit.specs:
            raise ConfigError("--fit", key, f"REGION.param with a region of the circuit ({', '.join(circuit.specs)})",
                              repr(key))
        if region != decision and not nx.has_path(graph, region, decision):
            raise ConfigError("--fit", key, f"a parameter of a region on the way to the decision ('{decision}')",
                              f"region '{region}', which does not reach it")
        part |= {region} | (nx.descendants(graph, region) & nx.ancestors(graph, decision))
    observed = set(observed_outputs(circuit, decision))
    for k in circuit.links:
        if k.src in part and k.dst not in part and not (k.src == decision and k.signal in observed):
            raise ConfigError("--fit", k.src, "fitted regions whose outputs reach only the decision",
                              f"edge {k}: the learning part would depend on the fitted parameters "
                              "(refit by simulation, neurocur.fit.sbi)")
    clock = next((n for n in part if circuit.specs[n].cls.is_clock), None)
    if clock is not None:
        raise ConfigError("--fit", clock, "fitted regions whose way to the decision does not pass the clock region "
                          "(the episode source)", f"clock region '{clock}' in the decision part "
                          f"({', '.join(sorted(part))}): refit by simulation, neurocur.fit.sbi")
    return tuple(n for n in circuit.step_order if n in part)


def observed_outputs(circuit: Circuit, decision: str) -> tuple[str, ...]:
    """The decision region's outputs that a replay replaces with the observed decision.

    Parameters
    ----------
    circuit : Circuit
        The model's circuit.
    decision : str
        The decision region (an LC model, with probabilities and a ``next_context`` output).

    Returns
    -------
    tuple of str
        ``action`` (when the region has it) and ``next_context``.

    Raises
    ------
    ConfigError
        When ``decision`` is not a decision region.
    """
    cls = circuit.specs[decision].cls
    names = tuple(s.name for s in cls.outputs)
    if not hasattr(cls, "probabilities") or "next_context" not in names:
        raise ConfigError(circuit.source, f"regions.{decision}", "a decision region (an LC model, with "
                          "probabilities and a next_context output)", circuit.specs[decision].type_name)
    return tuple(n for n in ("action", "next_context") if n in names)
