"""The shipped CD-MISFA circuit and its variants, run on the stand-in world."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.circuit import Circuit
from neurocur.config import ConfigError

EPISODE_COLUMNS = ["episode", "step", "context", "n_frames", "reward", "familiar", "gating_module", "error",
                   "episode_error", "min_frozen_error", "module_learned", "n_modules", "da", "q_engage", "q_disengage", "action",
                   "next_context", "epsilon", "ne_tonic", "ne_phasic"]


@pytest.fixture(scope="module")
def circuit(circuits_dir, small):
    return Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides=small)


@pytest.fixture(scope="module")
def run(circuit, make_world):
    return circuit.build(make_world(), seed=11).run(20 * 400)


def test_builds_and_schedules(circuit):
    assert circuit.step_order == ("sensory", "EC", "HPC", "VTA", "PFC", "LC")
    assert circuit.learn_order == ("EC", "HPC")
    text = circuit.schedule()
    assert "  LC.next_context -> sensory.next_context" in text and "  HPC.familiar -> EC.familiar" in text
    assert set(circuit.graph.nodes) == {"sensory", "EC", "HPC", "VTA", "PFC", "LC"}
    assert circuit.graph.edges["LC", "sensory"]["links"][0].delayed


def test_episode_table_schema_and_consistency(run):
    df = run.episodes()
    assert list(df.columns) == EPISODE_COLUMNS
    assert len(df) == 400 and run.n_frames == 8000
    assert df.dtypes["familiar"] == np.bool_ and df.dtypes["n_modules"] == np.int64 and df.dtypes["context"] == np.int64
    np.testing.assert_array_equal(df["step"], 20 * np.arange(400))
    assert set(df["action"]) <= {"engage", "disengage"}
    # the decision at episode k names the context of episode k+1
    np.testing.assert_array_equal(df["next_context"].iloc[:-1], df["context"].iloc[1:])
    stay = df["action"] == "engage"
    np.testing.assert_array_equal(df["next_context"][stay], df["context"][stay])
    assert (df["next_context"][~stay] != df["context"][~stay]).all()
    assert (df.loc[df.familiar, "da"] == -100.0).all()
    assert (df.loc[df.familiar, "gating_module"] >= 0).all() and (df.loc[~df.familiar, "gating_module"] == -1).all()
    assert not (df.familiar & df.module_learned).any()
    np.testing.assert_array_equal(df["n_modules"], np.cumsum(df["module_learned"]))
    assert df["module_learned"].sum() >= 1
    # epsilon: x0.995 per episode, back to 0.6 when a module is stored
    eps = df["epsilon"].to_numpy()
    for k in range(1, len(df)):
        assert eps[k] == pytest.approx(0.6 if df.module_learned.iloc[k] else eps[k - 1] * 0.995)
    assert ((df.ne_tonic >= 0) & (df.ne_tonic <= 1) & (df.ne_phasic >= 0) & (df.ne_phasic <= 1)).all()
    assert (df.loc[df.module_learned, "ne_phasic"] == 1.0).all()


def test_modules_table_and_library(run):
    products = run.products()
    modules = products["modules"]
    df = run.episodes()
    assert list(modules.columns) == ["module", "step", "episode", "context", "n_clusters"]
    learned = df[df.module_learned]
    np.testing.assert_array_equal(modules["module"], np.arange(len(learned)))
    np.testing.assert_array_equal(modules["episode"], learned["episode"])
    np.testing.assert_array_equal(modules["step"], learned["step"])
    np.testing.assert_array_equal(modules["context"], learned["context"])
    assert (modules["n_clusters"] > 0).all()
    ec, hpc = run.regions["EC"], run.regions["HPC"]
    assert len(ec.library) == len(hpc.library) == len(modules) and hpc.threshold == 0.3
    assert products["library"] == ec.library and set(products) == {"library", "modules"}
    # EC's stacked encoding equals every frozen module's own transform (eq 2)
    episode = run.regions["sensory"].episode
    y, lib, _ = ec.step(episode)
    for m, module in enumerate(ec.library):
        np.testing.assert_allclose(lib[:, m, :], module.transform(episode.frames), atol=1e-10)
    np.testing.assert_allclose(y, ec.adaptive.transform(episode.frames), atol=1e-10)


def test_region_seeds_follow_names_not_positions(circuit, make_world):
    from neurocur.circuit import Circuit

    reordered = Circuit(dict(reversed(list(circuit.specs.items()))), circuit.links)
    assert reordered.step_order == circuit.step_order and list(reordered.specs) != list(circuit.specs)
    a = circuit.build(make_world(), seed=5).run(20 * 120)
    b = reordered.build(make_world(), seed=5).run(20 * 120)
    pd.testing.assert_frame_equal(a.episodes(), b.episodes())
    pd.testing.assert_frame_equal(a.products()["modules"], b.products()["modules"])


def test_same_seed_same_tables(circuit, make_world):
    a = circuit.build(make_world(), seed=5).run(20 * 120)
    b = circuit.build(make_world(), seed=5).run(20 * 120)
    pd.testing.assert_frame_equal(a.episodes(), b.episodes())
    pd.testing.assert_frame_equal(a.products()["modules"], b.products()["modules"])
    pd.testing.assert_frame_equal(a.probes(), b.probes())
    c = circuit.build(make_world(), seed=6).run(20 * 120)
    assert not a.episodes()["context"].equals(c.episodes()["context"])


def test_frame_recording(circuit, make_world):
    sim = circuit.build(make_world(), seed=2, record_frames=True).run(20 * 30)
    long = sim.probes()
    n = sim.n_frames
    for region, signal in (("sensory", "state"), ("EC", "y0"), ("EC", "y1"), ("HPC", "frame_error")):
        rows = long[(long.region == region) & (long.signal == signal)]
        assert len(rows) == n, (region, signal)
        np.testing.assert_array_equal(rows["step"], np.arange(n))
    states = long[long.signal == "state"]["value"].to_numpy().reshape(30, 20)
    contexts = sim.episodes()["context"]
    assert (states[:, 0] >= 0).all() and (np.diff(states, axis=1) % 20 == 1).all()
    assert len(contexts) == 30
    episode_level = long[(long.region == "VTA") & (long.signal == "da")]
    np.testing.assert_array_equal(episode_level["value"], sim.episodes()["da"])


def test_lesioned_lc_switches_uniformly(make_world, circuits_dir, small):
    circuit = Circuit.from_toml(circuits_dir / "lesion_lc_random.toml", overrides=small)
    assert circuit.lesions == (("LC", "random", {}),)
    assert circuit.specs["LC"].params.epsilon0 == 1.0 and circuit.specs["LC"].params.decay == 1.0
    df = circuit.build(make_world(), seed=8).run(20 * 1200).episodes()
    n = len(df)
    assert (df["epsilon"] == 1.0).all() and (df["ne_tonic"] == 0.5).all()
    engage = (df["action"] == "engage").to_numpy()
    assert abs(engage.mean() - 0.5) < 4.5 * np.sqrt(0.25 / n)
    # after a disengage from context c the next context is uniform over the two others
    moved = df[~engage]
    for c in range(3):
        targets = moved.loc[moved.context == c, "next_context"]
        k, m = (targets == (c + 1) % 3).sum(), len(targets)
        assert m > 100 and abs(k / m - 0.5) < 4.5 * np.sqrt(0.25 / m)
    # the visits themselves are uniform over contexts (chi-square, 2 dof, p = 1e-4)
    counts = np.bincount(df["context"], minlength=3)
    chi2 = ((counts - n / 3) ** 2 / (n / 3)).sum()
    assert chi2 < 18.4


def test_variant_files(make_world, circuits_dir, small):
    novelty = Circuit.from_toml(circuits_dir / "vta_novelty.toml", overrides=small)
    assert novelty.specs["VTA"].type_name == "vta.novelty"
    df = novelty.build(make_world(), seed=1).run(20 * 40).episodes()
    visits = df.groupby("context").cumcount() + 1
    np.testing.assert_allclose(df["da"], 1.0 / np.sqrt(visits))
    gating = Circuit.from_toml(circuits_dir / "lesion_gating.toml", overrides=small)
    assert gating.specs["HPC"].params.gating is False
    df = gating.build(make_world(), seed=1).run(20 * 200).episodes()
    assert not df["familiar"].any() and (df["da"] != -100.0).all()
    base = Circuit.from_toml(circuits_dir / "cd_misfa.toml")
    assert base.to_dict()["regions"]["HPC"]["params"]["threshold"] == 0.3
    assert Circuit.from_toml(circuits_dir / "lesion_lc_random.toml").to_dict()["lesions"] == [{"region": "LC", "how": "random"}]


def test_python_lesion_and_replace_match_files(circuit, make_world, circuits_dir, small):
    from neurocur.regions.vta import NoveltyVTA

    by_python = circuit.lesion("LC", how="random").build(make_world(), seed=4).run(20 * 60).episodes()
    by_file = Circuit.from_toml(circuits_dir / "lesion_lc_random.toml", overrides=small).build(make_world(), seed=4)
    pd.testing.assert_frame_equal(by_python, by_file.run(20 * 60).episodes())
    replaced = circuit.replace("VTA", NoveltyVTA("VTA", scale=3.0)).build(make_world(), seed=4).run(20 * 5)
    assert replaced.episodes()["da"].iloc[0] == 3.0


def test_replace_names_or_drops_the_edges_the_new_region_has_no_port_for(make_world, circuits_dir, small):
    """vta.state_progress reads HPC's progress; a model without that input needs the edge dropped."""
    from neurocur.regions.vta import NoveltyVTA

    circuit = Circuit.from_toml(circuits_dir / "vta_state_progress.toml", overrides=small)
    with pytest.raises(ConfigError, match=r"key 'replace.VTA': .*drop_edges=True.*got vta.novelty, which has no "
                                          r"port for HPC.progress -> VTA.progress"):
        circuit.replace("VTA", {"type": "vta.novelty"})
    swapped = circuit.replace("VTA", NoveltyVTA("VTA", scale=3.0), drop_edges=True)
    assert {str(k) for k in circuit.links} - {str(k) for k in swapped.links} == {"HPC.progress -> VTA.progress"}
    novelty = Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides=small).replace("VTA", NoveltyVTA("VTA", scale=3.0))
    pd.testing.assert_frame_equal(swapped.build(make_world(), seed=4).run(20 * 60).episodes(),
                                  novelty.build(make_world(), seed=4).run(20 * 60).episodes())


def test_engage_gives_two_episodes(make_world, circuits_dir, small):
    circuit = Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides={**small, "sensory.episodes_on_engage": 2})
    df = circuit.build(make_world(), seed=3).run(20 * 100).episodes()
    stayed = (df["action"] == "engage").to_numpy()[:-1]
    np.testing.assert_array_equal(df["n_frames"].iloc[1:], np.where(stayed, 40, 20))
    np.testing.assert_array_equal(df["step"].iloc[1:], np.cumsum(df["n_frames"]).iloc[:-1])


def test_overrides_are_validated_against_the_region(make_world, circuits_dir, small):
    with pytest.raises(ConfigError, match="key 'HPC.freeze': expected one of 'context_mean'"):
        Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides={"HPC.freeze": "mean"})
    with pytest.raises(ConfigError, match="key 'EC.n_components': expected at most n_pca = 3, got 4"):
        Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides={"EC.n_components": 4})
    with pytest.raises(ValueError, match="smaller than the world's 20 context-states"):
        Circuit.from_toml(circuits_dir / "cd_misfa.toml", overrides={"HPC.n_states": 10}).build(make_world(), 0)


@pytest.mark.parametrize("seed", [0, 1])
def test_without_gating_the_adaptive_module_relearns_what_is_stored(seed, circuit, make_world):
    """The paper's gating claim (section 4.1): it keeps the adaptive module from learning an already
    stored representation. Lesioned, the stand-in world's one slow source is stored again and again
    (docs/hypotheses.md, entry 9, measures it on the synthetic world)."""
    def modules_stored(c):
        return int(c.build(make_world(), seed=seed).run(20_000).episodes()["module_learned"].sum())

    intact, lesioned = modules_stored(circuit), modules_stored(circuit.lesion("HPC", "no_gating"))
    assert 1 <= intact <= 4 and lesioned > 10 * intact


def test_the_world_is_seeded_under_its_own_key_not_by_a_region(circuit, make_world):
    """Renaming the region that shows the world leaves the world's draws (its mixing matrices) as they
    were; they are those of a world seeded with the run's world key (scheduler.world_seed)."""
    import dataclasses

    from neurocur.scheduler import world_seed

    def rename(name):
        return "eyes" if name == "sensory" else name

    renamed = Circuit({rename(n): dataclasses.replace(s, name=rename(n)) for n, s in circuit.specs.items()},
                      [dataclasses.replace(k, src=rename(k.src), dst=rename(k.dst)) for k in circuit.links])
    worlds = [make_world(), make_world(), make_world(), make_world()]
    circuit.build(worlds[0], seed=5)
    renamed.build(worlds[1], seed=5)
    worlds[2].np_random = np.random.default_rng(world_seed(np.random.SeedSequence(5)))
    worlds[2].reset()
    circuit.build(worlds[3], seed=6)
    for source in ("S", "N"):
        np.testing.assert_array_equal(worlds[0].mixing[source], worlds[1].mixing[source])
        np.testing.assert_array_equal(worlds[0].mixing[source], worlds[2].mixing[source])
        assert not np.array_equal(worlds[0].mixing[source], worlds[3].mixing[source])
    assert "eyes" in renamed.specs and "sensory" not in renamed.specs
