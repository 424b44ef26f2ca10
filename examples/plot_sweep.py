"""
# Sweep one parameter

An experiment file's `[sweep]` table, or `--set KEY=V1,V2` on the command line, runs every
condition at every point, with run *i* seeded the same at every point, so points compare paired.
Here the shipped synthetic experiment runs its curious condition at two values of the PFC's
discount, 2 short runs per point, into a temporary results folder that the analysis then reads. The bars show the modules stored per
run (one colour per run) at each discount.
"""

import tempfile

import matplotlib.pyplot as plt

from neurocur.analysis import load
from neurocur.experiments import load_experiment, run_experiment

experiment = load_experiment("synthetic", runs=2, steps=30_000, sets=["PFC.discount=0.5,0.95"])
with tempfile.TemporaryDirectory() as out:
    run_experiment(experiment, out, jobs=1, conditions=["curious"], progress=False)
    episodes, modules = load(out)

stored = modules.groupby(["PFC.discount", "run"]).size().unstack("run")
fig, ax = plt.subplots(figsize=(5, 3.2))
stored.plot.bar(ax=ax)
ax.set_ylabel("modules stored")
fig.tight_layout()
