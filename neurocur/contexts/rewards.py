"""Extrinsic reward per context, for every world: the ``rewards`` key of ``[world]``.

A world may pay an extrinsic reward for each visit of a context (:attr:`.base.Episode.reward`,
also the reward of :meth:`.base.World.step`). An experiment file declares it in its
``[world]`` table, one entry per context, in context order::

    [world]
    rewards = [0, 0, 1.0, [1, 0, 0], 0]

An entry is a number, the reward of every visit of that context, or a **schedule**: a
non-empty list of numbers cycled per visit of that context. Visit ``k`` of a context
(``k = 0, 1, ...``, counted per context from the start of the run, so a context's count
is not advanced by visits of others) pays ``schedule[k % len(schedule)]``: ``[1, 0, 0]``
pays on the first, fourth, seventh ... visit. One visit is one episode (one
:meth:`~.base.World.step`; an agent that stays for two episodes makes two visits). Without
``rewards`` (the default) every visit pays 0. The counts restart with every
:meth:`~.base.World.reset`; nothing is drawn at random, so the world's random stream is
the same with and without rewards.

Each world's parameter class declares the key with :func:`rewards_param` and checks it
with :func:`check_rewards` (a list of the wrong length is a ConfigError that names the key
and the expected length); the world turns it into a :class:`Rewards`, which
:class:`~.base.World` pays out.
"""

from __future__ import annotations

from collections.abc import Sequence

from neurocur.config import ConfigError, ParamSpec, describe, spec_param

__all__ = ["Rewards", "check_rewards", "rewards_param"]

_NUMBER = ParamSpec(float)
#: An entry: a number, or a schedule (a list, checked item by item by :func:`check_rewards`).
_ENTRY = ParamSpec(float, classes=(list, tuple))
_EXPECTED = "a number or a schedule (a non-empty list of numbers, cycled per visit of the context)"


def rewards_param():
    """The ``rewards`` field of a world's parameter class (None: no extrinsic reward)."""
    return spec_param(None, ParamSpec.sequence(_ENTRY, min_length=1, optional=True),
                      doc="extrinsic reward per context: a number or a list cycled per visit")


def check_rewards(params, n_contexts: int, names: Sequence[str] | None = None) -> None:
    """Check ``params.rewards`` against the world's ``n_contexts`` (``names``: the contexts, for
    the message) and store each schedule as a tuple of floats. Call it in ``__post_init__``
    after :func:`~neurocur.config.check_params`.

    Parameters
    ----------
    params : dataclass instance
        A world's parameters with a ``rewards`` field (None: nothing to check); a schedule is stored
        back into it as a tuple of floats.
    n_contexts : int
        The world's number of contexts: ``rewards`` needs one entry per context.
    names : sequence of str, optional
        The context names, listed in the message.

    Raises
    ------
    ConfigError
        ``rewards`` of the wrong length, an empty schedule, or a schedule item that is not a number
        (naming ``rewards[i][j]``).
    """
    where, rewards = type(params).__name__, params.rewards
    if rewards is None:
        return
    if len(rewards) != n_contexts:
        which = f": {', '.join(names)}" if names else ""
        raise ConfigError(where, "rewards", f"a list of {n_contexts} entries (one per context{which}), each {_EXPECTED}",
                          f"{len(rewards)} entries {describe(list(rewards))}")
    checked = []
    for i, entry in enumerate(rewards):
        if isinstance(entry, (list, tuple)):
            if not entry:
                raise ConfigError(where, f"rewards[{i}]", _EXPECTED, "an empty list")
            entry = tuple(_NUMBER.coerce(v, source=where, key=f"rewards[{i}][{j}]") for j, v in enumerate(entry))
        checked.append(entry)
    object.__setattr__(params, "rewards", tuple(checked))


class Rewards:
    """The reward each visit pays, per context, from checked entries (:func:`check_rewards`).

    Parameters
    ----------
    rewards : sequence
        One checked entry per context: a number (paid at every visit) or a tuple of numbers (a
        schedule, cycled per visit of the context).
    """

    def __init__(self, rewards: Sequence):
        self.schedules = tuple(entry if isinstance(entry, tuple) else (float(entry),) for entry in rewards)
        self.reset()

    @classmethod
    def of(cls, rewards: Sequence | None) -> Rewards | None:
        """The rewards of a parameter value (None when the world pays none)."""
        return None if rewards is None else cls(rewards)

    def reset(self) -> None:
        """Restart every context's visit count (a new run)."""
        self.visits = [0] * len(self.schedules)

    def pay(self, context: int) -> float:
        """The reward of this visit of ``context``; counts the visit."""
        schedule = self.schedules[context]
        k = self.visits[context]
        self.visits[context] = k + 1
        return schedule[k % len(schedule)]
