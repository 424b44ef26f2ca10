"""World.visits: n visits of a context as one block equal n steps joined, in every world path."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.contexts.base import concatenate_episodes
from neurocur.contexts.mixing import SourceFrames, mix_frames, scale_frames
from neurocur.contexts.synthetic import SyntheticWorld

SOURCES = {"A": {"sinusoid": 5}, "N": {"noise": "white", "dims": 2}}


def _world(visit_length, normalise="global", **kwargs):
    """Sources of 40 steps: a replayed sinusoid pair S-X, S-D (redrawn) and declared noise (redrawn, centred)."""
    t = np.arange(40) * 2 * np.pi / 40
    sources = {"X": np.column_stack([np.sin(t), np.cos(7 * t)]), **SOURCES}
    return SyntheticWorld(["X", "A", "N"], sources=sources, visit_length=visit_length, normalise=normalise,
                          frame_shape=(3, 4), rewards=[1.0, [0.0, 2.5, 0.25], 0.5], **kwargs)


def _same(a, b):
    np.testing.assert_array_equal(a.frames, b.frames)
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.starts, b.starts)
    assert a.context == b.context and a.reward == b.reward


@pytest.mark.parametrize("normalise", ["global", "image"])
@pytest.mark.parametrize("visit_length", [7, 40, 53])  # wraps inside, exactly at the end, a visit longer than an epoch
def test_visits_equal_steps_joined(visit_length, normalise):
    blocks, steps = _world(visit_length, normalise), _world(visit_length, normalise)
    blocks.reset(seed=3)
    steps.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(40):
        c, n = int(rng.integers(3)), int(rng.integers(1, 4))
        block = blocks.visits(c, n)
        _same(block, concatenate_episodes([steps.step(c)[0] for _ in range(n)]))
        assert not block.frames.flags.writeable
        assert block.frames.min() >= 0.0 and block.frames.max() <= 1.0
        assert list(block.starts) == list(range(0, n * visit_length, visit_length))
    for c in range(3):  # the worlds' generators, clocks and reward counts are in step
        _same(blocks.step(c)[0], steps.step(c)[0])
        np.testing.assert_array_equal(blocks.context_frames(c), steps.context_frames(c))


def test_a_redrawn_source_scales_the_rows_of_its_whole_draw():
    rng = np.random.default_rng(1)
    signal, mixing = rng.standard_normal((50, 2)), rng.standard_normal((12, 2))
    for normalise, symmetric in [("global", False), ("global", True), ("image", False)]:
        whole, limits = mix_frames(signal, mixing, normalise, symmetric=symmetric)
        shown = SourceFrames(mixing.copy(), normalise, symmetric=symmetric, whole=False)
        shown.show(signal.copy())
        assert shown.limits == limits
        out = np.empty((17, 12))
        shown.scale_rows(20, out)
        np.testing.assert_array_equal(out, whole[20:37])
        np.testing.assert_array_equal(shown.frames(), whole)
        np.testing.assert_array_equal(scale_frames(signal[5:9] @ mixing.T, normalise, limits), whole[5:9])
    peak = float(np.abs(signal @ mixing.T).max())
    assert mix_frames(signal, mixing, "global", symmetric=True)[1] == (-peak, peak)


def test_visits_checks_its_arguments():
    world = _world(7)
    world.reset(seed=0)
    for n in (0, 1.5, True):
        with pytest.raises(ValueError, match="n must be a positive integer"):
            world.visits(0, n)
    with pytest.raises(ValueError, match="context must be an int"):
        world.visits(3, 2)


def test_a_source_too_large_to_scale_is_refused_when_rendered():
    t = np.linspace(-1.0, 1.0, 20)
    for normalise in ("global", "image"):
        with np.errstate(over="ignore"), pytest.raises(ValueError, match="not finite"):  # the range overflows
            SyntheticWorld(["X"], sources={"X": np.column_stack([t * 1e308, t[::-1]])}, frame_shape=(2, 2),
                           normalise=normalise).reset(seed=0)


def test_compiled_std_and_scaling_equal_numpy():
    from neurocur.contexts.mixing import _scale
    from neurocur.contexts.sources import _column_std

    rng = np.random.default_rng(4)
    for n in (2, 9, 1000, 1001):
        walk = rng.standard_normal((n, 2)) * 10.0 ** rng.uniform(-3, 3, 2)
        np.testing.assert_array_equal(_column_std(walk), walk.std(axis=0))
        raw = rng.standard_normal((n, 7)) * 10.0 ** rng.uniform(-3, 3)
        low, high = float(raw.min()), float(raw.max())
        np.testing.assert_array_equal(_scale(raw, low, high - low, np.empty_like(raw)), (raw - low) / (high - low))


def test_a_blocks_derivative_never_spans_a_start():
    """Two joined episodes: the derivative is the difference of successive rows within each,
    and NaN at each episode's first row."""
    from neurocur.contexts.base import Episode

    parts = [Episode(frames=np.full((3, 1), 0.1), states=np.arange(3), context=0),
             Episode(frames=np.array([[0.9], [0.5]]), states=np.arange(2), context=0)]
    block = concatenate_episodes(parts)
    y = np.array([1.0, 2.0, 4.0, 10.0, 13.0])
    dy = block.derivative(y)
    np.testing.assert_array_equal(np.isnan(dy), [True, False, False, True, False])
    np.testing.assert_array_equal(dy[~np.isnan(dy)], [1.0, 2.0, 3.0])
    assert block.derivative(np.column_stack([y, -y])).shape == (5, 2)
