"""Fitting circuits to behaviour (design section 7): data, replay, maximum likelihood, recovery, comparison.

| part | module |
|---|---|
| behaviour data: a tidy table of episodes, CSV, Parquet or a results folder | ``data`` |
| people's trials: one row per trial (subject, trial, choice, outcome), CSV, Parquet or tab-separated text | ``trials`` |
| a model's declared free parameters and the kind of data it reads | ``models`` |
| replay: log P(observed decisions given theta), cached learning part | ``replay`` |
| the decision part: the regions a cached replay runs again for each theta | ``part`` |
| the decision part's recorded inputs, played back to it as a circuit the scheduler steps | ``tape`` |
| maximum likelihood with several starts, profile-likelihood intervals | ``mle`` |
| parametric bootstrap: percentile intervals from refits of data sets simulated at the estimate | ``bootstrap`` |
| random-effects Bayesian model selection (Stephan et al. 2009, Rigoux et al. 2014) | ``bms`` |
| Ten et al. 2021's posted trial files as trial tables, the paper's exclusion | ``ten2021`` |
| the signals of Ten et al. 2021's choice models (PC, LP, plays) | ``ten2021_utilities`` |
| group parameters: empirical-Bayes EM with a Laplace approximation (Huys et al. 2011) | ``hierarchical``, ``transforms`` |
| a subject's Laplace posterior and evidence, the group's sampled evidence, the integrated BIC | ``evidence`` |

A layer above :mod:`neurocur.experiments`: it builds circuits and worlds from experiment files.
"""
