"""The runs an experiment still has to compute, generated as they are needed.

``--runs 100000000`` must start computing at once: :class:`Pending` holds only the selected
conditions, the run count and the finished runs, and yields each (condition, run) pair,
with its seed made from the run's index (:meth:`~neurocur.experiments.conditions.Experiment.run_seed`),
when the scheduler asks for the next one.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

__all__ = ["Pending"]


class Pending:
    """The (condition, run) pairs of ``conditions`` × ``range(runs)`` not in ``done``, condition by
    condition, each run in order; sized and iterable without listing them.

    Parameters
    ----------
    conditions : sequence of Condition
        The selected conditions, in order (anything with a ``name``).
    runs : int
        The runs of each condition.
    done : set of (str, int)
        The finished (condition name, run) pairs; pairs outside ``conditions`` × ``range(runs)`` are ignored.
    """

    def __init__(self, conditions: Sequence, runs: int, done: set[tuple[str, int]]):
        self.conditions = list(conditions)
        self.runs = int(runs)
        names = {c.name for c in self.conditions}
        self.done = {(c, i) for c, i in done if c in names and 0 <= i < self.runs}

    def __len__(self) -> int:
        return len(self.conditions) * self.runs - len(self.done)

    def __bool__(self) -> bool:
        return len(self) > 0

    def __iter__(self) -> Iterator[tuple]:
        for condition in self.conditions:
            for run in range(self.runs):
                if (condition.name, run) not in self.done:
                    yield condition, run

    def first_of_each(self) -> dict[str, tuple]:
        """Each condition's first pending run, by name (conditions with none left out)."""
        first = {}
        for condition in self.conditions:
            run = next((i for i in range(self.runs) if (condition.name, i) not in self.done), None)
            if run is not None:
                first[condition.name] = (condition, run)
        return first
