"""The recording contract: the columns of the results tables that the analysis reads.

Declared once, here: :data:`EPISODE_COLUMNS` (the episodes table, one row per episode,
from the regions' probes) and :data:`MODULE_COLUMNS` (the stored-module table, HPC's
end-of-run product ``"modules"``). A region type that takes over a role of the circuit
(a VTA model, an LC model) produces the columns of that role;
``tests/circuit/test_contract.py`` runs every registered region type through this
contract, and :func:`require_columns` gives an analysis function a clear error when a
table lacks what it reads. The units and meanings are in docs/regions.md.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Column", "EPISODE_COLUMNS", "MODULE_COLUMNS", "require_columns"]


@dataclass(frozen=True)
class Column:
    """A column of a results table: its name, kind (as :class:`~neurocur.regions.base.Probe`),
    unit, meaning and the circuit role (region name in ``neurocur/circuits/cd_misfa.toml``) producing it.

    Parameters
    ----------
    name : str
        The column's name.
    kind : str
        ``"float"``, ``"int"``, ``"bool"`` or ``"category"``.
    unit : str
        Its unit.
    doc : str
        What it means.
    role : str
        The circuit role (region name) producing it.
    """

    name: str
    kind: str
    unit: str
    doc: str
    role: str


#: The episodes table's columns read by the analysis (docs/regions.md, "Recorded signals").
EPISODE_COLUMNS = (
    Column("episode", "int", "index", "pass number of the run", "scheduler"),
    Column("step", "int", "frames", "global frame at the start of the episode", "scheduler"),
    Column("context", "int", "index", "context of this episode", "sensory"),
    Column("n_frames", "int", "frames", "frames in this episode (block)", "sensory"),
    Column("reward", "float", "reward units", "extrinsic reward the world paid for this episode", "sensory"),
    Column("familiar", "bool", "", "a frozen module gates this episode", "HPC"),
    Column("gating_module", "int", "index", "frozen module that gates this episode; -1 if none", "HPC"),
    Column("error", "float", "feature distance", "adaptive module's context error (eq 11 / M)", "HPC"),
    Column("module_learned", "bool", "", "the adaptive module is stored at this episode", "HPC"),
    Column("n_modules", "int", "modules", "library size after this episode", "HPC"),
    Column("da", "float", "reward units per episode", "dopamine: the reward of this episode", "VTA"),
    Column("q_engage", "float", "discounted DA", "Q(current context, engage)", "PFC"),
    Column("q_disengage", "float", "discounted DA", "Q(current context, disengage)", "PFC"),
    Column("action", "category", "", "decision at the end of this episode", "LC"),
    Column("next_context", "int", "index", "context of the next episode", "LC"),
    Column("ne_tonic", "float", "[0, 1]", "tonic noradrenaline", "LC"),
    Column("ne_phasic", "float", "[0, 1]", "phasic noradrenaline", "LC"),
)

#: The stored-module table (end-of-run product ``"modules"``), one row per stored module.
MODULE_COLUMNS = (
    Column("module", "int", "index", "rank of the module in the library", "HPC"),
    Column("step", "int", "frames", "global frame at the start of the storing episode", "HPC"),
    Column("episode", "int", "index", "episode at which it was stored", "HPC"),
    Column("context", "int", "index", "context in which it was learned", "HPC"),
    Column("n_clusters", "int", "clusters", "clusters kept by its clusterers", "HPC"),
)


def require_columns(table, names, *, needed_by: str) -> None:
    """Raise ValueError when ``table`` lacks any of ``names``, naming the role that produces each.

    Parameters
    ----------
    table : DataFrame
        The table checked.
    names : sequence of str
        The columns it must have.
    needed_by : str
        What needs them, named in the message.
    """
    missing = [n for n in names if n not in table.columns]
    if missing:
        roles = {c.name: c.role for c in MODULE_COLUMNS + EPISODE_COLUMNS}  # the episodes table's roles win
        detail = ", ".join(f"{n!r} (from {roles.get(n, 'no declared role')})" for n in missing)
        raise ValueError(f"{needed_by} needs the column(s) {detail}; see neurocur.contract")
