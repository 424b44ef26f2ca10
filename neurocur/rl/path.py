"""The circuit's sensory path, fed by an environment's observations instead of a world.

A circuit (``cd_misfa`` by default) is cut down to what the VTA needs: the regions upstream of
the VTA along step and learn-phase edges (EC and HPC in the shipped circuits), the VTA model, and
a :class:`Feed` in the sensory region's place. The PFC and the LC, which choose contexts in
neurocur's own agent, are left out: here the reinforcement-learning agent acts. A :class:`Bonus`
region reads the VTA's ``da``. The cut circuit runs on neurocur's own
:class:`~neurocur.scheduler.Simulator`, so every pass is the circuit's pass (docs/regions.md,
"How a pass runs"): EC encodes (eq 2), HPC measures the errors and the gating (eqs 10-11,
section 2.6), the VTA model releases DA, then EC and HPC learn.

One pass is one block of ``frames`` environment steps, as one pass of neurocur's own agent is
one visit of a context. Its episode holds the observation before the block and the block's
observations as frames, with context-states 0, 1, ..., ``frames`` (HPC keeps a clusterer per
position in the block), in one segment: EC's slow features see the stream of observations, a
reset's jump included (a segment must hold more frames than those that only set IncSFA's mean,
so a short environment episode cannot be a segment of its own). A block waits for a further step
while its frames are all equal (a fresh IncSFA module cannot start on a block that does not
vary). The pass's context is the context of the block's last observation, its reward the
environment's reward summed over the block. The DA of the pass is the bonus of the step that
closes the block; the other steps of the block get none.

``path="counts"`` keeps the VTA alone: the feed delivers the context and the reward, an undefined
error (NaN) and no familiarity or storage. It suits a model that reads only the context and the
reward, such as count novelty (``vta.novelty``, whose default path it is); its blocks are single
steps.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import numpy as np

from ..circuit import Circuit
from ..circuit.specs import Link, RegionSpec
from ..config import ConfigError
from ..contexts.base import Episode
from ..regions import REGIONS, Region, Signal
from ..tables import shipped_files

__all__ = ["PATHS", "COUNT_MODELS", "SensoryPath", "Feed", "Bonus", "model_circuit", "cut"]

#: The sensory paths: the circuit's EC and HPC, or the VTA alone.
PATHS = ("slow_features", "counts")
#: Models that read only the context and the reward: their default path is ``"counts"``.
COUNT_MODELS = ("vta.novelty",)
_ONE_SEGMENT = np.zeros(1, dtype=np.int64)


class Feed(Region):
    """The sensory region's place: delivers the episode the wrapper set (a clock, like
    ``sensory.world``), its context and reward, and, for the counts path, the constant HPC
    signals of a circuit without memory (an undefined error, never familiar, never stored).

    Parameters
    ----------
    name : str
        The region's name in the circuit (default: the class name).
    params : Params, optional
        Its parameters (it has none).
    **kwargs
        Keyword parameters instead of ``params``.
    """

    is_clock = True
    outputs = (
        Signal("episode", "Episode", (), "the observation before the block, then the block's", optional=True),
        Signal("context", "int64", (), "context of the block's last observation", optional=True),
        Signal("reward", "float64", (), "the environment's reward summed over the block", optional=True),
        Signal("reward_error", "float64", (), "NaN: no memory measures an error", optional=True),
        Signal("familiar", "bool", (), "False: no memory gates", optional=True),
        Signal("module_learned", "bool", (), "False: no memory stores", optional=True),
    )

    def reset(self, rng) -> None:
        self.episode, self.context, self.reward, self.n_frames = None, 0, 0.0, 1

    def step(self):
        return self.episode, self.context, self.reward, math.nan, False, False


class Bonus(Region):
    """Reads the VTA's dopamine for the wrapper.

    Parameters
    ----------
    name : str
        The region's name in the circuit (default: the class name).
    params : Params, optional
        Its parameters (it has none).
    **kwargs
        Keyword parameters instead of ``params``.
    """

    inputs = (Signal("da", "float64", (), "dopamine released at this pass"),)

    def reset(self, rng) -> None:
        self.da = 0.0

    def step(self, da):
        self.da = float(da)
        return ()


class _Sizes:
    """What the regions' ``bind`` reads of a world."""

    def __init__(self, n_contexts: int, n_pixels: int, n_states: int):
        self.n_contexts, self.n_pixels, self.n_states = n_contexts, n_pixels, n_states


def model_circuit(model: str, *, params: Mapping | None = None, circuit=None, inputs: Mapping | None = None,
                  source: str = "IntrinsicReward") -> Circuit:
    """The circuit whose VTA is ``model`` (a registered VTA type or an entry point of the
    ``neurocur.regions`` group) with ``params``: ``circuit`` (a Circuit, a shipped circuit's name or
    a file) with its VTA replaced; by default the shipped variant named after ``model``
    (``vta_state_progress`` for ``vta.state_progress``, so it keeps its wiring,
    ``HPC.progress -> VTA.progress``; not ``ne_plasticity``, which extends it with the LC's NE),
    else the first shipped circuit, by name, whose VTA is ``model``, else ``cd_misfa`` with its VTA
    replaced. ``inputs`` feeds inputs the circuit does not (``{"progress": "HPC.progress"}``, as
    :meth:`~neurocur.circuit.Circuit.replace`).

    Parameters
    ----------
    model : str
        The VTA's region type.
    params : mapping, optional
        The VTA's parameters.
    circuit : Circuit or str or path, optional
        The circuit whose VTA is replaced.
    inputs : mapping of str to str, optional
        Edges into the model's inputs that the circuit does not feed.
    source : str
        Names the caller in errors.

    Returns
    -------
    Circuit
        The circuit with ``model`` as its VTA.
    """
    if not isinstance(model, str) or model not in REGIONS:
        raise ConfigError(source, "model", f"a registered region type ({', '.join(REGIONS.names())})", repr(model))
    if not any(s.name == "da" for s in REGIONS.get(model).outputs):
        raise ConfigError(source, "model", "a VTA model (a region type with a 'da' output)", repr(model))
    if circuit is None:
        shipped = shipped_files("circuit")
        variant = model.replace(".", "_")  # the circuit of a VTA variant bears its name: vta_state_progress
        circuit = shipped[variant] if variant in shipped else next(
            (path for path in shipped.values()
             if getattr(Circuit.from_toml(path).specs.get("VTA"), "type_name", None) == model), "cd_misfa")
    base = circuit if isinstance(circuit, Circuit) else Circuit.from_toml(circuit)
    if "VTA" not in base.specs:
        raise ConfigError(base.source, "regions", "a region named 'VTA'", f"regions {', '.join(base.specs)}")
    return base.replace("VTA", {"type": model, "params": dict(params or {})}, drop_edges=True, inputs=inputs)


def cut(circuit: Circuit, path: str, *, source: str = "IntrinsicReward") -> Circuit:
    """The regions of ``circuit`` the VTA needs on ``path``, a :class:`Feed` as ``sensory`` and a :class:`Bonus`.

    Parameters
    ----------
    circuit : Circuit
        The whole circuit.
    path : str
        ``"slow_features"`` or ``"counts"``.
    source : str
        Names the caller in errors.

    Returns
    -------
    Circuit
        The cut circuit.
    """
    keep = {"VTA"}
    if path == "slow_features":
        upstream: dict[str, set] = {}
        for link in circuit.links:
            if not link.delayed:
                upstream.setdefault(link.dst, set()).add(link.src)
        todo = list(upstream.get("VTA", ()))
        while todo:
            name = todo.pop()
            if name not in keep and name != "sensory":
                keep.add(name)
                todo += upstream.get(name, ())
    delivered = {s.name for s in Feed.outputs}
    links = []
    for link in circuit.links:
        if link.dst not in keep or link.src in keep:
            if link.dst in keep:
                links.append(link)
            continue
        if link.signal not in delivered:
            raise ConfigError(source, "path", f"'slow_features' for a model that reads {link} (the '{path}' "
                              f"path delivers only {', '.join(sorted(delivered))})", repr(path))
        links.append(dataclasses.replace(link, src="sensory", delayed=False))
    specs = {name: spec for name, spec in circuit.specs.items() if name in keep}
    specs["sensory"] = RegionSpec("sensory", Feed, Feed.Params(), instance=Feed("sensory"))
    specs["Bonus"] = RegionSpec("Bonus", Bonus, Bonus.Params(), instance=Bonus("Bonus"))
    return Circuit(specs, [*links, Link("VTA", "da", "Bonus", "da")], source=circuit.source)


class SensoryPath:
    """The cut circuit of ``circuit`` (see the module's docstring) on the observations ``coder``
    turns into frames and contexts (:class:`~neurocur.rl.observations.ObservationCoder`), in blocks
    of ``frames`` steps, built and reset from ``seed`` (an int or a SeedSequence; each region's
    stream is keyed by its name, :func:`~neurocur.scheduler.region_seed`). ``streams`` environments
    (those of a vector environment) share the circuit, each with its own block; their steps run
    through it in the order they are given.

    Parameters
    ----------
    circuit : Circuit
        The whole circuit (cut here, :func:`cut`).
    path : str
        ``"slow_features"`` or ``"counts"``.
    coder : ObservationCoder
        Turns observations into frames and contexts.
    frames : int
        Steps per pass: 1 on the ``counts`` path, at least 4 on the ``slow_features`` path.
    seed : int or numpy.random.SeedSequence
        Builds and resets the circuit.
    streams : int
        The environments sharing the circuit.
    source : str
        Names the caller in errors.
    """

    def __init__(self, circuit: Circuit, path: str, coder, *, frames: int, seed, streams: int = 1,
                 source: str = "IntrinsicReward"):
        if path not in PATHS:
            raise ConfigError(source, "path", f"one of {', '.join(PATHS)}", repr(path))
        counts = path == "counts"
        whole = isinstance(frames, (int, np.integer)) and not isinstance(frames, bool)
        if not whole or (frames != 1 if counts else frames < 4):
            raise ConfigError(source, "frames", "1 on the 'counts' path (a pass per step)" if counts else
                              "an integer >= 4 (steps per pass on the 'slow_features' path)", repr(frames))
        self.frames, self.coder = int(frames), coder
        self.circuit = cut(circuit, path, source=source)
        if "HPC" in self.circuit.specs and hasattr(self.circuit.specs["HPC"].params, "n_states"):
            self.circuit = self.circuit.with_params({"HPC.n_states": self.frames + 1}, source=source)
        sim = self.circuit.build(_Sizes(coder.n_contexts, coder.n_pixels, self.frames + 1), seed)
        self.simulator = sim
        self._feed, self._bonus, self._run = sim.regions["sensory"], sim.regions["Bonus"], sim.run
        self._counts = path == "counts"
        self._blocks: list[list] = [[] for _ in range(streams)]
        self._rewards = [0.0] * streams
        self._steps = [0] * streams  # steps of each stream's episode, for errors
        self._source = source

    def start(self, observation, stream: int = 0) -> int:
        """An episode of environment ``stream`` starts on ``observation`` (the reset's): a frame of its
        block. Returns the number of its values outside the space's bounds (:meth:`step`)."""
        self._steps[stream] = 0
        try:
            x, outside = self.coder.check(observation)
        except ConfigError as error:
            raise self._located(error, stream) from None
        if not self._counts:
            self._blocks[stream].append(np.array(x))
        return outside

    def step(self, observation, reward: float, stream: int = 0) -> tuple[float | None, int]:
        """Add one step of ``stream``; returns the DA of the pass when the step closes a block (else
        None) and the number of the observation's values outside the space's bounds (clipped in its
        frame). An observation the coder refuses (:meth:`ObservationCoder.check
        <neurocur.rl.observations.ObservationCoder.check>`) or a reward that is not finite is a
        ConfigError naming the step."""
        self._steps[stream] += 1
        if not math.isfinite(reward):  # vta.td would keep it in its values
            raise self._located(ConfigError(self._source, "reward", "a finite number", str(float(reward))), stream)
        feed = self._feed
        if self._counts:  # a pass per step, on the observation's context alone
            try:
                feed.context, outside = self.coder.checked_context(observation)
            except ConfigError as error:
                raise self._located(error, stream) from None
            feed.reward = float(reward)
            self._run(1)
            return self._bonus.da, outside
        try:
            x, outside = self.coder.check(observation)
        except ConfigError as error:
            raise self._located(error, stream) from None
        block = self._blocks[stream]
        block.append(np.array(x))
        self._rewards[stream] += reward
        if len(block) <= self.frames:
            return None, outside
        frames = self.coder.frames(np.stack(block))
        if not (frames != frames[0]).any():  # a block that does not vary waits for a further step
            return None, outside
        feed.context = int(self.coder.contexts_of(frames[-1:])[0])
        feed.reward, feed.n_frames = self._rewards[stream], len(frames)
        feed.episode = Episode(frames, np.minimum(np.arange(len(frames)), self.frames), feed.context,
                               _ONE_SEGMENT, feed.reward)
        self._blocks[stream], self._rewards[stream] = [block[-1]], 0.0
        self._run(1)
        return self._bonus.da, outside

    def _located(self, error: ConfigError, stream: int) -> ConfigError:
        """The coder's ``error`` naming the step of the episode (``reset`` for the reset's observation)
        and, with several streams, the sub-environment."""
        step = self._steps[stream]
        where = f"{self._source} {'reset' if step == 0 else f'step {step}'}"
        return error.relocated(f"{where} of sub-environment {stream}" if len(self._steps) > 1 else where)
