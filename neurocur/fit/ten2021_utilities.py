"""The activity signals of Ten et al. 2021's choice models, as small numpy functions (docs/ten2021.md).

For one participant's whole sequence of trials (forced, then free), each trial's signals of every
activity *before* that trial's choice, from the outcomes of the earlier trials of the activity:

- ``plays``: how many times the activity was played (the paper's code calls it ``abst``, time);
- ``pc``: competence, the percent correct over the activity's last ``window`` = 15 trials;
- ``lp``: learning progress, the absolute difference between the percent correct over the last
  ``late`` = 9 and over the first ``early`` = 10 of those 15 trials (the two parts overlap by 4);

NaN while the activity has fewer than ``window`` trials. The forced phase plays each activity 15
times, so every window is full when free play begins and the first free choice already sees the
forced trials' PC and LP. These are the quantities of the authors' published analysis code
(Zenodo 10.5281/zenodo.5068243, ``prepare_data.ipynb``: 15-trial rolling windows per activity,
carried forward between the activity's trials, LP by ``rlp_func``, absolute).

The computation lives in :mod:`neurocur.regions.ten2021` (the choice models' region reads the
same functions); this module is its name for the analyses of the posted data. :func:`minmax` is
the per-participant rescaling the paper's fits apply to each signal before the
softmax (``model_utils.normalize``): all of a participant's values of the signal, every activity
and trial together, mapped onto [0, 1].
"""

from __future__ import annotations

from ..regions.ten2021 import EARLY, LATE, WINDOW, activity_signals, minmax

__all__ = ["EARLY", "LATE", "WINDOW", "activity_signals", "minmax"]
