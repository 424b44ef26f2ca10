"""neurocur: neuromodulation-focused cognitive simulation (CD-MISFA)."""

__version__ = "0.1.0"
