"""Recording: per-episode probes into growing numpy buffers, turned into pandas tables on demand.

During a run nothing but numpy row writes happens: one float64 row per pass holding
every region's probe values (bools and ints as exact floats, categories as codes),
plus, when frame recording is on, one (T, n) block per region per pass. The tables
are built from these same arrays:

- :meth:`Recorder.episodes`: wide, one row per episode (``episode``, ``step``, then
  every probe, named by the probe: probe names are unique within a circuit);
- :meth:`Recorder.probes`: tidy long form ``episode, step, region, signal, value``
  (episode-level rows first, then frame-level rows whose ``step`` is the global frame);
- :meth:`Recorder.events`: the events regions emitted (``episode``, ``step``,
  ``region``, then the event's fields).

The columns that :mod:`neurocur.analysis` reads are declared in :mod:`neurocur.contract`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["Recorder"]

_KIND_DTYPE = {"float": np.float64, "int": np.int64, "bool": bool}


class Recorder:
    """Buffers for the probes of the regions ``[(name, probes, frame_probes), ...]``.

    Parameters
    ----------
    regions : sequence of (str, sequence of Probe, sequence of Probe)
        Each region's name, episode probes and frame probes.
    record_frames : bool
        Also buffer the frame probes.
    capacity : int
        The rows each buffer holds before it grows.
    """

    def __init__(self, regions, *, record_frames: bool = False, capacity: int = 1024):
        self.regions = [(name, tuple(p), tuple(fp)) for name, p, fp in regions]
        self.record_frames = record_frames
        self.columns: list[tuple[str, object]] = []  # (region, Probe) per buffer column
        for name, probes, _ in self.regions:
            self.columns += [(name, p) for p in probes]
        self._rows = np.empty((capacity, len(self.columns)))
        self._steps = np.empty(capacity, dtype=np.int64)
        self.n = 0
        self._frames: list[tuple[int, int, int, np.ndarray]] = []  # (episode, step, region index, block)
        self._events: list[tuple[int, int, str, dict]] = []

    def append(self, step: int, row: tuple) -> None:
        """Store one pass: the global frame at its start and all probe values, concatenated."""
        i = self.n
        if i == len(self._steps):
            self._rows = np.concatenate([self._rows, np.empty_like(self._rows)])
            self._steps = np.concatenate([self._steps, np.empty_like(self._steps)])
        self._steps[i] = step
        self._rows[i] = row
        self.n = i + 1

    def append_frames(self, step: int, region_index: int, block: np.ndarray) -> None:
        self._frames.append((self.n, step, region_index, np.asarray(block, dtype=np.float64)))

    def append_event(self, step: int, region: str, event: dict) -> None:
        self._events.append((self.n, step, region, event))

    # ------------------------------------------------------------------ tables

    @staticmethod
    def _typed(values: np.ndarray, probe):
        if probe.kind == "category":
            return np.asarray(probe.categories, dtype=object)[values.astype(np.int64)]
        return values.astype(_KIND_DTYPE[probe.kind])

    def episodes(self) -> pd.DataFrame:
        data = {"episode": np.arange(self.n, dtype=np.int64), "step": self._steps[: self.n].copy()}
        rows = self._rows[: self.n]
        for j, (_, probe) in enumerate(self.columns):
            data[probe.name] = self._typed(rows[:, j], probe)
        return pd.DataFrame(data)

    def probes(self) -> pd.DataFrame:
        n = self.n
        episode = np.arange(n, dtype=np.int64)
        parts = []
        for j, (region, probe) in enumerate(self.columns):
            parts.append(pd.DataFrame({"episode": episode, "step": self._steps[:n], "region": region,
                                       "signal": probe.name, "value": self._rows[:n, j]}))
        for ep, step, r, block in self._frames:
            name, _, frame_probes = self.regions[r]
            T = block.shape[0]
            for j, probe in enumerate(frame_probes):
                parts.append(pd.DataFrame({"episode": np.full(T, ep, dtype=np.int64),
                                           "step": step + np.arange(T, dtype=np.int64), "region": name,
                                           "signal": probe.name, "value": block[:, j]}))
        if not parts:
            return pd.DataFrame({"episode": np.empty(0, np.int64), "step": np.empty(0, np.int64),
                                 "region": np.empty(0, object), "signal": np.empty(0, object), "value": np.empty(0)})
        table = pd.concat(parts, ignore_index=True)
        table["region"] = table["region"].astype(object)
        table["signal"] = table["signal"].astype(object)
        return table

    def events(self, kind: str | None = None) -> pd.DataFrame:
        rows = [{"episode": ep, "step": step, "region": region, **ev}
                for ep, step, region, ev in self._events if kind is None or ev.get("event") == kind]
        return pd.DataFrame(rows, columns=None if rows else ["episode", "step", "region", "event"])
