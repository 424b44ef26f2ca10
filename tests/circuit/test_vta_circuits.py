"""The VTA models in circuits: the shipped circuit files, every model in short runs of the synthetic and
the iCub experiments (its recorded DA is the model applied to the recorded HPC and sensory signals),
the extrinsic reward reaching the VTA, and clear errors for bad input."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from neurocur.circuit import Circuit, Link, RegionSpec
from neurocur.config import ConfigError
from neurocur.experiments import run_one
from neurocur.regions import REGIONS
from neurocur.regions.vta import VTARole
from neurocur.regions.vta_td import TDVTA

#: the shipped circuit file of each VTA model
CIRCUIT_FILES = {"vta_novelty": "vta.novelty", "vta_abs_lp": "vta.abs_learning_progress",
                 "vta_content_novelty": "vta.content_novelty", "vta_surprise": "vta.surprise", "vta_td": "vta.td",
                 "vta_mixture": "vta.mixture"}
VTA_TYPES = [n for n in REGIONS.names() if n.startswith("vta.")]


#: where the models that read a ``progress`` input get it (their circuit files' edges)
PROGRESS = {"vta.state_progress": ("HPC", "progress"), "vta.slowness_progress": ("EC", "slowness_progress")}


def with_vta(circuit: Circuit, type_name: str) -> Circuit:
    """``circuit`` with the VTA model ``type_name`` (default parameters): the role's ports keep their
    edges, a ``progress`` input is wired as the model's circuit file wires it, and edges into
    inputs it does not have are dropped."""
    cls = REGIONS.get(type_name)
    role = {s.name for s in VTARole.inputs}
    links = tuple(k for k in circuit.links if k.dst != "VTA" or k.input in role)
    extra = tuple(Link(*PROGRESS[type_name], "VTA", s.name) for s in cls.inputs if s.name not in role)
    return Circuit({**circuit.specs, "VTA": RegionSpec("VTA", cls, cls.Params())}, links + extra,
                   source=circuit.source, lesions=circuit.lesions)


def replayed(circuit: Circuit, episodes, error_column: str) -> np.ndarray:
    """The DA a fresh instance of the circuit's VTA model gives on the recorded inputs."""
    spec = circuit.specs["VTA"]
    vta = spec.cls("VTA", spec.params)

    class World:
        n_contexts = int(episodes["context"].max()) + 1

    vta.bind(World())
    vta.reset(np.random.default_rng(0))
    cols = [episodes[c].tolist() for c in ("context", error_column, "familiar", "module_learned", "reward")]
    return np.array([vta.step(*x)[0] for x in zip(*cols)])


def test_the_vta_reads_the_sensory_reward_in_every_shipped_circuit(circuits_dir):
    for path in sorted(circuits_dir.glob("*.toml")):
        circuit = Circuit.from_toml(path)
        links = {(k.src, k.signal, k.dst) for k in circuit.links}
        assert "VTA" not in circuit.specs or ("sensory", "reward", "VTA") in links, path.name


@pytest.mark.parametrize("name, type_name", CIRCUIT_FILES.items())
def test_circuit_file_swaps_the_vta(name, type_name, circuits_dir, small, make_world):
    circuit = Circuit.from_toml(circuits_dir / f"{name}.toml", overrides=small)
    assert circuit.specs["VTA"].type_name == type_name
    episodes = circuit.build(make_world(), seed=2).run(3000).episodes()
    assert np.isfinite(episodes["da"]).all() and (episodes["reward"] == 0.0).all()
    np.testing.assert_array_equal(episodes["da"], replayed(circuit, episodes, "error"))


def replayed_progress(sim) -> np.ndarray:
    """HPC's ``progress`` of every episode, replayed from the recorded frames: the mean, over the
    frames with an error now and one stored at their state's previous visit, of stored minus now.
    Each (context, state) keeps its last error; the table starts afresh after a module is stored."""
    episodes, probes = sim.episodes(), sim.probes()
    frames = probes[probes["signal"].isin(["state", "frame_error"])]
    frames = frames.set_index(["episode", "step", "signal"])["value"].unstack("signal")
    stored, progress = {}, []
    for (_, block), row in zip(frames.groupby(level="episode"), episodes.itertuples()):
        keys = [(row.context, int(s)) for s in block["state"]]
        drops = [stored[k] - e for k, e in zip(keys, block["frame_error"]) if e == e and k in stored]
        progress.append(np.mean(drops) if drops else np.nan)
        stored.update((k, e) for k, e in zip(keys, block["frame_error"]) if e == e)
        if row.module_learned:
            stored = {}
    return np.array(progress)


def test_state_progress_is_the_same_state_drop(circuits_dir, small, make_world):
    circuit = Circuit.from_toml(circuits_dir / "vta_state_progress.toml", overrides=small)
    assert circuit.specs["VTA"].type_name == "vta.state_progress"
    sim = circuit.build(make_world(), seed=4, record_frames=True).run(3000)
    episodes, progress = sim.episodes(), replayed_progress(sim)
    assert episodes["familiar"].any() and np.isfinite(progress).sum() >= 30
    expected = np.where(episodes["familiar"], -100.0, np.nan_to_num(progress, nan=0.0))
    np.testing.assert_allclose(episodes["da"], expected, rtol=1e-12, atol=1e-15)


def delta(y, starts):
    """Eq 4's Δ of one output over a block of segments: the mean of its squared successive differences."""
    bounds = [*starts.tolist(), len(y)]
    steps = [y[t + 1] - y[t] for a, b in zip(bounds[:-1], bounds[1:]) for t in range(a, b - 1)]
    return sum(d * d for d in steps) / len(steps)


def test_slowness_progress_is_the_drop_of_the_slowest_outputs_delta(circuits_dir, small, make_world):
    """DA on an unfamiliar episode = Δ(y₀) under the adaptive module's projection at the context's
    previous visit minus Δ(y₀) under its projection now, both on this episode's frames; 0 on a
    context's first visit with a module (and before the module has learned); -100 when familiar."""
    circuit = Circuit.from_toml(circuits_dir / "vta_slowness_progress.toml",
                                overrides={**small, "sensory.episodes_on_engage": 2})  # blocks of two segments too
    assert circuit.specs["VTA"].type_name == "vta.slowness_progress"
    sim = circuit.build(make_world(), seed=3)
    ec = sim.regions["EC"]
    assert "slowness_progress" in ec.wired
    seen, expected = {}, []
    while sim.n_frames < 3000:
        module = ec.adaptive
        now = module.projection_[:, 0].copy() if module.__sklearn_is_fitted__() else None
        sim.run(1)
        episode = ec.episode
        before = seen.get((module, episode.context))  # keyed by the object: an id is reused once it is freed
        if now is not None:
            seen[(module, episode.context)] = now
        dropped = (delta(episode.frames @ before, episode.starts) - delta(episode.frames @ now, episode.starts)
                   if before is not None and now is not None else 0.0)
        expected.append(dropped)
    episodes = sim.episodes()
    assert episodes["familiar"].any() and episodes["module_learned"].any()
    assert (np.array(expected)[~episodes["familiar"]] != 0).sum() >= 10 and (episodes["n_frames"] > 30).any()
    np.testing.assert_allclose(episodes["da"], np.where(episodes["familiar"], -100.0, expected), rtol=1e-9, atol=1e-10)


def test_an_unread_optional_output_is_not_computed(circuits_dir, small, make_world):
    sim = Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides=small).build(make_world(), seed=3)
    ec = sim.regions["EC"]
    assert ec.wired == {"features", "library_features"}
    sim.run(600)
    assert np.isnan(ec.step(ec.episode)[2])


def paying(world_class):
    """``world_class`` paying ``10 + context`` for a visit of contexts 1 and 2, nothing for context 0."""

    class Paying(world_class):
        def _visit(self, context):
            return dataclasses.replace(super()._visit(context), reward=float(10 + context) * (context > 0))

    return Paying


def test_td_learns_the_worlds_reward_in_the_circuit(circuits_dir, small, make_world):
    circuit = Circuit.from_toml(circuits_dir / "vta_td.toml", overrides=small)
    sim = circuit.build(paying(make_world)(), seed=4).run(20 * 600)
    episodes = sim.episodes()
    expected = np.where(episodes["context"] > 0, 10.0 + episodes["context"], 0.0)
    np.testing.assert_array_equal(episodes["reward"], expected)
    np.testing.assert_array_equal(episodes["da"], replayed(circuit, episodes, "error"))
    value = sim.regions["VTA"].value
    assert value[2] > value[1] > value[0] > 10  # each context is worth its own reward and what follows


@pytest.fixture(scope="module")
def synthetic(short_experiment):
    return short_experiment("synthetic", 15000)


@pytest.mark.parametrize("type_name", VTA_TYPES)
def test_every_vta_model_runs_in_the_synthetic_experiment(synthetic, type_name):
    cond = synthetic.conditions["curious"]
    circuit = with_vta(cond.circuit, type_name)
    result = run_one(dataclasses.replace(cond, circuit=circuit), 0, synthetic.steps, synthetic.run_seed(0))
    episodes = result.episodes
    assert episodes["familiar"].any() and episodes["module_learned"].any()
    if type_name in PROGRESS:  # their input is not recorded per episode: replayed from frames above
        assert (episodes["da"][episodes["familiar"]] == -100.0).all() and (episodes["da"][~episodes["familiar"]] != 0).any()
    else:
        np.testing.assert_array_equal(episodes["da"], replayed(circuit, episodes, "episode_error"))
    if type_name == "vta.td":
        assert (episodes["da"] == 0.0).all()  # no extrinsic reward in the synthetic world


def test_the_mixture_halves_learning_progress_and_leaves_the_behaviour(synthetic):
    """Without extrinsic reward, DA = 0.5 LP: PFC's values halve and every decision stays the same."""
    cond = synthetic.conditions["curious"]
    runs = {t: run_one(dataclasses.replace(cond, circuit=with_vta(cond.circuit, t)), 0,
                       synthetic.steps, synthetic.run_seed(0)).episodes for t in ("vta.learning_progress", "vta.mixture")}
    lp, mix = runs["vta.learning_progress"], runs["vta.mixture"]
    np.testing.assert_array_equal(mix["context"], lp["context"])
    np.testing.assert_allclose(mix["da"], 0.5 * lp["da"], rtol=1e-15)


@pytest.fixture(scope="module")
def icub(short_experiment):
    return short_experiment("icub", 600)


@pytest.mark.parametrize("type_name", VTA_TYPES)
def test_every_vta_model_runs_in_the_icub_experiment(icub, type_name):
    cond = icub.conditions["curious"]
    circuit = with_vta(cond.circuit, type_name)
    episodes = run_one(dataclasses.replace(cond, circuit=circuit), 0, icub.steps, icub.run_seed(0)).episodes
    assert episodes["module_learned"].any() and np.isfinite(episodes["da"]).all()
    if type_name not in PROGRESS:  # their input is not recorded per episode: replayed from frames above
        np.testing.assert_array_equal(episodes["da"], replayed(circuit, episodes, "error"))


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize("table, key, expected", [
    ('type = "vta.curiosity"', "replace.VTA.type", "a registered region type ("),
    ('type = "vta.td"\nparams = { discount = 1.0 }', "replace.VTA.params.discount", "a number >= 0 and < 1"),
    ('type = "vta.td"\nparams = { rate = 0 }', "replace.VTA.params.rate", "a number > 0 and <= 1"),
    ('type = "vta.surprise"\nparams = { scale = -1.0 }', "replace.VTA.params.scale", "a number > 0"),
    ('type = "vta.content_novelty"\nparams = { scale = "big" }', "replace.VTA.params.scale", "a number > 0"),
    ('type = "vta.abs_learning_progress"\nparams = { bordeom = 1 }', "replace.VTA.params.bordeom",
     "a parameter of LearningProgressParams (boredom)"),
    ('type = "vta.mixture"\nparams = { weight = 1.5 }', "replace.VTA.params.weight", "a number >= 0 and <= 1"),
    ('type = "vta.mixture"\nparams = { intrinsic = "vta.td" }', "replace.VTA.params.intrinsic",
     "one of 'vta.learning_progress', 'vta.abs_learning_progress', 'vta.novelty'"),
    ('type = "vta.mixture"\nparams = { intrinsic_params = { scale = 2.0 } }',
     "replace.VTA.params.intrinsic_params.scale", "a parameter of LearningProgressParams (boredom)"),
    ('type = "vta.mixture"\nparams = { intrinsic = "vta.novelty", intrinsic_params = { boredom = 0.0 } }',
     "replace.VTA.params.intrinsic_params.boredom", "a parameter of NoveltyParams (scale)"),
    ('type = "vta.mixture"\nparams = { intrinsic = "vta.surprise", intrinsic_params = { scale = -2.0 } }',
     "replace.VTA.params.intrinsic_params.scale", "a number > 0"),
    ('type = "vta.mixture"\nparams = { boredom = -10.0 }', "replace.VTA.params.boredom",
     "a parameter of MixtureParams (weight, intrinsic, intrinsic_params)"),
])
def test_bad_vta_tables_name_the_file_and_key(tmp_path, table, key, expected):
    path = tmp_path / "bad.toml"
    path.write_text(f'extends = "cd_misfa"\n[replace.VTA]\n{table}\n')
    with pytest.raises(ConfigError) as info:
        Circuit.from_toml(path)
    assert (info.value.source, info.value.key) == (str(path), key)
    assert info.value.expected.startswith(expected)
    if key.endswith(".type"):  # the registry's message lists every VTA model
        assert all(name in info.value.expected for name in VTA_TYPES)


def test_bad_vta_parameters_from_python_and_overrides():
    with pytest.raises(ConfigError, match=r"TDParams: key 'discount': expected a number >= 0 and < 1, got 1.5"):
        TDVTA("VTA", discount=1.5)
    with pytest.raises(ConfigError, match=r"overrides: key 'VTA.weight': expected a number >= 0 and <= 1, got -0.5"):
        Circuit.from_toml("vta_mixture", overrides={"VTA.weight": -0.5})
