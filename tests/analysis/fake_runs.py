"""Hand-made runs and results folders following the results schema, independent of the simulator (imported by
the analysis tests and their conftest)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

SOURCES = ("S-A", "S-A", "S-B", "S-C", "S-D")
NAMES = ("C1", "C2", "C3", "C4", "C5")


def make_run(contexts, stored, *, n_frames=100, seed=0):
    """Episodes and modules tables of one run.

    ``contexts``: the context index of each episode; ``stored``: list of
    (episode, source, gates) for the modules, in storage order. ``n_frames``: an int or
    one value per episode.
    """
    rng = np.random.default_rng(seed)
    n = len(contexts)
    frames = np.broadcast_to(np.asarray(n_frames, dtype=np.int64), (n,)).copy()
    learned = np.zeros(n, dtype=bool)
    learned[[e for e, _, _ in stored]] = True
    steps = np.concatenate([[0], np.cumsum(frames)[:-1]])
    familiar = rng.random(n) < 0.2
    error = np.linspace(2.0, 0.2, n) + 0.05 * rng.random(n)
    episodes = pd.DataFrame({
        "episode": np.arange(n),
        "step": steps,
        "context": np.asarray(contexts, dtype=np.int64),
        "n_frames": frames,
        "familiar": familiar,
        "gating_module": np.where(familiar, 0, -1),
        "error": error,
        "episode_error": error + 0.01,
        "min_frozen_error": np.where(np.cumsum(learned) > 0, 0.5, np.nan),
        "module_learned": learned,
        "n_modules": np.cumsum(learned),
        "da": np.where(familiar, -100.0, 0.05 * rng.standard_normal(n)),
        "q_engage": rng.random(n),
        "q_disengage": rng.random(n),
        "action": np.where(rng.random(n) < 0.5, "engage", "disengage"),
        "next_context": np.roll(np.asarray(contexts), -1),
        "epsilon": 0.6 * 0.995 ** np.arange(n),
        "ne_tonic": rng.random(n),
        "ne_phasic": learned.astype(float),
    })
    modules = pd.DataFrame({
        "module": np.arange(len(stored), dtype=np.int64),
        "step": np.array([steps[e] + frames[e] for e, _, _ in stored], dtype=np.int64),
        "episode": np.array([e for e, _, _ in stored], dtype=np.int64),
        "context": np.array([contexts[e] for e, _, _ in stored], dtype=np.int64),
        "n_clusters": np.full(len(stored), 1500, dtype=np.int64),
        "source": pd.Series([s for _, s, _ in stored], dtype=object),
        "quality": np.full(len(stored), 0.95),
        "gates": pd.Series([g for _, _, g in stored], dtype=object),
    })
    return episodes, modules


#: eq 14's learning rate recorded for each condition's PFC in the hand-made config.toml
PFC_ALPHA = {"curious": 0.3, "random_switching": 0.05}


def write_results(root, runs, alphas=PFC_ALPHA, control="random_switching"):
    """Write a results folder: ``runs`` maps condition -> list of (episodes, modules), the first
    the reference; the config.toml records each condition's PFC (type and ``alpha``, ``alphas``)
    and the experiment's ``control`` condition as a real one does."""
    root.mkdir(parents=True, exist_ok=True)
    config = 'circuit = "neurocur/circuits/cd_misfa.toml"\nseed = 1\n'
    if control is not None:
        config += f'control = "{control}"\n'
    for condition in runs:
        config += f"\n[conditions.\"{condition}\"]\n"             # quoted: a sweep's names hold '@' and '='
        if condition in alphas:
            config += (f"\n[conditions.\"{condition}\".resolved_circuit.regions.PFC]\ntype = \"pfc.lspi\"\n"
                       f"params = {{ alpha = {alphas[condition]} }}\n")
    (root / "config.toml").write_text(config)
    for condition, tables in runs.items():
        for run, (episodes, modules) in enumerate(tables):
            folder = root / "runs" / condition / f"run-{run:03d}"
            folder.mkdir(parents=True)
            for name, table in (("episodes", episodes), ("modules", modules)):
                table = table.copy()
                table.insert(0, "condition", condition)
                table.insert(1, "run", run)
                table.to_parquet(folder / f"{name}.parquet")
            (folder / "run.json").write_text(json.dumps({
                "run": run, "condition": condition, "learnable": ["S-A", "S-B", "S-C"],
                "contexts": [{"name": n, "source": s} for n, s in zip(NAMES, SOURCES)]}))
    (root / "summary.json").write_text("{}")
    return root


# Context sequence shared by the hand-made runs: 60 episodes cycling C1..C5 in blocks.
CYCLE = [c for c in range(5) for _ in range(3)] * 4

#: (stored modules per run) for the two conditions of the hand-made results folder.
CURIOUS = [
    [(10, "S-A", "C1,C2"), (25, "S-B", "C3"), (50, "S-C", "C4")],            # exact, τ = 1
    [(10, "S-A", "C1,C2"), (25, "S-C", "C4"), (50, "S-B", "C3")],            # τ = 1/3
    [(10, "S-A", "C1"), (25, "S-B", "C3"), (40, "S-C", "C4"), (55, "S-D", "")],  # exact, S-D stored
    [(10, "S-A", "C2"), (40, "S-B", "")],                                     # gated 1, τ = 1
]
RANDOM = [
    [],
    [(30, "S-A", "C1,C2")],
    [(20, "S-B", "C1"), (45, "S-A", "")],                                     # gated 0, τ = -1
]
