"""The statistics of a results folder, one module per question (re-exported by :mod:`neurocur.analysis`).

Every function that needs more than one table takes a :class:`~neurocur.analysis.results.Results`;
the tests and adjustments take the per-run tables those functions return. Nothing here imports
matplotlib; :mod:`~neurocur.analysis.stats.inverted_u` and :mod:`~neurocur.analysis.stats.goldilocks`
import statsmodels' full API and are imported on first use.
"""
