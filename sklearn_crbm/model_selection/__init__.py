"""Model selection for sequence models and imputers.

:func:`make_imputation_scorer` turns a fill-in error into a scorer for
:class:`~sklearn.model_selection.GridSearchCV`: it erases a pattern of
channels in held-out sequences and scores how an imputer fills them.
"""

from ._scorers import make_imputation_scorer

__all__ = ["make_imputation_scorer"]
