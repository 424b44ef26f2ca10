"""
# Progress or novelty DA

A circuit variant is a small TOML file that `extends` the full circuit and replaces one region;
`vta_novelty` ships with the package. In Python the same swap is
`circuit.replace("VTA", {"type": "vta.novelty"})`. Learning-progress dopamine (the paper's)
reports the fall of the context's estimation error; count novelty reports 1/√(visits).
The lines show each model's dopamine per episode over one run of 40 000 frames (seed 5), with
the boredom reward (−100) left out so that the scale of the rest shows.
"""

import matplotlib.pyplot as plt

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld

progress = Circuit.from_toml("cd_misfa")
novelty = progress.replace("VTA", {"type": "vta.novelty"})

fig, ax = plt.subplots(figsize=(8, 3.2))
for name, circuit in (("learning progress", progress), ("novelty", novelty)):
    episodes = circuit.build(SyntheticWorld(), seed=5).run(40_000).episodes()
    da = episodes["da"].where(episodes["da"] > -50)  # leave out the boredom reward (-100) to see the scale
    ax.plot(episodes["step"], da, lw=0.8, label=name)
ax.set_xlabel("frame")
ax.set_ylabel("DA (boredom episodes left out)")
ax.legend()
fig.tight_layout()
