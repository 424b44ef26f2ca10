"""neurocur: neuromodulation-focused cognitive simulation (CD-MISFA).

``neurocur.load_agent(DIR, condition, run)``: a run's saved agent as a simulator
(:func:`neurocur.experiments.agent.load_agent`).
"""

import importlib

__version__ = "0.1.0"


def __getattr__(name: str):
    # imported on first use, by name: every layer reads ``neurocur.__version__``, and importing this
    # package must not import the experiment layer above them
    if name == "load_agent":
        return importlib.import_module("neurocur.experiments.agent").load_agent
    raise AttributeError(f"module 'neurocur' has no attribute {name!r}")
