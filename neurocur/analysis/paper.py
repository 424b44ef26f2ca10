"""The numbers the paper reports (Luciw et al. 2013), each with the section it comes from.

The one copy of them in the package: the order table
(:func:`neurocur.analysis.report.order_table`), the reproduction study's table
(:mod:`neurocur.analysis.reproduction`) and the iCub figures (:mod:`neurocur.analysis.figures.icub`)
set these beside their own results. The keys of :data:`SYNTHETIC_CURIOUS`,
:data:`SYNTHETIC_RANDOM` and :data:`ICUB_CURIOUS` are the row labels of the order table.
Counts are "runs out of 25" (synthetic, section 4.1.2) or "out of 15" (iCub, section 4.2.2).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EXPERIMENTS", "Reported", "SYNTHETIC_CURIOUS", "SYNTHETIC_RANDOM", "SYNTHETIC_OMEGA", "ICUB_CURIOUS", "ICUB_OMEGA"]


#: The shipped experiments (their ``name``, recorded in a results folder's ``config.toml``) whose
#: conditions are the paper's synthetic experiment (section 4.1) or readings of it: the order
#: table sets the paper's numbers beside these only, not beside a lesion or a world of one's own.
EXPERIMENTS = ("synthetic", "reproduction")


@dataclass(frozen=True)
class Reported:
    """A number of the paper.

    Parameters
    ----------
    value : str
        The number as the paper gives it.
    section : str
        The paper's section it comes from.
    note : str
        Shown beside it in the order table ("implied": it follows from the stated counts without being stated).
    """

    value: str
    section: str
    note: str = ""

    def cell(self) -> str:
        """The value with its note, as the order table prints it: ``"18/25 (implied)"``."""
        return f"{self.value} ({self.note})" if self.note else self.value


#: The curious agent in the synthetic world (section 4.1). Section 4.1.4 reads "S-A's module
#: is mostly third (18/25)"; it means S-C. S-D is never stored: "the end of each run has only
#: the unlearnable context remaining" (4.1.4, Figure 4D). 18 exact runs and 7 with S-B and
#: S-C swapped (τ = 1/3) give the mean Kendall τ (18 + 7/3) / 25 = 0.81.
SYNTHETIC_CURIOUS = {
    "S-A first": Reported("25/25", "4.1.4"),
    "S-B second": Reported("18/25", "4.1.4"),
    "S-C third": Reported("18/25", "4.1.4"),
    "exact S-A→S-B→S-C": Reported("18/25", "4.1.4", "implied"),
    "S-D stored": Reported("0/25", "4.1.4"),
    "modules per run": Reported("3", "4.1.4", "implied"),
    "learnable sources gated": Reported("3", "4.1.4", "implied"),
    "Kendall τ vs Ω": Reported("0.81", "4.1.4", "implied"),
    "S-A learning time (epochs)": Reported("2–3", "4.1.1"),
    "S-B learning time (epochs)": Reported("≈15", "4.1.1"),
    "S-C learning time (epochs)": Reported("≈40", "4.1.1"),
}

#: Random exploration in the synthetic world: "incapable of learning any meaningful
#: representation" (section 4.3).
SYNTHETIC_RANDOM = {
    "learnable sources gated": Reported("0", "4.3", "4.3: learns nothing"),
}

#: Ω (eq 15) of the synthetic learnable sources (section 4.1.1).
SYNTHETIC_OMEGA = {
    "S-A": Reported("0.9933", "4.1.1"),
    "S-B": Reported("0.9988", "4.1.1"),
    "S-C": Reported("0.9997", "4.1.1"),
}

#: The curious agent in the iCub experiment: the easier topple representation was learned
#: first "in 14 of the 15 runs" (section 4.2.2, Figure 6D), and both objects in every run
#: (implied: Figure 6C averages the second module's learning over the runs).
ICUB_CURIOUS = {
    "topple first": Reported("14/15", "4.2.2"),
    "both learned": Reported("15/15", "4.2.2", "implied"),
}

#: Ω (eq 15) of the iCub contexts' images (section 4.2; the paper calls the roll context "push").
ICUB_OMEGA = {
    "topple": Reported("0.9982", "4.2"),
    "roll": Reported("0.9988", "4.2"),
}
