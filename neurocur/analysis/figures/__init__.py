"""The figures of a results folder, in matplotlib (imported on first use: :mod:`neurocur.analysis`).

- :mod:`~neurocur.analysis.figures.learning` — paper Figures 4D and 4F (cumulative error,
  learning time) and the storage order;
- :mod:`~neurocur.analysis.figures.reward` — paper Figures 4E and 4G (intrinsic reward, reward
  function) and a run's neuromodulator traces;
- :mod:`~neurocur.analysis.figures.neuro` — the neuromodulator and behaviour analyses (inverted
  U, occupancy, signals over time, event-locked traces, tonic/phasic NE, efficiency);
- :mod:`~neurocur.analysis.figures.goldilocks` — engagement against learnability;
- :mod:`~neurocur.analysis.figures.choice_shares` — each option's share of free choices over time
  and where each subject's shares peak;
- :mod:`~neurocur.analysis.figures.icub` — the iCub experiment (Figures 6–7);
- :mod:`~neurocur.analysis.figures.invariance` — the invariance demonstration (Figure 5);
- :mod:`~neurocur.analysis.figures.validation` — the canonical tasks of the neuromodulator models
  (docs/validation.md) and their figure sets;
- :mod:`~neurocur.analysis.figures.posner` — the inferential Posner task of Yu & Dayan 2005 (ACh and
  NE as uncertainty; docs/validation.md) and its figure set;
- :mod:`~neurocur.analysis.figures.sweeps` — a sweep's efficiency by condition and sweep point;
- :mod:`~neurocur.analysis.figures.layout` — readable symlog ticks, panels laid out by a sweep;
- :mod:`~neurocur.analysis.figures.sets` — the figure set of each world type and
  :func:`~neurocur.analysis.figures.sets.write_all`;
- :mod:`~neurocur.analysis.figures.style` — the style and saving.

Importing the package imports every module, so each figure set registers its world type.
"""

from . import (  # noqa: F401  (registration)
           choice_shares,
           goldilocks,
           icub,
           invariance,
           layout,
           learning,
           neuro,
           posner,
           reward,
           sets,
           style,
           sweeps,
           validation,
)
from .choice_shares import *  # noqa: F403
from .goldilocks import *  # noqa: F403
from .icub import *  # noqa: F403
from .invariance import *  # noqa: F403
from .learning import *  # noqa: F403
from .neuro import *  # noqa: F403
from .posner import *  # noqa: F403
from .reward import *  # noqa: F403
from .sets import *  # noqa: F403
from .sweeps import *  # noqa: F403
from .validation import *  # noqa: F403

__all__ = [*choice_shares.__all__, *goldilocks.__all__, *icub.__all__, *invariance.__all__, *learning.__all__, *neuro.__all__,
           *posner.__all__, *reward.__all__, *sets.__all__, *sweeps.__all__, *validation.__all__]
