"""
# Fit the softmax gain

`neurocur.fit` scores observed decisions under a circuit (log P(decision | state, θ)) and fits θ
by maximum likelihood. Here the shipped free-choice task (`free_choice`: four tasks of graded
difficulty, the next task chosen by a softmax over each task's learning progress) is simulated at
a few known gains; each run's choices are then fitted by signal replay (the recorded per-episode
error stands in for the learner), and the fitted gain is drawn against the true one with its 95 %
profile-likelihood interval. Paper-size recovery studies are `neurocur recover` (docs/fitting.md).
"""

import tempfile

import matplotlib.pyplot as plt

from neurocur.experiments import load_experiment, run_experiment
from neurocur.fit.study import condition_of, fit_data, load_data, make_replays

true_gains = [5.0, 15.0, 30.0]
estimates, lows, highs = [], [], []
for gain in true_gains:
    experiment = load_experiment("free_choice", runs=1, sets=[f"LC.gain={gain}"])
    experiment, condition = condition_of(experiment, "learning_progress")
    with tempfile.TemporaryDirectory() as out:
        run_experiment(experiment, out, jobs=1, conditions=["learning_progress"], progress=False)
        data = load_data(out, condition, signal=("HPC", "error"))
        replays = make_replays(experiment, condition, data, ["LC.gain"], signal=("HPC", "error"))
        (fit,) = fit_data(replays, {"LC.gain": (0.0, 100.0)}, pooled=False)
    estimates.append(fit.estimate["LC.gain"])
    lows.append(fit.ci["LC.gain"][0])
    highs.append(fit.ci["LC.gain"][1])

fig, ax = plt.subplots(figsize=(4.5, 4))
ax.errorbar(true_gains, estimates, yerr=[[e - lo for e, lo in zip(estimates, lows)],
                                         [hi - e for e, hi in zip(estimates, highs)]], fmt="o", capsize=3)
ax.plot([0, 35], [0, 35], color="0.6", lw=0.8, ls="--")
ax.set_xlabel("true gain (LC.gain)")
ax.set_ylabel("fitted gain, 95 % profile interval")
fig.tight_layout()
