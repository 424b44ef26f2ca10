"""Incremental learners of CD-MISFA: pure mathematics, no brain vocabulary.

| learner | module | paper |
|---|---|---|
| CCIPCA (amnesic incremental PCA, whitening) | ``ccipca`` | Algorithm 2 |
| MCA (CIMCA minor components) | ``mca`` | eqs 8, 16, 17 |
| IncSFA (CCIPCA + CIMCA on the whitened derivative) | ``incsfa`` | Algorithm 1, eq 2 |
| ROC-Amnesic robust online clustering, one clusterer per state | ``roc`` | Algorithm 3, eqs 3, 10 |
| model-based LSPI | ``lspi`` | section 2.8 |
| the learning-cost measure Ω | ``omega`` | eqs 15, 40 |
| exact batch SFA (the reference) | ``sfa_batch`` | eqs 4–7 |

The sequential per-sample loops are compiled with numba in ``_kernels`` and
``_roc_kernels``; the classes validate input and call them once per block. Each
learner declares its parameters once, as regions and worlds do: a dataclass whose fields
are made with :func:`neurocur.config.param` (type, range, default), read back by
:func:`neurocur.config.param_specs`.

IncSFA, CCIPCA and MCA are scikit-learn transformers (``fit``, ``partial_fit``,
``transform``, ``get_params``, ``clone``, ``Pipeline``, ``GridSearchCV``; see
``_estimator``); they pass ``sklearn.utils.estimator_checks.check_estimator`` but for
the checks :func:`expected_failed_checks` lists with their reasons. Their input must be
finite and within a numerical range (``_scale.check_scale``).
"""

from ._estimator import expected_failed_checks
from .ccipca import CCIPCA, AmnesicSchedule
from .incsfa import IncSFA
from .lspi import lspi, value_iteration
from .mca import MCA
from .omega import derivative_eigenvalues, omega
from .roc import ROCBank
from .sfa_batch import BatchSFA, batch_sfa

__all__ = [
    "AmnesicSchedule",
    "BatchSFA",
    "CCIPCA",
    "IncSFA",
    "MCA",
    "ROCBank",
    "batch_sfa",
    "derivative_eigenvalues",
    "expected_failed_checks",
    "lspi",
    "omega",
    "value_iteration",
]
