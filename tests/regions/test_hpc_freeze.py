"""HPC's freeze rules (section 2.6; ``docs/regions.md``): the comparisons exactly at the
threshold, and a context partly gated by another module.

Documented: a module is stored when the freeze quantity is *below* the threshold
(``context_mean``: the mean of the context's stored eq-10 errors; ``converged``: the
extrapolated remaining drift E / (1 − ρ)), and an episode is familiar when a frozen
module's mean error is *below* it. So a quantity equal to the threshold neither stores
nor gates; the next float above the threshold does both. The inputs are chosen so that
every error is exact in binary (0.25, 0.125), so the quantity equals the threshold
exactly, not to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
from bound_region import bound

from neurocur.contexts.base import Episode
from neurocur.learn.roc import ROCBank
from neurocur.regions.hpc import HPCROC

ON = 0.25  # the freeze quantity of every test, exactly
JUST_ABOVE = float(np.nextafter(ON, np.inf))
STATES = np.arange(4)


def region(threshold, freeze="context_mean"):
    return bound(HPCROC, "HPC", n_states=4, threshold=threshold, freeze=freeze)


def visit(hpc, x, library=None, states=STATES):
    """One pass over ``states`` of context 0, with the adaptive features (x, 0) on each frame;
    returns (familiar, module_learned, the recorded context error)."""
    features = np.column_stack([np.full(len(states), x), np.zeros(len(states))])
    lib = np.empty((len(states), 0, 2)) if library is None else library
    familiar, learned, *_ = hpc.step(Episode(np.zeros((len(states), 1)), states, 0), features, lib)
    error = hpc.record()[2]
    hpc.learn()
    return familiar, learned, error


@pytest.mark.parametrize("threshold, stored", [(ON, False), (JUST_ABOVE, True)])
def test_context_mean_stores_only_below_the_threshold(threshold, stored):
    hpc = region(threshold)
    visit(hpc, 0.0)  # a cluster at 0 in every state, no error yet
    familiar, learned, error = visit(hpc, ON)  # every stored error is |0.25 - 0|
    assert error == ON and not familiar
    assert learned is stored and len(hpc.library) == int(stored)


@pytest.mark.parametrize("threshold, stored", [(ON, False), (JUST_ABOVE, True)])
def test_converged_stores_only_below_the_threshold(threshold, stored):
    hpc = region(threshold, freeze="converged")
    visit(hpc, 0.0)  # clusters at 0
    assert visit(hpc, 0.25)[1:] == (False, 0.25)  # errors 0.25, no previous ones: no freeze; clusters {0, 0.25}
    # errors min(0.375, 0.125) = 0.125, previous 0.25: rho = 0.5, drift 0.125 / (1 - 0.5) = 0.25
    familiar, learned, error = visit(hpc, 0.375)
    assert error == 0.125 and not familiar
    assert learned is stored and len(hpc.library) == int(stored)


@pytest.mark.parametrize("threshold, gated", [(ON, False), (JUST_ABOVE, True)])
def test_familiar_only_below_the_threshold(threshold, gated):
    hpc = region(threshold)
    frozen = ROCBank(8, 2)  # clusterer c * 4 + s: a cluster at 0 for every state of context 0
    frozen.partial_fit(STATES, np.zeros((4, 2)))
    hpc.library.append(frozen)
    library = np.zeros((4, 1, 2))
    library[:, 0, 1] = ON  # the frozen module's error on every frame is 0.25
    familiar, learned, _ = visit(hpc, 0.0, library)
    rec = dict(zip([p.name for p in hpc.probes], hpc.record()))
    assert rec["min_frozen_error"] == ON
    assert familiar is gated and rec["gating_module"] == (0 if gated else -1)
    assert not learned


# ---------------------------------------------------------------- a context partly gated by another module

WINDOW_A, WINDOW_B = np.array([0, 1]), np.array([2, 3])


def frozen_bank(states):
    """A frozen module with a cluster at 0 for ``states`` of context 0 only."""
    bank = ROCBank(8, 2)
    bank.partial_fit(states, np.zeros((len(states), 2)))
    return bank


def frozen_output(value, n=2):
    library = np.zeros((n, 1, 2))
    library[:, 0, 0] = value
    return library


#: window A's features per visit, from which each rule stores (after the first, A's errors are
#: 0.1 for context_mean; 0.25 then 0.125, a drift extrapolated to 0.25, for converged)
LEARNING_A = {"context_mean": [0.0, 0.1], "converged": [0.0, 0.25, 0.375]}


@pytest.mark.parametrize("freeze", list(LEARNING_A))
def test_states_seen_only_in_gated_episodes_do_not_block_the_freeze(freeze):
    """Window B of the context is explained by a frozen module (familiar), window A is not.
    Nothing is learned on a familiar episode, so the adaptive module has no cluster, hence
    no stored error, in window B's states; the freeze asks for an error only where no
    frozen module explains the state, so A's errors alone store the module (before, such
    a context could never be stored, however well A was learned)."""
    hpc = region(0.3, freeze)
    hpc.library.append(frozen_bank(WINDOW_B))
    first, *rest = LEARNING_A[freeze]
    visit(hpc, first, frozen_output(0.0), WINDOW_A)  # no frozen cluster here: not familiar
    familiar, learned, _ = visit(hpc, 0.0, frozen_output(0.1), WINDOW_B)
    assert familiar and not learned
    assert np.isnan(hpc.stored[0, WINDOW_B]).all()  # no adaptive cluster there
    stored = [visit(hpc, x, frozen_output(0.0), WINDOW_A)[1] for x in rest]
    assert stored == [False] * (len(rest) - 1) + [True] and len(hpc.library) == 2


@pytest.mark.parametrize("freeze", list(LEARNING_A))
def test_states_never_seen_or_seen_unfamiliar_still_block_the_freeze(freeze):
    """The exemption is for states whose last visit was gated: a state never visited, or
    visited unfamiliar before the adaptive module had a cluster there, still lacks its error."""
    hpc = region(0.3, freeze)
    hpc.library.append(frozen_bank(WINDOW_B))
    assert not any(visit(hpc, x, frozen_output(0.0), WINDOW_A)[1] for x in LEARNING_A[freeze])  # B never visited
    familiar, _, _ = visit(hpc, 0.0, frozen_output(5.0), WINDOW_B)  # visited, not familiar: clusters now
    assert not familiar
    familiar, _, _ = visit(hpc, 0.0, frozen_output(0.1), WINDOW_B)  # gated now, but its error is stored
    assert familiar and hpc.stored[0, WINDOW_B].tolist() == [0.0, 0.0]
