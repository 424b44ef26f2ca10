"""Declared sources of the synthetic world: noise kinds, sinusoid pairs, non-stationary files, Ω, errors."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.contexts.sources import (
    graded_sinusoids,
    isotropic_random_walk,
    noise_source,
    random_walk,
    sinusoid_pair,
    white_noise,
)
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.learn.incsfa import IncSFA
from neurocur.learn.omega import omega

IID = np.random.default_rng(5).standard_normal((1000, 2))  # an i.i.d.-noise "file"
SMALL = {"frame_shape": (10, 10), "clock_offsets": "zero"}


def test_noise_kinds():
    x = white_noise(0, 20000, 3)
    assert x.shape == (20000, 3)
    np.testing.assert_allclose(x.std(axis=0), 1.0, atol=0.02)
    lag1 = [np.corrcoef(x[1:, d], x[:-1, d])[0, 1] for d in range(3)]
    np.testing.assert_allclose(lag1, 0.0, atol=0.03)  # independent samples
    walk = random_walk(0, 20000, 3)
    np.testing.assert_allclose(np.diff(walk, axis=0), x[1:], atol=1e-9)  # the same draws, summed
    np.testing.assert_array_equal(walk[0], x[0])
    np.testing.assert_array_equal(noise_source("isotropic_walk", 4), isotropic_random_walk(4))
    with pytest.raises(ValueError, match="an isotropic walk has 2 dimensions"):
        noise_source("isotropic_walk", 0, dims=3)
    with pytest.raises(ValueError, match="unknown noise kind 'pink'"):
        noise_source("pink", 0)


def test_graded_sinusoids_pick_the_fast_cycles_nearest_each_omega():
    family = graded_sinusoids([0.99, 0.9988, 0.9997, 0.9997])
    assert list(family) == [70, 24, 12]  # the paper's S-B and S-C are k = 24 and 12
    for k, value in family.items():
        assert value == pytest.approx(omega(sinusoid_pair(k), 0.05), abs=1e-12)
    assert family[24] == pytest.approx(0.9988, abs=5e-5) and family[12] == pytest.approx(0.9997, abs=5e-5)


def _epochs(world, n_epochs, seed=None):
    """Frames of the next ``n_epochs`` whole epochs of context 0 (clocks from zero), one array per
    epoch; with ``seed``, a new run first (whose first visit is the first of the epochs)."""
    visits = [world.reset(seed=seed)[0].frames] if seed is not None else []
    per_epoch = world.n_states // world.visit_length
    visits += [world.step(0)[0].frames for _ in range(per_epoch * n_epochs - len(visits))]
    return np.split(np.concatenate(visits), n_epochs)


def test_declared_sinusoid_and_file_sources_are_replayed():
    for contexts in (["G", "X"], ["X", "G"]):
        world = SyntheticWorld(contexts, sources={"G": {"sinusoid": 24}, "X": IID}, **SMALL)
        a, b = _epochs(world, 2, seed=0)
        np.testing.assert_array_equal(a, b)
        assert not world.redraws(0) and world.source_spec().learnable == tuple(contexts)
    np.testing.assert_array_equal(world.source_signal("G"), sinusoid_pair(24))
    np.testing.assert_array_equal(world.source_signal("X"), IID)


@pytest.mark.parametrize("kind", ["white", "random_walk", "isotropic_walk"])
def test_noise_is_redrawn_every_epoch_centred_and_deterministic_by_seed(kind):
    worlds = [SyntheticWorld(["TV"], sources={"TV": {"noise": kind, "scale": 3.0}}, **SMALL) for _ in range(2)]
    first = _epochs(worlds[0], 3, seed=7)
    np.testing.assert_array_equal(np.concatenate(first), np.concatenate(_epochs(worlds[1], 3, seed=7)))
    assert not np.allclose(first[0], first[1]) and not np.allclose(first[1], first[2])
    for frames in first:  # every draw centred on 0.5, within [0, 1], touching one end
        assert frames.min() >= 0.0 and frames.max() <= 1.0
        np.testing.assert_allclose(frames.mean(axis=0), 0.5, atol=1e-12)
        assert min(frames.min(), 1.0 - frames.max()) == pytest.approx(0.0, abs=1e-12)
    signal = worlds[0].source_signal("TV")
    np.testing.assert_allclose(signal.mean(axis=0), 0.0, atol=1e-12)
    assert worlds[0].redraws(0) and worlds[0].source_spec().learnable == ()
    if kind == "white":
        assert signal.std() == pytest.approx(3.0, rel=0.1)  # scale is the standard deviation


def test_noise_follows_the_worlds_flag_unless_it_has_its_own():
    def replayed(world_flag, own):
        entry = {"noise": "white"} if own is None else {"noise": "white", "nonstationary": own}
        world = SyntheticWorld(["TV"], sources={"TV": entry}, nonstationary=world_flag, **SMALL)
        a, b = _epochs(world, 2, seed=1)
        return np.array_equal(a, b)

    assert not replayed(True, None) and replayed(False, None)
    assert replayed(True, False) and not replayed(False, True)


def test_a_nonstationary_file_shows_its_rows_in_a_new_order_every_epoch():
    world = SyntheticWorld(["X"], sources={"X": {"file": IID, "nonstationary": True}}, **SMALL)
    epochs = _epochs(world, 1, seed=2)
    signals = [world.source_signal("X")]
    for _ in range(2):  # the signal shown is replaced at the wrap that ends each epoch
        epochs += _epochs(world, 1)
        signals.append(world.source_signal("X"))
    for signal in signals:
        np.testing.assert_array_equal(np.sort(signal, axis=0), np.sort(IID, axis=0))  # the file's rows
    assert not np.array_equal(signals[0], IID)  # the first epoch is shuffled too
    assert not np.array_equal(signals[0], signals[1]) and not np.array_equal(signals[1], signals[2])
    # the same values each epoch, so the same normalisation: the frames are the file's frames, permuted
    flat = [np.sort(f.ravel()) for f in epochs]
    np.testing.assert_allclose(flat[0], flat[1], atol=1e-12)
    assert not np.allclose(epochs[0], epochs[1])
    assert world.source_spec().learnable == ()


def _axis_change(sources, seed, epochs=20):
    """Mean change (degrees, 0..90) of the slowest feature's axis in the source plane between the
    last ten pairs of successive epochs, IncSFA (the EC's rates) learning one context."""
    world = SyntheticWorld(["X"], sources=sources, **SMALL)
    sfa = IncSFA(1, 2, amnesic=2.0, mca_rate=0.05, mca_rates="equal", random_state=seed)
    axes = []
    for frames in _epochs(world, epochs, seed=seed):
        for visit in np.split(frames, 10):
            sfa.partial_fit(visit)
        d = sfa.projection_[:, 0] @ world.mixing("X")
        axes.append(np.arctan2(d[1], d[0]))
    change = np.degrees(np.abs(np.angle(np.exp(2j * np.diff(axes)))) / 2)
    return change[-10:].mean()


def test_an_iid_file_is_learned_when_replayed_but_not_when_resampled():
    """Replayed, the slowest feature settles on the file's one sampling accident; re-sampled
    (or white noise redrawn), its axis jumps by about 45 degrees (a random axis) every epoch.
    Two whitened dimensions: the frames' rank (a third CCIPCA component would only hold
    estimation error)."""
    replayed = [_axis_change({"X": IID}, seed) for seed in range(4)]
    resampled = [_axis_change({"X": {"file": IID, "nonstationary": True}}, seed) for seed in range(4)]
    white = [_axis_change({"X": {"noise": "white"}}, seed) for seed in range(4)]
    sinusoid = [_axis_change({"X": {"sinusoid": 24}}, seed) for seed in range(4)]
    assert max(replayed) < 0.1 and max(sinusoid) < 0.5
    assert min(resampled) > 20 and np.mean(resampled) > 30
    assert min(white) > 20 and np.mean(white) > 30


def test_omega_of_replayed_and_redrawn_sources():
    world = SyntheticWorld(["X", "R", "TV", "IW", "S-D", "S-A"],
                           sources={"X": IID, "R": {"file": IID, "nonstationary": True},
                                    "TV": {"noise": "white"}, "IW": {"noise": "isotropic_walk"}})
    world.reset(seed=0)
    value, per_draw = world.omega(0)
    assert value == pytest.approx(omega(IID, 0.05), abs=1e-9) and value < 0.996  # the learnable-looking file
    assert per_draw.tolist() == [value]
    assert world.omega(5)[0] == pytest.approx(0.99332, abs=1e-5)
    for context in (1, 2):  # re-sampled file and white noise: each draw alone looks learnable, joined they do not
        joined, per_draw = world.omega(context, draws=40)
        assert per_draw.shape == (40,) and np.median(per_draw) < 0.996 and joined > 0.997
    joined, per_draw = world.omega(3)
    assert joined > 0.99999 and per_draw.min() > 0.99999  # the isotropic walk: Omega = 1
    again = SyntheticWorld(["TV"], sources={"TV": {"noise": "white"}})
    again.reset(seed=0)
    # the draws come from the seed, not the world's stream; the mixing (another here) does not change Omega
    np.testing.assert_allclose(world.omega(2, seed=3)[1], again.omega(0, seed=3)[1], rtol=1e-9)


def test_omega_command_reports_redrawn_sources(tmp_path, capsys):
    np.save(tmp_path / "iid.npy", IID)
    (tmp_path / "tv.toml").write_text(
        'circuit = "cd_misfa"\nruns = 1\nsteps = 100\n[world]\ncontexts = ["X", "TV"]\n'
        '[world.sources]\nX = { file = "iid.npy", nonstationary = true }\nTV = { noise = "white" }\n')
    assert main(["omega", "--experiment", str(tmp_path / "tv.toml"), "--draws", "4"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[:2] for line in lines] == [["C1", "X"], ["C2", "TV"]]
    for line in lines:
        assert "redrawn every epoch: 4 draws joined; per draw mean 0.99" in line


def test_plain_paths_and_tables_in_an_experiment_file(tmp_path):
    from neurocur.experiments import load_experiment

    (tmp_path / "data").mkdir()
    np.save(tmp_path / "data" / "x.npy", IID)
    path = tmp_path / "exp.toml"
    path.write_text('circuit = "cd_misfa"\nruns = 1\nsteps = 100\n[world]\ncontexts = ["X", "Y", "S-A"]\n'
                    '[world.sources]\nX = "data/x.npy"\nY = { file = "data/x.npy", nonstationary = true }\n')
    world = next(iter(load_experiment(path).conditions.values())).make_world()
    world.reset(seed=0)
    np.testing.assert_array_equal(world.source_signal("X"), IID)
    assert world.redraws(1) and not world.redraws(0) and world.source_spec().learnable == ("S-A", "X")


@pytest.mark.parametrize("entry, key, expected", [
    ({"noise": "white", "scale": 0.0}, "sources.TV.scale", "a number > 0"),
    ({"noise": "white", "scale": -1}, "sources.TV.scale", "a number > 0"),
    ({"noise": "pink"}, "sources.TV.noise", "one of 'white', 'random_walk', 'isotropic_walk'"),
    ({"noise": "white", "dims": 1}, "sources.TV.dims", "an integer >= 2"),
    ({"noise": "isotropic_walk", "dims": 3}, "sources.TV.dims", "2 (an isotropic walk is 2-d)"),
    ({"noise": "white", "sinusoid": 5}, "sources.TV", "exactly one of file, sinusoid or noise"),
    ({"nonstationary": True}, "sources.TV", "exactly one of file, sinusoid or noise"),
    ({"sinusoid": 12, "scale": 2.0}, "sources.TV", "scale and dims only for a noise source"),
    ({"sinusoid": 500}, "sources.TV.sinusoid", "fewer than 1000 / 2 fast cycles"),
    ({"sinusoid": 1}, "sources.TV.sinusoid", "an integer >= 2"),
    ({"noise": "white", "nonstationary": "yes"}, "sources.TV.nonstationary", "a boolean"),
    ({"noise": "white", "colour": "pink"}, "sources.TV.colour", "a parameter of SourceParams"),
    (7, "sources.TV.file", "a file or folder path"),
])
def test_bad_sources_name_the_key(entry, key, expected):
    with pytest.raises(ConfigError) as info:
        SyntheticWorld(["TV", "S-A"], sources={"TV": entry})
    assert info.value.key == key and expected in info.value.expected


def test_a_bad_source_in_an_experiment_file_names_the_file_and_key(tmp_path):
    from neurocur.experiments import load_experiment

    path = tmp_path / "exp.toml"
    path.write_text('circuit = "cd_misfa"\nruns = 1\nsteps = 100\n[world]\ncontexts = ["TV"]\n'
                    '[world.sources]\nTV = { noise = "white", scale = -2.0 }\n')
    with pytest.raises(ConfigError) as info:
        load_experiment(path)
    assert info.value.source == str(path) and info.value.key == "world.sources.TV.scale"
    assert "a number > 0" in str(info.value) and "-2.0" in str(info.value)
