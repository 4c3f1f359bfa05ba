"""Model selection for sequence models and imputers.

:func:`make_imputation_scorer` turns a fill-in error into a scorer for
:class:`~sklearn.model_selection.GridSearchCV`: it erases a pattern of
channels in held-out sequences and scores how an imputer fills them.
:func:`erasure_mask` is that pattern (by default from half-way through every
sequence, as in the paper), and :func:`make_fillin_cases` builds the paper's
fill-in cases (§4.4) from held-out trials and :func:`paper_body_parts`;
:func:`compare_imputers` scores fitted imputers on them.
:func:`make_prediction_scorer` scores a model's one-step-ahead prediction of
held-out frames; without a ``scoring=``, a search ranks ConditionalRBMs by
their held-out log-likelihood (:meth:`~sklearn_crbm.ConditionalRBM.score`).
"""

from ._fillin import (
    compare_imputers,
    erasure_mask,
    make_fillin_cases,
    paper_body_parts,
)
from ._scorers import make_imputation_scorer, make_prediction_scorer

__all__ = [
    "compare_imputers",
    "erasure_mask",
    "make_fillin_cases",
    "make_imputation_scorer",
    "make_prediction_scorer",
    "paper_body_parts",
]
