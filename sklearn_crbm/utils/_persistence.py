"""Pickling that records the scikit-learn version, as scikit-learn's estimators do."""

import warnings

import sklearn
from sklearn.exceptions import InconsistentVersionWarning

__all__ = ["VersionedPickleMixin"]


class VersionedPickleMixin:
    """Record the scikit-learn version in pickles; warn when it differs on load.

    :class:`sklearn.base.BaseEstimator` stores ``_sklearn_version`` in the
    pickled state and warns with
    :class:`~sklearn.exceptions.InconsistentVersionWarning` on loading under
    another version, but only for classes defined in ``sklearn.*`` modules.
    This mixin does the same for the estimators of this package, whose
    fitted state (weights, scaler statistics, seed windows) may depend on
    scikit-learn internals too.  Put it to the left of ``BaseEstimator``.

    Examples
    --------
    >>> import warnings
    >>> import sklearn
    >>> from sklearn.base import BaseEstimator
    >>> from sklearn_crbm.utils._persistence import VersionedPickleMixin
    >>> class Model(VersionedPickleMixin, BaseEstimator):
    ...     pass
    >>> state = Model().__getstate__()
    >>> state["_sklearn_version"] == sklearn.__version__
    True
    >>> state["_sklearn_version"] = "0.24.2"  # as if pickled by an old release
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     Model.__new__(Model).__setstate__(state)
    >>> type(caught[0].message).__name__
    'InconsistentVersionWarning'
    """

    # Parameters added after models were first saved, with the value under
    # which a model pickled before them was trained: set on loading when the
    # pickle lacks them, so get_params, clone and training keep working.
    _added_parameters: dict = {}

    def __getstate__(self):
        state = super().__getstate__()
        return dict(state, _sklearn_version=sklearn.__version__)

    def __setstate__(self, state):
        state = dict(state)
        pickled_version = state.pop("_sklearn_version", "pre-0.18")
        if pickled_version != sklearn.__version__:
            warnings.warn(
                InconsistentVersionWarning(
                    estimator_name=type(self).__name__,
                    current_sklearn_version=sklearn.__version__,
                    original_sklearn_version=pickled_version,
                )
            )
        for name, value in self._added_parameters.items():
            state.setdefault(name, value)
        super().__setstate__(state)
