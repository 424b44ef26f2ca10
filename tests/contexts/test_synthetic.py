"""The synthetic world of section 4.1: sources, frames, clocks, normalisation, user sources."""

import numpy as np
import pytest

from neurocur.contexts.base import Episode
from neurocur.contexts.sources import (
    N_STEPS,
    SLOW_DIM,
    isotropic_random_walk,
    paper_source,
    sinusoid_pair,
)
from neurocur.contexts.synthetic import SyntheticWorld, mix_frames
from neurocur.learn.omega import derivative_eigenvalues, omega

PAPER_OMEGA = {"S-A": 0.9933, "S-B": 0.9988, "S-C": 0.9997}


_R = np.random.default_rng(99).standard_normal((400, 8))


def reduced(F):
    """(1000, 400) frames of rank <= 8 through a generic (400, 8) map: same rank, same Omega
    (whitening removes any invertible linear map of the signal's span), 50x cheaper."""
    return F @ _R


def centred_rank(X):
    s = np.linalg.svd(X - X.mean(axis=0), compute_uv=False)
    return int((s > 1e-9 * s[0]).sum())


@pytest.mark.parametrize("name", sorted(PAPER_OMEGA))
def test_learnable_sources_have_the_papers_omega(name):
    src = paper_source(name)
    assert src.shape == (N_STEPS, 2)
    assert omega(src, 0.05) == pytest.approx(PAPER_OMEGA[name], abs=5e-4)


def test_slow_dimension_is_dim_0():
    src = sinusoid_pair(24)
    # one cycle per epoch in dim 0, 24 in dim 1: dim 0's derivative is 24x smaller
    d = np.abs(np.diff(src, axis=0)).mean(axis=0)
    assert SLOW_DIM == 0 and d[0] * 20 < d[1]
    np.testing.assert_allclose(src[:, 0], np.sin(2 * np.pi * np.arange(N_STEPS) / N_STEPS))


@pytest.mark.parametrize("seed", range(5))
def test_sd_is_isotropic_and_has_the_highest_omega(seed):
    sd = isotropic_random_walk(seed)
    lam = derivative_eigenvalues(sd)
    assert lam[1] - lam[0] < 1e-2 * lam[1]  # equal slowness in every direction (up to the wrap step)
    value = omega(sd, 0.05)
    assert value > 0.9999
    assert value > max(omega(paper_source(n), 0.05) for n in PAPER_OMEGA)
    # and, unlike the periodic learnable sources, it is irregular: no single frequency carries it
    power = np.abs(np.fft.rfft(sd[:, 0])) ** 2
    assert power.max() < 0.9 * power.sum()


def test_sd_is_drawn_per_run():
    w = SyntheticWorld()
    w.reset(seed=1)
    a = w.source_signal("S-D").copy()
    w.reset(seed=2)
    assert not np.allclose(a, w.source_signal("S-D"))
    w.reset(seed=1)
    np.testing.assert_array_equal(a, w.source_signal("S-D"))


@pytest.mark.parametrize("normalise", ["global", "image"])
def test_frames_and_visits(normalise):
    w = SyntheticWorld(normalise=normalise, clock_offsets=[0, 950, 10, 20, 30])
    ep, info = w.reset(seed=3, context=1)
    assert isinstance(ep, Episode) and ep.context == 1 and info == {"context": 1}
    assert ep.frames.shape == (100, 400) and ep.frames.dtype == np.float64
    assert ep.states.dtype == np.int64
    # C2's clock started at 950: it wraps at 1000
    np.testing.assert_array_equal(ep.states, np.r_[950:1000, 0:50])
    for c in range(5):
        F = w.context_frames(c)
        assert F.shape == (1000, 400) and F.min() >= 0.0 and F.max() <= 1.0
    if normalise == "global":
        assert F.min() == 0.0 and F.max() == 1.0
    else:
        np.testing.assert_allclose(w.context_frames(0).min(axis=1), 0.0, atol=1e-12)
        np.testing.assert_allclose(w.context_frames(0).max(axis=1), 1.0, atol=1e-12)
    # the local clock continues across visits, whatever is visited in between
    first = w.step(3)[0]
    w.step(2)
    w.step(4)
    ep2, reward, terminated, truncated, _ = w.step(3)
    assert (reward, terminated, truncated) == (0.0, False, False)
    np.testing.assert_array_equal(first.states, np.arange(20, 120))
    np.testing.assert_array_equal(ep2.states, np.arange(120, 220))
    np.testing.assert_array_equal(ep2.frames, w.context_frames(3)[120:220])
    assert w.clock(3) == 220


def test_c1_and_c2_share_frames_and_offsets_decide_whether_they_replay_alike():
    zero = SyntheticWorld(clock_offsets="zero")
    a, _ = zero.reset(seed=4, context=0)
    b = zero.step(1)[0]
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.frames, b.frames)

    rand = SyntheticWorld()  # default: random clock offsets per run
    a, _ = rand.reset(seed=4, context=0)
    np.testing.assert_array_equal(rand.context_frames(0), rand.context_frames(1))  # same source, same mixing
    assert rand.source_of(0) == rand.source_of("C2") == "S-A"
    b = rand.step(1)[0]
    assert not np.array_equal(a.states, b.states)
    assert not np.allclose(a.frames, b.frames)


def test_normalisation_ranks_and_omega():
    for norm, rank in (("global", 2), ("image", 3)):
        w = SyntheticWorld(normalise=norm)
        w.reset(seed=5)
        omegas = [omega(reduced(w.context_frames(c)), 0.05) for c in range(5)]
        for c in range(5):
            assert centred_rank(reduced(w.context_frames(c))) == rank
        assert omegas[0] < omegas[2] < omegas[3]  # S-A < S-B < S-C survives both
        if norm == "global":
            # an affine map of the source: the frames' Omega is the source's Omega
            for c in range(5):
                src = w.source_signal(w.source_of(c))
                assert omegas[c] == pytest.approx(omega(src, 0.05), abs=1e-9)
            assert omegas[4] == max(omegas)
        else:
            # per-image scaling is not linear: S-A's Omega moves off the paper's value
            assert abs(omegas[0] - PAPER_OMEGA["S-A"]) > 5e-4


def test_image_normalisation_of_a_blank_frame():
    frames, _ = mix_frames(np.array([[0.0, 0.0], [1.0, 2.0]]), np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]), "image")
    np.testing.assert_array_equal(frames[0], 0.5)
    np.testing.assert_allclose(frames[1], [0.0, 0.5, 1.0])


def test_world_is_deterministic_by_seed():
    w1, w2 = SyntheticWorld(), SyntheticWorld()
    e1, _ = w1.reset(seed=7)
    e2, _ = w2.reset(seed=7)
    np.testing.assert_array_equal(e1.frames, e2.frames)
    np.testing.assert_array_equal(w1.mixing("S-B"), w2.mixing("S-B"))
    w2.reset(seed=8)
    assert not np.allclose(w1.mixing("S-B"), w2.mixing("S-B"))


def test_user_sources():
    t = np.arange(500) / 500
    x = np.column_stack([np.sin(2 * np.pi * t), np.sin(2 * np.pi * 30 * t), np.cos(2 * np.pi * 7 * t)])
    w = SyntheticWorld.from_sources({"S-X": x}, visit_length=50, frame_shape=(10, 10))
    ep, _ = w.reset(seed=0)
    assert w.n_states == 500 and w.context_names == ("C1",) and w.source_names == ("S-X",)
    assert ep.frames.shape == (50, 100)
    np.testing.assert_array_equal(w.source_signal("S-X"), x)
    assert w.mixing("S-X").shape == (100, 3)
    assert x.flags.writeable  # the caller's array is left alone
    # user sources mix with built-in names when lengths agree
    y = paper_source("S-B")[:, ::-1].copy()
    w = SyntheticWorld(["S-A", "S-Y", "S-D"], sources={"S-Y": y})
    w.reset(seed=0)
    assert w.source_of(1) == "S-Y"


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"contexts": ["S-A", "S-Z"]}, r"key 'contexts': expected source names among S-A, S-B, S-C, S-D, got 'S-Z'"),
        ({"sources": {"S-X": np.zeros(5)}, "contexts": ["S-X"]},
         r"key 'sources.S-X': expected .*array of shape \(n_steps, n_dims\).*got source 'S-X' must be 2-d"),
        ({"sources": {"S-X": np.ones((1000, 2))}, "contexts": ["S-X"]}, "source 'S-X' has zero variance"),
        ({"sources": {"S-X": np.random.default_rng(0).random((400, 2))}, "contexts": ["S-X", "S-A"]},
         "key 'sources': expected sources of equal length.*S-X: 400, S-A: 1000"),
        ({"sources": {"S-X": "no/such/file.npy"}, "contexts": ["S-X"]}, "expected an existing .npy file"),
        ({"normalise": "pixel"}, "key 'normalise': expected one of 'global', 'image', got 'pixel'"),
        ({"clock_offsets": [0, 1]}, r"key 'clock_offsets': expected 'random', 'zero' or 5 start steps in \[0, 1000\)"),
        ({"clock_offsets": "late"}, "key 'clock_offsets': expected a list of at least 1 item"),
        ({"clock_offsets": [0, 0, 0, 0, 1000]}, "key 'clock_offsets'"),
        ({"visit_length": 0}, "key 'visit_length': expected an integer >= 1, got 0"),
        ({"frame_shape": [20, 20, 1]}, "key 'frame_shape': expected a list of 2 items"),
        ({"context_names": ["a", "a", "b", "c", "d"]}, "key 'context_names': expected 5 distinct names"),
        ({"learnable": ["S-A", "S-X"]}, "key 'learnable': expected sources shown by a context"),
    ],
)
def test_bad_arguments_name_what_was_expected(kwargs, match):
    contexts = kwargs.pop("contexts", ("S-A", "S-A", "S-B", "S-C", "S-D"))
    with pytest.raises(ValueError, match=match):
        SyntheticWorld(contexts, **kwargs)


def test_analysis_accessors_need_a_reset_and_known_names():
    w = SyntheticWorld()
    with pytest.raises(RuntimeError, match="reset"):
        w.context_frames(0)
    w.reset(seed=0)
    with pytest.raises(ValueError, match="unknown source 'S-Q'"):
        w.source_signal("S-Q")
    with pytest.raises(ValueError, match="unknown context 'C9'"):
        w.source_of("C9")
    with pytest.raises(ValueError, match="context must be an int"):
        w.step(5)


def test_unlearnable_source_is_redrawn_every_epoch_but_learnable_ones_replay():
    world = SyntheticWorld(clock_offsets="zero")
    first, _ = world.reset(seed=3, context=4)
    sd_epoch0 = world.source_signal("S-D").copy()
    for _ in range(9):
        world.step(4)
    again, *_ = world.step(4)  # local steps 0..99 of the second epoch
    assert np.array_equal(again.states, first.states)
    assert not np.allclose(again.frames, first.frames)
    assert not np.allclose(world.source_signal("S-D"), sd_epoch0)
    a0 = world.step(0)[0]
    for _ in range(9):
        world.step(0)
    a1 = world.step(0)[0]
    assert np.array_equal(a0.states, a1.states) and np.array_equal(a0.frames, a1.frames)


def test_stationary_option_replays_the_same_random_walk():
    world = SyntheticWorld(clock_offsets="zero", nonstationary=False)
    first, _ = world.reset(seed=3, context=4)
    for _ in range(9):
        world.step(4)
    again, *_ = world.step(4)
    assert np.array_equal(again.frames, first.frames)
