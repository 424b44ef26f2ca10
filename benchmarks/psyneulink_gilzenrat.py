"""Reference trajectories and statistics of Gilzenrat et al. (2002)'s model from PsyNeuLink, the
Cohen lab's implementation, for ``tests/regions/test_gilzenrat_reference.py``.

PsyNeuLink is not a dependency of neurocur: run this script with a Python that has it, e.g.

    python3 -m venv /work/pnl && /work/pnl/bin/pip install psyneulink
    /work/pnl/bin/python benchmarks/psyneulink_gilzenrat.py            # writes tests/data/gilzenrat_psyneulink.json

It builds the model as PsyNeuLink's ``GilzenratModel`` does (an input layer, an ``LCAMechanism``
decision layer with self-excitation, mutual inhibition and crosstalk, a one-unit ``LCAMechanism``
response layer, an ``LCControlMechanism`` whose FitzHugh-Nagumo LC monitors the target decision
unit and modulates the gain of both layers), with Gilzenrat et al.'s parameters, and writes:

- ``trajectories``: per mode (C = 0.95 and 0.55, the lab's initial v and u), the outputs f_1,
  f_2, f_3 of the decision and response units and the LC's v and u after each of 400 steps without
  noise, for the input sequence ``inputs`` (100 steps of nothing, 100 of a target, 100 of nothing,
  100 of a distractor);
- ``adaptive_gain``: PsyNeuLink's ``DualAdaptiveIntegrator`` (the function of its
  ``AGTControlMechanism``) on a sequence of utilities, with its parameters;
- ``statistics``: per mode, the vigilance task of ``neurocur run gilzenrat2002`` (300 trials of 300
  steps, a stimulus from step 100 for 100 steps, 20 % targets) with the units' noise (sd 0.22 per
  unit of time), the first 20 trials dropped: the LC's activity h(v) before the stimulus and its
  peak within 100 steps of the onset, the burst ratio, hit and false-alarm rates with the response
  criterion 0.6 on f_3, and d' (log-linear correction). These come from the transcription below
  (equal to PsyNeuLink's trajectories to rounding, ``trajectories``): PsyNeuLink runs about 15
  steps a second, so it runs only the first ``--pnl-trials`` trials of the task, none dropped
  (``statistics_psyneulink``), with its own noise draws;
- ``initial_outputs``: the units' outputs before their first step (PsyNeuLink's logistic at x = 0
  with unit gain), which a comparison needs for the first steps.

Without PsyNeuLink (``--transcription``, or when it is not installed) the same outputs come from
this file's own transcription of PsyNeuLink's equations (:func:`transcribed_step`), independent of
neurocur's code, and the file says so (``source``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

#: Gilzenrat et al. (2002)'s parameters, as PsyNeuLink's GilzenratModel sets them.
PARAMS = {"input_weight": 1.0, "crosstalk": 0.33, "self_excitation": 1.0, "inhibition": 1.0, "decision_bias": 0.0,
          "response_weight": 1.84, "response_self": 2.0, "response_bias": 2.0, "lc_weight": 0.3, "alpha": 0.5,
          "baseline": 0.5, "gain_base": 0.5, "gain_scale": 3.0, "tau_v": 0.05, "tau_u": 5.0, "dt": 0.02,
          "noise": 0.22}
#: Per mode: C and the lab's initial h(v) and u (initial v = (h - (1 - C) d) / C).
MODES = {"phasic": (0.95, 0.07, 0.14), "tonic": (0.55, 0.2, 0.2)}
TASK = {"trials": 300, "trial_length": 300, "onset": 100, "duration": 100, "target_probability": 0.2,
        "window": 100, "threshold": 0.6, "dropped": 20, "seed": 2002}
AGT = {"short_term_rate": 0.3, "long_term_rate": 0.05, "short_term_gain": 2.0, "long_term_gain": 3.0,
       "short_term_bias": 0.4, "long_term_bias": 0.2}


def reference_inputs() -> np.ndarray:
    """The deterministic input sequence: 100 steps of (0, 0), 100 of a target (1, 0), 100 of (0, 0), 100 of a
    distractor (0, 1)."""
    return np.repeat(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 1.0]]), 100, axis=0)


def initial_vu(mode: str) -> tuple[float, float]:
    c, h0, u0 = MODES[mode]
    return (h0 - (1.0 - c) * PARAMS["baseline"]) / c, u0


# --- PsyNeuLink ------------------------------------------------------------------------------------------------------

def pnl_model(mode: str, noise: float, seed: int):
    """The lab's composition (as in PsyNeuLink's GilzenratModel.py) for ``mode``; returns (composition,
    input layer, decision layer, response layer, LC)."""
    import psyneulink as pnl

    p, (c, _, _) = PARAMS, MODES[mode]
    v0, u0 = initial_vu(mode)
    rng_seeds = np.random.SeedSequence(seed).generate_state(2)
    input_layer = pnl.TransferMechanism(input_shapes=2, initial_value=np.array([[0.0, 0.0]]), name="INPUT")
    decision = pnl.LCAMechanism(input_shapes=2, time_step_size=p["dt"], leak=1.0, self_excitation=p["self_excitation"],
                                competition=p["inhibition"], function=pnl.Logistic(x_0=p["decision_bias"]),
                                noise=pnl.NormalDist(standard_deviation=noise, seed=int(rng_seeds[0])),
                                integrator_mode=True, name="DECISION")
    response = pnl.LCAMechanism(input_shapes=1, time_step_size=p["dt"], leak=1.0, self_excitation=p["response_self"],
                                function=pnl.Logistic(x_0=p["response_bias"]),
                                noise=pnl.NormalDist(standard_deviation=noise, seed=int(rng_seeds[1])),
                                integrator_mode=True, name="RESPONSE")
    weights = np.array([[p["input_weight"], p["crosstalk"]], [p["crosstalk"], p["input_weight"]]])
    pathway = pnl.Pathway(pathway=[input_layer, weights, decision, np.array([[p["response_weight"]], [0.0]]), response])
    lc = pnl.LCControlMechanism(
        integration_method="EULER", threshold_FitzHughNagumo=p["alpha"], uncorrelated_activity_FitzHughNagumo=p["baseline"],
        base_level_gain=p["gain_base"], scaling_factor_gain=p["gain_scale"], time_step_size_FitzHughNagumo=p["dt"],
        mode_FitzHughNagumo=c, time_constant_v_FitzHughNagumo=p["tau_v"], time_constant_w_FitzHughNagumo=p["tau_u"],
        a_v_FitzHughNagumo=-1.0, b_v_FitzHughNagumo=1.0, c_v_FitzHughNagumo=1.0, d_v_FitzHughNagumo=0.0,
        e_v_FitzHughNagumo=-1.0, f_v_FitzHughNagumo=1.0, a_w_FitzHughNagumo=1.0, b_w_FitzHughNagumo=-1.0,
        c_w_FitzHughNagumo=0.0, t_0_FitzHughNagumo=0.0, initial_v_FitzHughNagumo=v0, initial_w_FitzHughNagumo=u0,
        objective_mechanism=pnl.ObjectiveMechanism(
            function=pnl.Linear, monitor=[(decision, None, None, np.array([[p["lc_weight"]], [0.0]]))], name="LC objective"),
        modulated_mechanisms=[decision, response], name="LC")
    comp = pnl.Composition()
    comp.add_linear_processing_pathway(pathway)
    comp.add_node(lc)
    return comp, input_layer, decision, response, lc


def pnl_run(mode: str, inputs: np.ndarray, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """PsyNeuLink's model over ``inputs`` (one run trial per time step): rows (f_1, f_2, f_3, v, u, gain
    the LC released in the step) per step."""
    comp, input_layer, decision, response, lc = pnl_model(mode, noise, seed)
    rows = []

    def record(context):
        value = lc.parameters.value.get(context)
        rows.append([*decision.parameters.value.get(context)[0], response.parameters.value.get(context)[0][0],
                     value[1][0], value[2][0], value[0][0]])

    comp.run(inputs={input_layer: inputs}, num_trials=len(inputs), call_after_trial=record)
    return np.array(rows, dtype=float)


def pnl_initial_outputs(mode: str) -> list[float]:
    """The outputs the decision and response units have before their first execution: their logistic
    at x = 0 with the function's own gain (1), not the LC's."""
    _, _, decision, response, _ = pnl_model(mode, 0.0, 0)
    return [*np.ravel(decision.defaults.value), *np.ravel(response.defaults.value)]


def pnl_dual_adaptive(utilities: np.ndarray) -> np.ndarray:
    """PsyNeuLink's DualAdaptiveIntegrator (AGTControlMechanism's function, PRODUCT of its two terms) on
    ``utilities``, one value per step."""
    import psyneulink as pnl

    f = pnl.DualAdaptiveIntegrator(initial_short_term_avg=0.0, initial_long_term_avg=0.0, **AGT)
    return np.array([float(np.ravel(f(u))[0]) for u in utilities])


# --- an independent transcription of PsyNeuLink's equations ------------------------------------------------------------

def transcribed_step(s: list, i1: float, i2: float, c: float, e: np.ndarray, noise: float) -> None:
    """One step of the lab's model, written from PsyNeuLink's documented equations (LeakyCompetingIntegrator,
    Logistic, FitzHughNagumoIntegrator with Euler, LCControlMechanism's g = G + k w) in the order its
    scheduler runs them: the decision layer, the LC, the response layer. ``s`` = [x1, x2, x3,
    f1, f2, f3, v, u], updated in place; ``e`` the three units' standard normal draws, ``noise`` their
    standard deviation per unit of time (the integrator adds noise x sqrt(dt) x e)."""
    p = PARAMS
    dt, sq = p["dt"], math.sqrt(p["dt"])
    x1, x2, x3, f1, f2, f3, v, u = s
    g = p["gain_base"] + p["gain_scale"] * u  # the gain of the LC's last step
    net1 = p["input_weight"] * i1 + p["crosstalk"] * i2 + p["self_excitation"] * f1 - p["inhibition"] * f2
    net2 = p["crosstalk"] * i1 + p["input_weight"] * i2 + p["self_excitation"] * f2 - p["inhibition"] * f1
    x1 = x1 + (net1 - x1) * dt + noise * e[0] * sq
    x2 = x2 + (net2 - x2) * dt + noise * e[1] * sq
    f1 = 1.0 / (1.0 + math.exp(-g * (x1 - p["decision_bias"])))
    f2 = 1.0 / (1.0 + math.exp(-g * (x2 - p["decision_bias"])))
    # the LC runs next (it monitors the decision layer); the response layer, which it modulates, after it
    dv = (-v ** 3 + (1.0 + p["alpha"]) * v ** 2 - p["alpha"] * v - u + p["lc_weight"] * f1) / p["tau_v"]
    du = (c * v + (1.0 - c) * p["baseline"] - u) / p["tau_u"]
    v, u = v + dt * dv, u + dt * du
    g = p["gain_base"] + p["gain_scale"] * u
    x3 = x3 + (p["response_self"] * f3 + p["response_weight"] * f1 - x3) * dt + noise * e[2] * sq
    f3 = 1.0 / (1.0 + math.exp(-g * (x3 - p["response_bias"])))
    s[:] = [x1, x2, x3, f1, f2, f3, v, u]


def transcribed_run(mode: str, inputs: np.ndarray, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """The transcription over ``inputs`` from PsyNeuLink's first state (x = 0, the outputs of
    ``initial_outputs`` in :func:`main`): rows as :func:`pnl_run`'s."""
    c = MODES[mode][0]
    s = [0.0, 0.0, 0.0, 0.5, 0.5, 1.0 / (1.0 + math.exp(PARAMS["response_bias"])), *initial_vu(mode)]
    rng = np.random.default_rng(seed)
    rows = []
    for i1, i2 in inputs:
        transcribed_step(s, i1, i2, c, rng.standard_normal(3), noise)
        rows.append([s[3], s[4], s[5], s[6], s[7], PARAMS["gain_base"] + PARAMS["gain_scale"] * s[7]])
    return np.array(rows)


def transcribed_dual_adaptive(utilities: np.ndarray) -> np.ndarray:
    """The DualAdaptiveIntegrator's PRODUCT form as PsyNeuLink computes it: its ``_function`` passes
    (rate, previous average, input) to ``_EWMA_filter(previous_value, rate, variable)``, so each average
    becomes (1 - previous) x rate + previous x input, not the documented (1 - rate) x previous + rate x
    input; then (1 - logistic(gain_s s - bias_s)) x logistic(gain_l l - bias_l)."""
    a = AGT
    s = l_avg = 0.0
    out = []
    for u in utilities:
        s = (1.0 - s) * a["short_term_rate"] + s * u
        l_avg = (1.0 - l_avg) * a["long_term_rate"] + l_avg * u
        short = 1.0 / (1.0 + math.exp(-a["short_term_gain"] * s + a["short_term_bias"]))
        long = 1.0 / (1.0 + math.exp(-a["long_term_gain"] * l_avg + a["long_term_bias"]))
        out.append((1.0 - short) * long)
    return np.array(out)


# --- the task's statistics -------------------------------------------------------------------------------------------

def task_statistics(run, mode: str, trials: int = TASK["trials"], dropped: int = TASK["dropped"]) -> dict:
    """The vigilance task (:data:`TASK`, its first ``trials`` trials, the first ``dropped`` left out of
    the statistics) through ``run`` (pnl_run or transcribed_run) with the units' noise."""
    t = {**TASK, "trials": trials, "dropped": dropped}
    rng = np.random.default_rng(t["seed"])
    targets = rng.random(t["trials"]) < t["target_probability"]
    inputs = np.zeros((t["trials"], t["trial_length"], 2))
    on = slice(t["onset"], t["onset"] + t["duration"])
    inputs[targets, on] = (1.0, 0.0)
    inputs[~targets, on] = (0.0, 1.0)
    rows = run(mode, inputs.reshape(-1, 2), noise=PARAMS["noise"], seed=t["seed"])
    trials = rows.reshape(t["trials"], t["trial_length"], -1)[t["dropped"]:]
    targets = targets[t["dropped"]:]
    c, d = MODES[mode][0], PARAMS["baseline"]
    h = c * trials[:, :, 3] + (1.0 - c) * d
    baseline = h[:, :t["onset"]].mean(axis=1)
    peak = h[:, t["onset"]:t["onset"] + t["window"]].max(axis=1)
    response = (trials[:, t["onset"]:, 2] > t["threshold"]).any(axis=1)
    n_t, n_d = int(targets.sum()), int((~targets).sum())
    hit = (response[targets].sum() + 0.5) / (n_t + 1)
    fa = (response[~targets].sum() + 0.5) / (n_d + 1)
    from statistics import NormalDist

    z = NormalDist().inv_cdf
    return {"trials": len(targets), "targets": n_t, "baseline": float(baseline.mean()),
            "peak_target": float(peak[targets].mean()), "peak_distractor": float(peak[~targets].mean()),
            "burst_ratio": float(peak[targets].mean() / baseline.mean()),
            "hit_rate": float(response[targets].mean()), "false_alarm_rate": float(response[~targets].mean()),
            "d_prime": float(z(hit) - z(fa)), "mean_gain": float(trials[:, :, 5].mean())}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "tests/data/gilzenrat_psyneulink.json"))
    parser.add_argument("--transcription", action="store_true", help="use this file's transcription, not PsyNeuLink")
    parser.add_argument("--pnl-trials", type=int, default=20,
                        help="trials of the task run through PsyNeuLink itself (it takes about 15 steps a second)")
    args = parser.parse_args(argv)
    source = "transcription"
    if not args.transcription:
        try:
            import psyneulink

            source = f"psyneulink {psyneulink.__version__}"
        except ImportError:
            print("PsyNeuLink is not installed: using this file's transcription of its equations", file=sys.stderr)
    pnl = source != "transcription"
    run = pnl_run if pnl else transcribed_run
    inputs = reference_inputs()
    utilities = np.concatenate([np.full(40, 1.0), np.full(40, 0.0), np.linspace(-1.0, 2.0, 40)])
    out = {
        "source": source, "params": PARAMS, "modes": MODES, "columns": ["f1", "f2", "f3", "v", "u", "gain"],
        "inputs": inputs.tolist(),
        "initial_outputs": {mode: pnl_initial_outputs(mode) if pnl else [0.5, 0.5, 1.0 / (1.0 + math.exp(2.0))]
                            for mode in MODES},
        "trajectories": {mode: run(mode, inputs).tolist() for mode in MODES},
        "adaptive_gain": {"params": AGT, "utilities": utilities.tolist(),
                          "engagement": (pnl_dual_adaptive if pnl else transcribed_dual_adaptive)(utilities).tolist()},
        "task": TASK,
        # the transcription on the whole task (PsyNeuLink itself is too slow for it), and PsyNeuLink on its start
        "statistics": {mode: task_statistics(transcribed_run, mode) for mode in MODES},
    }
    if pnl and args.pnl_trials > 0:  # every trial counts: the LC starts near its rest
        out["statistics_psyneulink"] = {mode: task_statistics(pnl_run, mode, args.pnl_trials, 0) for mode in MODES}
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(f"{args.out} ({source})")
    for key in ("statistics", "statistics_psyneulink"):
        for mode, stats in out.get(key, {}).items():
            print(key, mode, {k: round(v, 4) for k, v in stats.items()})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
