"""Model selection for sequence models and imputers.

:func:`make_imputation_scorer` turns a fill-in error into a scorer for
:class:`~sklearn.model_selection.GridSearchCV`: it erases a pattern of
channels in held-out sequences and scores how an imputer fills them;
:func:`make_prediction_scorer` scores a model's one-step-ahead prediction of
held-out frames.  Without a ``scoring=``, a search ranks ConditionalRBMs by
their held-out log-likelihood (:meth:`~sklearn_crbm.ConditionalRBM.score`).
"""

from ._scorers import make_imputation_scorer, make_prediction_scorer

__all__ = ["make_imputation_scorer", "make_prediction_scorer"]
