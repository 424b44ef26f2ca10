"""Hand-made trials of a ``posner`` world with three cues (:mod:`neurocur.contexts.posner`), for the tests
of the regions of Yu & Dayan 2005."""

import numpy as np

from neurocur.contexts.base import Episode
from neurocur.contexts.posner import relevant_columns, target_column, validity_column

H = 3
NO_SUPPORT = np.zeros(2, dtype=np.int64)


def trial(cues, target, relevant=0, validity=0.8):
    """One trial: ``cues`` (H values 0/1), the ``target``'s side and the markers."""
    frame = np.zeros((1, 2 * H + 2))
    frame[0, :H] = cues
    frame[0, target_column(H)] = target
    frame[0, relevant_columns(H)][relevant] = 1.0
    frame[0, validity_column(H)] = validity
    return Episode(frames=frame, states=np.zeros(1, dtype=np.int64), context=0)
