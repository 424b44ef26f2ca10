"""
# Lesion the LC: curiosity against random switching

The paper's control for curiosity (section 4.3) is an agent that explores contexts at random:
the LC lesioned to a coin flip (`circuit.lesion("LC", how="random")`). Both agents see the same
world with the same seed. The bars show where each spent its frames; one short run is an
anecdote (here the curious agent lingers in C5, the unlearnable noise source, while its ε is
still high): the paired statistics over 25 runs are in docs/reproduction.md and docs/hypotheses.md.
"""

import matplotlib.pyplot as plt

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld

FRAMES = 60_000
circuit = Circuit.from_toml("cd_misfa")
agents = {"curious": circuit, "random switching": circuit.lesion("LC", how="random")}

fig, axes = plt.subplots(1, 2, figsize=(9, 3.2), sharey=True)
for ax, (name, agent) in zip(axes, agents.items()):
    episodes = agent.build(SyntheticWorld(), seed=3).run(FRAMES).episodes()
    frames = episodes.groupby("context")["n_frames"].sum() / FRAMES
    ax.bar([f"C{c + 1}" for c in frames.index], frames.to_numpy())
    ax.set_title(f"{name}: {int(episodes['module_learned'].sum())} module(s) stored")
    ax.set_xlabel("context")
axes[0].set_ylabel("share of frames")
fig.tight_layout()
