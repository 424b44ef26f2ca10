"""
# Lesion the LC

The paper's control for curiosity (section 4.3) is an agent that explores contexts at random:
the LC lesioned to a coin flip (`circuit.lesion("LC", how="random")`). Both agents see the same
world with the same seed. The bars show each agent's share of frames per context, labelled by the
world's context name and the source it shows (S-A, S-B and S-C learnable, S-D the unlearnable noise);
the script prints where each agent spent most. One short run is an anecdote: the paired statistics
over 25 runs are in docs/reproduction.md and docs/hypotheses.md.
"""

import matplotlib.pyplot as plt

from neurocur.circuit import Circuit
from neurocur.contexts.synthetic import SyntheticWorld

FRAMES = 60_000
circuit = Circuit.from_toml("cd_misfa")
agents = {"curious": circuit, "random switching": circuit.lesion("LC", how="random")}
spec = SyntheticWorld().source_spec()
labels = [f"{name}\n{source}" for name, source in zip(spec.context_names, spec.context_sources)]

fig, axes = plt.subplots(1, 2, figsize=(9, 3.2), sharey=True)
for ax, (name, agent) in zip(axes, agents.items()):
    episodes = agent.build(SyntheticWorld(), seed=3).run(FRAMES).episodes()
    frames = episodes.groupby("context")["n_frames"].sum().reindex(range(len(labels)), fill_value=0) / FRAMES
    ax.bar(labels, frames.to_numpy())
    ax.set_title(f"{name}: {int(episodes['module_learned'].sum())} module(s) stored")
    ax.set_xlabel("context and its source")
    most = int(frames.to_numpy().argmax())
    print(f"{name}: most frames in {spec.context_names[most]} (source {spec.context_sources[most]}), "
          f"{frames.iloc[most]:.2f} of them; in the noise source S-D: "
          f"{frames[[c for c, s in enumerate(spec.context_sources) if s == 'S-D']].sum():.2f}")
axes[0].set_ylabel("share of frames")
fig.tight_layout()
