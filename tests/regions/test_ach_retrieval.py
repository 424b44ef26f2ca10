"""ACh as the expected uncertainty of retrieval (``ach.retrieval_uncertainty``, R1-R3) and the HPC whose
switch between learning and gating reads it (``hpc.roc_ach``, H1-H2): the released ACh against the closed
form on a hand-made sequence of visits, and the gate changing HPC's decision exactly where ACh crosses
its threshold."""

from __future__ import annotations

import math

import numpy as np
import pytest
from bound_region import bound

from neurocur.circuit import Circuit
from neurocur.contexts.base import Episode
from neurocur.learn.roc import ROCBank
from neurocur.regions.ach_retrieval import RetrievalUncertaintyACh
from neurocur.regions.hpc_ach import HPCACh

NAN = math.nan


def closed_form(judged: list[float], a: float, b: float, leak: float) -> float:
    """R2-R3 written out: ACh = 1 - (sum_i w_i v_i + a) / (sum_i w_i + a + b), w_i = (1 - leak)^(N - 1 - i)
    over the N judged visits (retrieved not NaN) of the context so far."""
    v = [x for x in judged if x == x]
    w = [(1.0 - leak) ** (len(v) - 1 - i) for i in range(len(v))]
    return 1.0 - (sum(wi * vi for wi, vi in zip(w, v)) + a) / (sum(w) + a + b)


def test_ach_follows_the_closed_form_context_by_context():
    a, b, leak = 2.0, 1.0, 0.25
    ach = bound(RetrievalUncertaintyACh, "ACh", prior_valid=a, prior_invalid=b, leak=leak)
    # (context, retrieved) per visit: NaN visits (no frozen module responded) are not counted
    visits = [(0, NAN), (0, 1.0), (1, 0.0), (0, 0.0), (0, 1.0), (1, 0.0), (0, 1.0), (0, NAN), (1, 1.0), (0, 0.0), (0, 1.0)]
    seen: dict[int, list[float]] = {0: [], 1: []}
    released = []
    for context, retrieved in visits:
        (level,) = ach.step(context)
        released.append(level)
        assert level == pytest.approx(closed_form(seen[context], a, b, leak), abs=1e-12)
        ach.learn(context, retrieved)
        assert ach.record()[2] == retrieved or (retrieved != retrieved and ach.record()[2] != ach.record()[2])
        seen[context].append(retrieved)
    assert released[0] == pytest.approx(b / (a + b), abs=1e-15)  # never judged: the prior's b / (a + b)
    # context 0 before its last visit: judged 1, 0, 1, 1, 0 -> k = .75^4 + .75^2 + .75 + 0 ... written out
    k = 0.75 ** 4 + 0.75 ** 2 + 0.75
    n = 0.75 ** 4 + 0.75 ** 3 + 0.75 ** 2 + 0.75 + 1.0
    assert released[-1] == pytest.approx(1.0 - (k + a) / (n + a + b), abs=1e-12)
    assert released[-1] != pytest.approx(1.0 - (3 + a) / (5 + a + b), abs=1e-3)  # the counts without the leak


def gate_region(ach_threshold=0.5):
    return bound(HPCACh, "HPC", n_states=4, threshold=0.3, ach_threshold=ach_threshold)


STATES = np.arange(4)


def gated_visit(hpc, ach, frozen_error):
    """One pass of context 0 whose frozen module's error is ``frozen_error`` on every frame (None: no
    frozen module); returns (familiar, retrieved, gating_module)."""
    if frozen_error is not None and not hpc.library:
        frozen = ROCBank(8, 2)  # a cluster at 0 for every state of context 0
        frozen.partial_fit(STATES, np.zeros((4, 2)))
        hpc.library.append(frozen)
    library = np.zeros((4, len(hpc.library), 2))
    if frozen_error is not None:
        library[:, 0, 1] = frozen_error
    familiar, _, _, _, retrieved = hpc.step(Episode(np.zeros((4, 1)), STATES, 0), np.zeros((4, 2)), library, ach)
    gating = dict(zip([p.name for p in hpc.probes], hpc.record()))["gating_module"]
    hpc.learn()
    return familiar, retrieved, gating


@pytest.mark.parametrize("ach, familiar", [(np.nextafter(0.5, 0.0), True), (0.5, False), (0.9, False), (0.0, True)])
def test_the_gate_switches_hpc_where_ach_crosses_its_threshold(ach, familiar):
    hpc = gate_region(0.5)
    got, retrieved, gating = gated_visit(hpc, ach, 0.125)  # the frozen module explains the visit
    assert retrieved == 1.0  # what retrieval found, before the gate
    assert got is familiar and gating == (0 if familiar else -1)
    assert (hpc.bank.n_clusters_.sum() > 0) is not familiar  # encoded (the adaptive clusters learn) only when not gated


def test_retrieved_says_when_no_frozen_module_explains_the_visit():
    hpc = gate_region()
    assert math.isnan(gated_visit(hpc, 0.0, None)[1])  # no frozen module
    familiar, retrieved, _ = gated_visit(hpc, 0.0, 0.375)  # above the threshold 0.3
    assert retrieved == 0.0 and not familiar


def test_in_the_circuit_gating_is_retrieval_and_low_ach(circuits_dir, small, make_world):
    """Every pass: familiar exactly when retrieval found a module below threshold and ACh < 0.5; the ACh
    gate blocks some retrievals; with ACh clamped at 0 the circuit makes CD-MISFA's decisions."""
    fast = {**small, "HPC.freeze": "episode_mean", "HPC.threshold": 1.0}
    ach = Circuit.from_toml(circuits_dir / "cd_misfa_ach.toml", overrides=fast)
    episodes = ach.build(make_world(), seed=3).run(4000).episodes()
    match = episodes["retrieved"] == 1.0
    np.testing.assert_array_equal(episodes["familiar"], match & (episodes["ach"] < 0.5))
    assert (match & (episodes["ach"] >= 0.5)).sum() > 0 and episodes["familiar"].sum() > 0
    clamped = ach.lesion("ACh", "clamp", level=0.0).build(make_world(), seed=3).run(4000).episodes()
    paper = Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides=fast).build(make_world(), seed=3).run(4000).episodes()
    for column in ("context", "familiar", "module_learned", "da", "n_modules"):
        np.testing.assert_array_equal(clamped[column], paper[column], err_msg=column)
