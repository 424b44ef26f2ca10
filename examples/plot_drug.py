"""
# Clamp tonic NE (a drug)

Pharmacology is a lesion kind that works on any released neuromodulator: `clamp` fixes the
level, `scale` multiplies it, `noise` adds Gaussian noise. Here the paper's ε-greedy LC has its
tonic NE (its drive to disengage, the exploration rate) clamped low and high; the agent's mean
dwell per visit follows. The bars show, for each clamped level, the episodes per visit (episodes
between two context switches) of one run of 40 000 frames, seed 7.
"""

import matplotlib.pyplot as plt
import numpy as np

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld

circuit = Circuit.from_toml("cd_misfa")
levels = [0.05, 0.3, 0.9]
dwell = []
for level in levels:
    episodes = circuit.lesion("LC", "clamp", level=level).build(SyntheticWorld(), seed=7).run(40_000).episodes()
    switches = np.flatnonzero(np.diff(episodes["context"].to_numpy()) != 0)
    dwell.append(len(episodes) / (len(switches) + 1))

fig, ax = plt.subplots(figsize=(5, 3.2))
ax.bar([str(x) for x in levels], dwell)
ax.set_xlabel("tonic NE clamped at")
ax.set_ylabel("episodes per visit")
fig.tight_layout()
