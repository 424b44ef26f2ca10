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

**Cached replay.** The *decision part* (:mod:`neurocur.fit.part`) is the decision region and every
region on a path from a region with a fitted parameter to it (e.g. PFC for eq 14's alpha). Everything else,
the *learning part*, does not depend on the fitted parameters, so it runs once: the replay
records every input of the decision part, pass by pass. :meth:`Replay.loglik` then runs the
decision part again with each theta, as a circuit of its own that the scheduler builds and steps
(:func:`~neurocur.fit.tape.part_circuit`: the part's regions, their edges, delayed ones and
initial values as the scheduler runs them, and a region playing back the recorded inputs from
outside the part), reset with the run's seed sequence, so every region has the generator it had in
the run. For a decision region that declares a vectorised likelihood (a classmethod
``log_likelihoods``, :class:`~neurocur.regions.lc.LCRole`) it evaluates all thetas at once on the
decision's inputs, which the upstream part (PFC) gives once per upstream theta.

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

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np

from ..circuit import Circuit, RegionSpec
from ..circuit.specs import ports
from ..config import ConfigError
from ..regions.base import NoParams
from ..regions.free_choice import RecordedSignal
from ..regions.pfc import DISENGAGE, ENGAGE
from .data import Behaviour
from .part import decision_part, observed_outputs
from .tape import InputTape, part_circuit, retyped, scoring, taped
from .trials import Trials

__all__ = ["Replay", "signal_circuit"]


def signal_circuit(circuit: Circuit, name: str, behaviour: Behaviour, signal: str) -> Circuit:
    """``circuit`` with region ``name`` replaced by a :class:`~neurocur.regions.free_choice.RecordedSignal`
    emitting the data set's column ``signal`` (signal replay).

    Parameters
    ----------
    circuit : Circuit
        The model's circuit.
    name : str
        The region that would compute the signal (e.g. ``"HPC"``).
    behaviour : Behaviour
        The data set; its per-episode column ``signal`` is emitted.
    signal : str
        A per-episode column of ``behaviour`` (a ConfigError if it has none).

    Returns
    -------
    Circuit
        The circuit with region ``name`` replaced (``Circuit.replace``).
    """
    if signal not in behaviour.signals:
        raise ConfigError(behaviour.source, signal, f"a per-episode column '{signal}' for signal replay", "none")
    return circuit.replace(name, RecordedSignal(name, series=behaviour.signals[signal]))


class Replay:
    """One data set replayed through a circuit (module docstring).

    After construction, :attr:`logp` holds the per-episode log-probabilities at the circuit's own
    parameters, and :meth:`loglik` evaluates any theta on the cached inputs.

    Parameters
    ----------
    circuit : Circuit
        The model's circuit (with a :class:`~neurocur.regions.free_choice.RecordedSignal` for signal
        replay, :func:`signal_circuit`).
    world
        Its world (a world of options for ``Trials``).
    seed : int or numpy.random.SeedSequence
        The circuit's seed (a results folder's run seed reproduces the run's world).
    behaviour : Behaviour or Trials
        Episodes (:class:`~neurocur.fit.data.Behaviour`) or a subject's trials
        (:class:`~neurocur.fit.trials.Trials`, replayed by the world of options with the recorded outcomes).
    decision : str
        The decision region.
    fitted : sequence of str
        The ``"REGION.param"`` keys to be varied; they decide the decision part
        (:func:`~neurocur.fit.part.decision_part`).
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
        """Keep what the likelihood evaluations read from the one full run ``sim``: the decision part as a
        circuit of its own on the recorded inputs (:func:`~neurocur.fit.tape.part_circuit`), with the
        decision region scoring the observed decisions, and, for a vectorised decision, with an
        :class:`~neurocur.fit.tape.InputTape` in its place."""
        regions, decision, circuit = sim.regions, self.decision, self.circuit
        self.seed_sequence = sim.seed_sequence
        tapes = {n: regions[n].tape for n in self.part}
        self.logp = np.array(regions[decision].logp)
        self.episodes = sim.episodes()
        given = self.episodes["given"].to_numpy() if "given" in self.episodes.columns else 0
        self.scored = np.broadcast_to(np.asarray(given) == 0, (len(self.observed),)).copy()
        observed = observed_outputs(circuit, decision)
        spec = circuit.specs[decision]
        scored = scoring(spec.cls, self.observed)
        self._stepped = part_circuit(circuit, self.part, tapes, observed=observed, decision=dataclasses.replace(
            spec, cls=scored, instance=retyped(spec.instance, scored)))
        #: True when no region of the decision part reads a decision output other than the observed ones, so
        #: that the decision's inputs depend on the upstream parameters only (:meth:`_decision_tape`)
        self._separable = not any(k.src == decision and k.dst in self.part and k.signal not in observed
                                  for k in circuit.links)
        self._decision_inputs = tapes[decision]
        if self._separable and self.part != (decision,):
            stand_in = InputTape(decision, inputs=ports(spec, "inputs"))
            self._upstream = part_circuit(circuit, self.part, tapes, observed=observed,
                                          decision=RegionSpec(decision, InputTape, NoParams(), instance=stand_in))

    # ------------------------------------------------------------------ the one full run

    def _context_index(self, name: str) -> int:
        return [s.name for s in self.circuit.specs[name].cls.inputs].index("context")

    def _run(self, circuit: Circuit, seed):
        specs = dict(circuit.specs)
        for name in self.part:
            specs[name] = self._taped_spec(specs[name])
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

    def _taped_spec(self, spec: RegionSpec) -> RegionSpec:
        """``spec`` as a region that records its inputs and, the decision region, emits and scores the
        observed decisions (:func:`~neurocur.fit.tape.taped`)."""
        observed = (self.actions, self.next_contexts, self.observed) if spec.name == self.decision else None
        cls = taped(spec.cls, observed)
        return dataclasses.replace(spec, cls=cls, instance=retyped(spec.instance, cls))

    # ------------------------------------------------------------------ many thetas

    @property
    def n_obs(self) -> int:
        """The scored decisions (a given pass, module docstring, is not an observation)."""
        return int(self.scored.sum())

    def n_scored(self, mask=None) -> int:
        """The scored decisions among the passes ``mask`` selects.

        Parameters
        ----------
        mask : array of bool, optional
            Over the episodes (trials); all of them without one.

        Returns
        -------
        int
            The number of scored decisions (:attr:`scored`) among them.
        """
        return self.n_obs if mask is None else int(np.sum(self.scored & np.asarray(mask, dtype=bool)))

    def loglik(self, theta: Mapping[str, float] | Sequence[Mapping[str, float]], mask=None):
        """The log-likelihood of the observed decisions at ``theta``.

        A decision given probability 0 makes it -inf (:meth:`first_impossible` names the episode).

        Parameters
        ----------
        theta : mapping of str to float, or a sequence of them
            ``{"REGION.param": value}`` with only :attr:`fitted` keys (the circuit's value for the others).
        mask : array of bool, optional
            Over the episodes: sums only the episodes it selects (held-out scores).

        Returns
        -------
        float or numpy.ndarray
            The log-likelihood for one theta, an array of them for a sequence.
        """
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

    def _decision_tape(self, upstream: tuple) -> list:
        """The decision region's inputs, pass by pass, with the decision part's upstream regions (e.g.
        PFC) built with the ``upstream`` parameters and stepped by the scheduler (:meth:`_part_run`);
        memoised (the last 64), so that many decision parameters cost one upstream pass."""
        if self.part == (self.decision,):
            return self._decision_inputs
        memo = self.__dict__.setdefault("_memo", {})
        if upstream in memo:
            return memo[upstream]
        tape = self._part_run(self._upstream, dict(upstream)).regions[self.decision].tape
        if len(memo) >= 64:
            memo.pop(next(iter(memo)))
        memo[upstream] = tape
        return tape

    def _part_run(self, part: Circuit, theta: dict):
        """The decision part's circuit ``part`` with the parameters ``theta``, built on the run's world with
        the run's seed sequence (so every region is reset with the generator it had in the run: its decision
        draws are discarded, the observed decision replaces them; a stream of its own that the draws do not
        move, such as the FitzHugh–Nagumo LC's input noise, is the run's) and run through the recorded passes."""
        unknown = sorted(k for k in theta if k.split(".", 1)[0] not in self.part)
        if unknown:
            raise ConfigError("theta", unknown[0], f"'REGION.param' with REGION one of the decision part "
                              f"({', '.join(self.part)})", "a region the replay does not step again")
        circuit = part.with_params(theta, source="theta") if theta else part
        return circuit.build(self.world, self.seed_sequence).run(len(self.observed))

    def episode_logp(self, theta: Mapping[str, float]) -> np.ndarray:
        """Per episode, log P(observed decision | state, theta): the decision part stepped again on the
        recorded inputs, by the scheduler, with its regions built with ``theta``.

        Parameters
        ----------
        theta : mapping of str to float
            ``{"REGION.param": value}`` for regions of the decision part (:attr:`part`); the circuit's own
            value for every other parameter.

        Returns
        -------
        numpy.ndarray
            One log-probability per episode (trial): 0 on a given pass, -inf for a decision of probability 0.
        """
        return np.array(self._part_run(self._stepped, dict(theta)).regions[self.decision].logp, dtype=np.float64)

    def first_impossible(self, logp: np.ndarray) -> str | None:
        """The first episode whose observed decision had probability 0, named.

        Parameters
        ----------
        logp : numpy.ndarray
            Per-episode log-probabilities (:meth:`episode_logp`).

        Returns
        -------
        str or None
            The data set (subject), the episode (trial) and its decision, or None when none is -inf.
        """
        bad = np.flatnonzero(np.isneginf(logp))
        if not len(bad):
            return None
        t = int(bad[0])
        if isinstance(self.behaviour, Trials):
            return f"subject '{self.behaviour.name}', trial {self.behaviour.trials[t]} (choice {self.observed[t]}): " \
                   "probability 0"
        return (f"data set '{self.behaviour.name}', episode {t} (context {self.behaviour.contexts[t]}, "
                f"decision {self.observed[t]}): probability 0")


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
