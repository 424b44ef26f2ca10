"""The frame contract (Episode.frames: float64 in [0, 1]) is enforced where episodes leave a world."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.circuit import Circuit
from neurocur.contexts.base import Episode, World, conform_frames


class ScaledWorld(World):
    """Two contexts of random frames in [0, 1], turned into ``kind`` frames."""

    context_names = ("near", "far")
    source_names = ("a", "b")
    frame_shape = (2, 3)
    n_states = 4

    def __init__(self, kind="float64"):
        self.kind = kind

    def _reset(self):
        self.t = 0

    def _visit(self, context):
        self.t += 1
        unit = self.np_random.random((5, 6))
        frames = {
            "float64": unit,
            "uint8": np.round(unit * 255).astype(np.uint8),
            "float32": unit.astype(np.float32),
            "bool": unit > 0.5,
            "int64": (unit > 0.5).astype(np.int64),
            "x1e3": unit * 1e3,
            "int255": np.round(unit * 255).astype(np.int64),
            "negative": unit - 0.5,
            "nan": np.where(unit > 0.9, np.nan, unit),
            "rounding": np.minimum(unit + 0.5, 1.0 + 1e-12),
            "text": unit.astype(str),
        }[self.kind]
        return Episode(frames=frames, states=np.arange(5) % 4, context=context)


def test_float64_in_range_is_passed_through_untouched():
    world = ScaledWorld()
    world.reset(seed=0)
    ep = world._visit(1)
    assert conform_frames(ep, world) is ep


@pytest.mark.parametrize("kind", ["uint8", "float32", "bool", "int64", "rounding"])
def test_other_types_in_range_become_float64_in_unit_range(kind):
    world = ScaledWorld(kind)
    first, _ = world.reset(seed=0)
    ep = world.step(1)[0]
    for e in (first, ep):
        assert e.frames.dtype == np.float64 and e.frames.min() >= 0 and e.frames.max() <= 1 + 1e-9


def test_uint8_is_divided_by_255():
    raw = np.array([[0, 51, 255]], dtype=np.uint8)
    ep = conform_frames(Episode(frames=raw, states=np.zeros(1, dtype=np.int64), context=0))
    np.testing.assert_array_equal(ep.frames, [[0.0, 0.2, 1.0]])


@pytest.mark.parametrize("kind, found", [("x1e3", "float64 values in [2.7"), ("int255", "int64 values in [1, 254]"),
                                         ("negative", "float64 values in [-0.4"), ("nan", "NaN value"),
                                         ("text", "dtype <U")])
def test_frames_outside_the_contract_are_refused_naming_world_context_and_range(kind, found):
    world = ScaledWorld(kind)
    with pytest.raises(ValueError, match="ScaledWorld, context 'near' \\(index 0\\)") as info:
        world.reset(seed=0)
    assert found in str(info.value)
    with pytest.raises(ValueError, match="context 'far' \\(index 1\\)"):
        world.step(1)


def test_a_circuit_on_a_uint8_world_equals_the_float_world():
    """uint8 frames enter the circuit as the float frames k / 255 would."""
    small = {"HPC.n_states": 4, "EC.n_components": 2}

    class Exact(ScaledWorld):
        def _visit(self, context):
            ints = self.np_random.integers(0, 256, size=(5, 6)).astype(np.uint8)
            frames = ints if self.kind == "uint8" else ints / 255.0
            return Episode(frames=frames, states=np.arange(5) % 4, context=context)

    try:
        circuit = Circuit.from_toml("cd_misfa", overrides=small)
    except Exception as exc:  # the parameter names of the shipped circuit changed
        pytest.skip(f"cd_misfa does not take these overrides: {exc}")
    tables = []
    for kind in ("uint8", "float64"):
        sim = circuit.build(Exact(kind), seed=3)
        sim.run(200)
        tables.append(sim.episodes())
    assert tables[0].equals(tables[1])
