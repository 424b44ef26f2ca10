"""Replay: a circuit evaluated on observed behaviour, log P(observed decisions | theta).

The world shows the observed context sequence: the decision region (an LC model,
:class:`~neurocur.regions.lc.LCRole`) still steps, but the action and next context it
emits are the observed ones, and it scores the observed decision with the probability its
draw used (:meth:`~neurocur.regions.lc.LCRole.log_probability`). Design section 7.

- **Full replay**: the circuit as it is; EC and HPC learn from the frames of the observed
  contexts (data from agents in a known world; with the run's seed the world's frames are
  the run's own).
- **Signal replay**: a region emitting the observed per-episode signal in place of the one
  that would compute it (:func:`signal_circuit`, ``Circuit.replace``).

**Cached replay.** The *decision part* is the decision region and every region on a path
from a region with a fitted parameter to it (e.g. PFC for eq 14's alpha). Everything else,
the *learning part*, does not depend on the fitted parameters, so it runs once: the replay
records every input of the decision part, pass by pass. :meth:`Replay.loglik` then steps
fresh decision-part regions built with each theta through those inputs, and for a decision
region that declares a vectorised likelihood (a classmethod ``log_likelihoods``,
:class:`~neurocur.regions.lc.LCRole`) evaluates all thetas at once.

**Trials** (:class:`~neurocur.fit.trials.Trials`, people's choices among options): one pass is
one trial, the decision chooses the option that the task visits in the same pass, and the world
of options (:meth:`~neurocur.contexts.options.OptionsWorld.recorded`) pays the recorded outcome
of each trial, so every recorded choice is scored, the first from the initial values.

**Given passes.** A pass whose choice the circuit imposes rather than chooses (Ten et al. 2021's forced
trials, ``ten2021.utility``) is given probability 1 and scores log 1 = 0; the region says so by its probe
``given`` (1 on such a pass). :attr:`Replay.scored` marks the other passes, and :attr:`Replay.n_obs`
counts them: the observations of a BIC or an iBIC are the scored choices, not the rows.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Mapping, Sequence

import networkx as nx
import numpy as np

from ..circuit import Circuit
from ..config import ConfigError
from ..regions.free_choice import RecordedSignal
from ..regions.pfc import DISENGAGE, ENGAGE
from ..scheduler import region_seed
from .data import Behaviour
from .trials import Trials

__all__ = ["Replay", "decision_part", "signal_circuit"]


def signal_circuit(circuit: Circuit, name: str, behaviour: Behaviour, signal: str) -> Circuit:
    """``circuit`` with region ``name`` replaced by a :class:`~neurocur.regions.free_choice.RecordedSignal`
    emitting the data set's column ``signal`` (signal replay)."""
    if signal not in behaviour.signals:
        raise ConfigError(behaviour.source, signal, f"a per-episode column '{signal}' for signal replay", "none")
    return circuit.replace(name, RecordedSignal(name, series=behaviour.signals[signal]))


def decision_part(circuit: Circuit, decision: str, fitted: Sequence[str]) -> tuple[str, ...]:
    """The regions that depend on the fitted ``"REGION.param"`` keys on their way to ``decision``, in
    step order. A fitted region with no path to the decision, or a decision part that feeds the
    learning part with anything but the observed decision, is a ConfigError (no cached replay)."""
    graph = nx.DiGraph()
    graph.add_nodes_from(circuit.specs)
    graph.add_edges_from((k.src, k.dst) for k in circuit.links if not k.delayed)
    if decision not in circuit.specs:
        raise ConfigError(circuit.source, "decision", f"a region of the circuit ({', '.join(circuit.specs)})",
                          repr(decision))
    part = {decision}
    for key in fitted:
        region = key.split(".", 1)[0]
        if region not in circuit.specs:
            raise ConfigError("--fit", key, f"REGION.param with a region of the circuit ({', '.join(circuit.specs)})",
                              repr(key))
        if region != decision and not nx.has_path(graph, region, decision):
            raise ConfigError("--fit", key, f"a parameter of a region on the way to the decision ('{decision}')",
                              f"region '{region}', which does not reach it")
        part |= {region} | (nx.descendants(graph, region) & nx.ancestors(graph, decision))
    observed = set(_observed_outputs(circuit, decision))
    for k in circuit.links:
        if k.src in part and k.dst not in part and not (k.src == decision and k.signal in observed):
            raise ConfigError("--fit", k.src, "fitted regions whose outputs reach only the decision",
                              f"edge {k}: the learning part would depend on the fitted parameters "
                              "(refit by simulation, neurocur.fit.sbi)")
    return tuple(n for n in circuit.step_order if n in part)


def _observed_outputs(circuit: Circuit, decision: str) -> tuple[str, ...]:
    cls = circuit.specs[decision].cls
    names = tuple(s.name for s in cls.outputs)
    if not hasattr(cls, "probabilities") or "next_context" not in names:
        raise ConfigError(circuit.source, f"regions.{decision}", "a decision region (an LC model, with "
                          "probabilities and a next_context output)", circuit.specs[decision].type_name)
    return tuple(n for n in ("action", "next_context") if n in names)


class Replay:
    """One data set replayed through a circuit (module docstring).

    ``fitted``: the ``"REGION.param"`` keys to be varied (they decide the decision part);
    ``seed``: the circuit's seed (a results folder's run seed reproduces the run's world).
    ``behaviour``: episodes (:class:`~neurocur.fit.data.Behaviour`) or a subject's trials
    (:class:`~neurocur.fit.trials.Trials`, replayed by the world of options with the recorded outcomes).
    After construction, :attr:`logp` holds the per-episode log-probabilities at the circuit's
    own parameters, and :meth:`loglik` evaluates any theta on the cached inputs.
    """

    def __init__(self, circuit: Circuit, world, seed, behaviour: Behaviour | Trials, *, decision: str = "LC",
                 fitted: Sequence[str] = ()):
        self.circuit, self.world, self.behaviour, self.decision = circuit, world, behaviour, decision
        self.fitted = tuple(fitted)
        self.part = decision_part(circuit, decision, self.fitted)
        self.n_contexts = world.n_contexts
        b = behaviour
        cls = circuit.specs[decision].cls
        self.decides = cls.decides
        if isinstance(b, Trials):
            self.world = _trial_world(world, b, self.decides)
            self.next_contexts = self.observed = b.choices
            self.actions = np.r_[DISENGAGE, np.where(b.choices[1:] == b.choices[:-1], ENGAGE, DISENGAGE)]
            self._finish(self._run(circuit, seed))
            return
        if b.contexts.max() >= self.n_contexts or (b.free_choice and b.decisions.max() >= self.n_contexts):
            raise ConfigError(b.source, "context", f"contexts 0..{self.n_contexts - 1} of the world",
                              f"{max(b.contexts.max(), b.decisions.max())} in data set '{b.name}'")
        self.next_contexts = b.next_contexts(self.n_contexts)
        self.actions = (self.next_contexts != b.contexts).astype(np.int64)
        self.observed = b.decisions if self.decides == "next_context" else self.actions
        sim = self._run(circuit, seed)
        if sim.regions[decision].tape[0][self._context_index(decision)] != b.contexts[0]:
            clock = next((n for n, r in sim.regions.items() if r.is_clock), None)
            if clock is None or not hasattr(circuit.specs[clock].params, "initial_context"):
                raise ConfigError(b.source, "context", f"data set '{b.name}' to start in the circuit's first context",
                                  f"context {b.contexts[0]}")
            sim = self._run(circuit.with_params({f"{clock}.initial_context": int(b.contexts[0])}), seed)
        self._finish(sim)

    def _finish(self, sim) -> None:
        """Keep what the likelihood evaluations read from the one full run ``sim``."""
        regions, decision = sim.regions, self.decision
        self.seed_sequence = sim.seed_sequence
        self.tapes = {n: regions[n].tape for n in self.part}
        self.logp = np.array(regions[decision].logp)
        self.episodes = sim.episodes()
        given = self.episodes["given"].to_numpy() if "given" in self.episodes.columns else 0
        self.scored = np.broadcast_to(np.asarray(given) == 0, (len(self.observed),)).copy()
        self._plan = self._live_inputs()

    # ------------------------------------------------------------------ the one full run

    def _context_index(self, name: str) -> int:
        return [s.name for s in self.circuit.specs[name].cls.inputs].index("context")

    def _run(self, circuit: Circuit, seed):
        specs = dict(circuit.specs)
        for name in self.part:
            spec = specs[name]
            observed = (self.actions, self.next_contexts, self.observed) if name == self.decision else None
            specs[name] = dataclasses.replace(spec, cls=_taped(spec.cls, observed),
                                              instance=_retyped(spec.instance, observed))
        sim = Circuit(specs, circuit.links, source=circuit.source, lesions=circuit.lesions).build(self.world, seed)
        if isinstance(self.behaviour, Trials):  # the recorded world checks each visit against the recorded choice
            return sim.run(len(self.observed))
        contexts, i_ctx = self.behaviour.contexts, self._context_index(self.decision)
        tape = sim.regions[self.decision].tape
        for t in range(len(contexts)):
            sim.run(1)
            if t and tape[t][i_ctx] != contexts[t]:
                raise ConfigError(self.behaviour.source, "context", f"context {contexts[t]} at episode {t} of data "
                                  f"set '{self.behaviour.name}' (the observed decision's)",
                                  f"context {tape[t][i_ctx]} shown by the circuit's world")
            if t == 0 and tape[0][i_ctx] != contexts[0]:
                break
        return sim

    def _live_inputs(self):
        """Per decision-part region, ``(input index, source region, output index, delayed)`` of every
        input fed by another decision-part region's output that is not the observed decision."""
        observed = set(_observed_outputs(self.circuit, self.decision))
        plan = {}
        for name in self.part:
            cls = self.circuit.specs[name].cls
            ins = [s.name for s in cls.inputs]
            live = []
            for k in self.circuit.links:
                if k.dst == name and k.src in self.part and k.input in ins and \
                        not (k.src == self.decision and k.signal in observed):
                    outs = [s.name for s in self.circuit.specs[k.src].cls.outputs]
                    live.append((ins.index(k.input), k.src, outs.index(k.signal), k.delayed))
            plan[name] = live
        return plan

    # ------------------------------------------------------------------ many thetas

    @property
    def n_obs(self) -> int:
        """The scored decisions (a given pass, module docstring, is not an observation)."""
        return int(self.scored.sum())

    def n_scored(self, mask=None) -> int:
        """The scored decisions among the passes ``mask`` selects (all without one)."""
        return self.n_obs if mask is None else int(np.sum(self.scored & np.asarray(mask, dtype=bool)))

    def loglik(self, theta: Mapping[str, float] | Sequence[Mapping[str, float]], mask=None):
        """The log-likelihood of the observed decisions at ``theta`` (``{"REGION.param": value}``,
        only :attr:`fitted` keys), or an array of them for a list of thetas; ``mask`` (a boolean
        array over the episodes) sums only the episodes it selects (held-out scores). A decision
        given probability 0 makes it -inf (:meth:`first_impossible` names the episode)."""
        if isinstance(theta, Mapping):
            return float(self.loglik([theta], mask)[0])
        keep = np.ones(len(self.observed), dtype=bool) if mask is None else np.asarray(mask, dtype=bool)
        thetas = [dict(t) for t in theta]
        for t in thetas:
            unknown = set(t) - set(self.fitted)
            if unknown:
                raise ConfigError("theta", sorted(unknown)[0], f"one of the replay's fitted keys {self.fitted}",
                                  "a key the replay did not cache")
        spec = self.circuit.specs[self.decision]
        if getattr(spec.cls, "log_likelihoods", None) is not None and not spec.drugs and self._separable:
            groups: dict[tuple, list[int]] = {}
            own = f"{self.decision}."
            for i, t in enumerate(thetas):
                groups.setdefault(tuple(sorted((k, v) for k, v in t.items() if not k.startswith(own))), []).append(i)
            out = np.empty(len(thetas))
            for upstream, rows in groups.items():
                tape = self._decision_tape(upstream)
                out[rows] = self._vectorised([thetas[i] for i in rows], tape)[:, keep].sum(axis=1)
            return out
        return np.array([self.episode_logp(t)[keep].sum() for t in thetas])

    def _vectorised(self, thetas, tape) -> np.ndarray:
        """(m, n) log P of the observed decisions for m thetas at once: the decision region's own
        ``log_likelihoods`` on its parameters (a column each, the circuit's value where theta has
        none) and its inputs, pass by pass."""
        spec = self.circuit.specs[self.decision]
        own = f"{self.decision}."
        params = {f.name: np.array([t.get(own + f.name, getattr(spec.params, f.name)) for t in thetas])[:, None]
                  for f in dataclasses.fields(spec.params)}
        inputs = {s.name: [args[i] for args in tape] for i, s in enumerate(spec.cls.inputs)}
        return spec.cls.log_likelihoods(params, inputs, self.observed)

    @property
    def _separable(self) -> bool:
        """True when no region before the decision reads a decision output other than the observed ones,
        so the decision's inputs depend on the upstream parameters only (:meth:`_decision_tape`)."""
        return not any(src == self.decision for name in self.part if name != self.decision
                       for _, src, _, _ in self._plan[name])

    def _decision_tape(self, upstream: tuple) -> list:
        """The decision region's inputs, pass by pass, with the decision part's upstream regions (e.g.
        PFC) built with the ``upstream`` parameters; memoised (the last 64), so that many decision
        parameters cost one upstream pass."""
        if self.part == (self.decision,):
            return self.tapes[self.decision]
        memo = self.__dict__.setdefault("_memo", {})
        if upstream in memo:
            return memo[upstream]
        specs = self.circuit.with_params(dict(upstream), source="theta").specs if upstream else self.circuit.specs
        tape = [args for args, _ in self._passes(specs, step_decision=False)]
        if len(memo) >= 64:
            memo.pop(next(iter(memo)))
        memo[upstream] = tape
        return tape

    def _passes(self, specs, *, step_decision: bool):
        """The decision part stepped through the cached inputs, fresh regions of ``specs``: yields, pass by
        pass, the decision region's inputs and the decision region (stepped with them when
        ``step_decision``; else None, and its outputs keep their initial values, which only a separable
        part may do)."""
        names = self.part if step_decision else self.part[:-1]
        regions = {n: self._fresh(specs[n]) for n in names}
        outputs = {n: tuple(s.initial for s in specs[n].cls.outputs) for n in self.part}
        previous = dict(outputs)
        plan, tapes = self._plan, self.tapes
        for t in range(len(self.observed)):
            for name in self.part:
                args = tapes[name][t]
                if plan[name]:
                    args = list(args)
                    for i, src, j, delayed in plan[name]:
                        args[i] = (previous if delayed else outputs)[src][j]
                if name == self.decision:
                    inputs = tuple(args)
                if name in regions:
                    outputs[name] = regions[name].step(*args)
            previous = dict(outputs)
            yield inputs, regions.get(self.decision)

    def _fresh(self, spec):
        """A new region of ``spec``, bound to the world and reset with the generator it had in the run
        (its decision draws are discarded, the observed decision replaces them; a stream of its own
        that the draws do not move, such as the FitzHugh–Nagumo LC's input noise, is the run's)."""
        region = spec.make()
        region.wired = frozenset(k.signal for k in self.circuit.links if k.src == spec.name)
        region.bind(self.world)
        region.reset(np.random.default_rng(region_seed(self.seed_sequence, spec.name)))
        return region

    def episode_logp(self, theta: Mapping[str, float]) -> np.ndarray:
        """Per episode, log P(observed decision | state, theta): the decision part stepped through the
        cached inputs with fresh regions built with ``theta``."""
        specs = self.circuit.with_params(dict(theta), source="theta").specs if theta else self.circuit.specs
        observed = self.observed
        return np.array([region.log_probability(observed[t])
                         for t, (_, region) in enumerate(self._passes(specs, step_decision=True))], dtype=np.float64)

    def first_impossible(self, logp: np.ndarray) -> str | None:
        """The first episode whose observed decision had probability 0, named, or None."""
        bad = np.flatnonzero(np.isneginf(logp))
        if not len(bad):
            return None
        t = int(bad[0])
        if isinstance(self.behaviour, Trials):
            return f"subject '{self.behaviour.name}', trial {self.behaviour.trials[t]} (choice {self.observed[t]}): " \
                   "probability 0"
        return (f"data set '{self.behaviour.name}', episode {t} (context {self.behaviour.contexts[t]}, "
                f"decision {self.observed[t]}): probability 0")


def _taped(cls: type, observed):
    """A subclass of region class ``cls`` that records its step inputs (``tape``) and, for the
    decision region (``observed`` = (actions, next contexts, scored decisions)), emits the observed
    decision and keeps log P of it (``logp``)."""

    class Taped(cls):
        def reset(self, rng) -> None:
            super().reset(rng)
            self.tape, self.logp, self.t = [], [], 0

        def step(self, *inputs):
            self.tape.append(inputs)
            out = super().step(*inputs)
            if observed is None:
                return out
            t, self.t = self.t, self.t + 1
            self.logp.append(self.log_probability(observed[2][t]))
            names = [s.name for s in cls.outputs]
            out = list(out)
            self.shown = (int(observed[0][t]), int(observed[1][t]))
            for value, key in zip(self.shown, ("action", "next_context")):
                if key in names:
                    out[names.index(key)] = value
            return tuple(out)

        def record(self):
            return (*self.shown, *super().record()[2:]) if observed is not None else super().record()

    Taped.__name__ = Taped.__qualname__ = f"Replayed{cls.__name__}"
    Taped.type_name = cls.type_name
    return Taped


def _retyped(instance, observed):
    """A prebuilt region instance as its taped class (a copy; the original is left untouched)."""
    if instance is None:
        return None
    new = copy.deepcopy(instance)
    new.__class__ = _taped(type(instance), observed)
    return new


def _trial_world(world, trials: Trials, decides: str):
    """The world replaying ``trials``' choices and outcomes; a circuit that cannot replay trials is a ConfigError."""
    if not hasattr(world, "recorded") or decides != "next_context":
        raise ConfigError(trials.source, "choice", "an experiment whose world replays recorded trials (world type "
                          "'options', e.g. --experiment bandit) and whose decision chooses the option",
                          f"world {type(world).__name__}")
    if trials.choices.max() >= world.n_contexts:
        raise ConfigError(trials.source, "choice", f"options 0..{world.n_contexts - 1} of the world",
                          f"{trials.choices.max()} for subject '{trials.name}'")
    return world.recorded(trials.choices, trials.outcomes)
