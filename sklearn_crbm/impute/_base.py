"""What the imputers share: a base class with their input checks and tags."""

import numpy as np
from sklearn.base import BaseEstimator, OneToOneFeatureMixin, TransformerMixin
from sklearn.utils._array_api import (
    _is_numpy_namespace,
    check_same_namespace,
    get_namespace,
    get_namespace_and_device,
)
from sklearn.utils._mask import _get_mask
from sklearn.utils._missing import is_scalar_nan
from sklearn.utils._param_validation import MissingValues
from sklearn.utils.validation import FLOAT_DTYPES, check_is_fitted, validate_data

from ..utils._array_api import array_ops, to_numpy
from ..utils._persistence import VersionedPickleMixin
from ..utils._sequences import check_sequence_ids

__all__ = ["BaseMotionImputer"]


class BaseMotionImputer(
    VersionedPickleMixin, OneToOneFeatureMixin, TransformerMixin, BaseEstimator
):
    """Base class of the imputers of motion sequences.

    They follow :mod:`sklearn.impute`: ``fit`` learns from complete frames,
    ``transform`` fills every entry equal to ``missing_values`` and returns
    the observed values unchanged, and both take ``sequence_ids`` (requested
    through metadata routing, so a Pipeline passes it on).  Subclasses call
    :meth:`_complete_frames` at the start of ``fit`` and
    :meth:`_check_transform_input` at the start of ``transform``, and name
    in ``_fitted_attribute`` a fitted array whose namespace and device the
    input must share.
    """

    _parameter_constraints: dict = {"missing_values": [MissingValues()]}

    # With sklearn.set_config(enable_metadata_routing=True) a Pipeline or a
    # search passes ``sequence_ids`` to these methods without being asked.
    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}

    _fitted_attribute: str

    def _complete_frames(self, X, sequence_ids):
        """Validate ``fit``'s input; its complete frames, their run ids and rows.

        A frame with a missing value is left out and splits its sequence in
        two (:func:`complete_runs`).
        """
        X, mask = check_imputer_input(self, X, reset=True)
        rows, run_ids = complete_runs(to_numpy(mask), sequence_ids)
        return array_ops(X).take(X, rows, axis=0), run_ids, rows

    def _check_transform_input(self, X, sequence_ids):
        """Validate ``transform``'s input: ``X`` (a float copy), its mask, sequences."""
        check_is_fitted(self)
        check_same_namespace(
            X, self, attribute=self._fitted_attribute, method="transform"
        )
        X, mask = check_imputer_input(self, X, reset=False)
        check_same_place(
            getattr(self, self._fitted_attribute),
            X,
            f"{type(self).__name__} was fitted on",
        )
        return X, mask, check_sequence_ids(sequence_ids, X.shape[0])

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit on ``X``, then fill its missing values.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Training sequences; the imputer learns from their complete
            frames, then their missing values are filled.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        X_filled : ndarray of shape (n_frames, n_features)
            ``X`` with no missing value left, as a new array.
        """
        return self.fit(X, sequence_ids=sequence_ids).transform(
            X, sequence_ids=sequence_ids
        )

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = is_scalar_nan(self.missing_values)
        tags.array_api_support = True
        return tags


def check_imputer_input(imputer, X, *, reset):
    """Validate ``X`` the way :mod:`sklearn.impute` does.

    NaN is allowed when it is the missing-value marker; the returned array is
    a float copy (never the caller's array), so it can be filled in place.
    ``X`` may be any array API namespace's array (with
    ``sklearn.set_config(array_api_dispatch=True)``), and stays in it.

    Returns
    -------
    X : ndarray of shape (n_frames, n_features)
    mask : ndarray of bool of shape (n_frames, n_features)
        True where ``X`` holds ``missing_values``.
    """
    xp = get_namespace(X)[0]
    ensure_all_finite = "allow-nan" if is_scalar_nan(imputer.missing_values) else True
    X = validate_data(
        imputer,
        X,
        dtype=FLOAT_DTYPES if _is_numpy_namespace(xp) else [xp.float64, xp.float32],
        ensure_all_finite=ensure_all_finite,
        copy=True,
        force_writeable=True,
        reset=reset,
    )
    if _is_numpy_namespace(xp):
        return X, _get_mask(X, imputer.missing_values)
    if is_scalar_nan(imputer.missing_values):
        return X, xp.isnan(X)
    return X, X == imputer.missing_values


def complete_runs(mask, sequence_ids):
    """The complete frames, split into runs of consecutive complete frames.

    ``fit`` learns from complete frames only: a frame with a missing value
    is left out and splits its sequence in two, so that no history ever
    spans a gap.

    Returns
    -------
    rows : ndarray of shape (n_complete,)
        Indices of the complete frames.
    run_ids : ndarray of shape (n_complete,)
        A sequence id for every complete frame: one per run.
    """
    complete = ~mask.any(axis=1)
    if not complete.any():
        raise ValueError(
            "fit needs complete frames, but every frame of X holds a missing value."
        )
    sequences = check_sequence_ids(sequence_ids, mask.shape[0])
    ids = sequences.per_frame_ids()
    new_run = np.ones(mask.shape[0], dtype=bool)
    new_run[1:] = (ids[1:] != ids[:-1]) | ~complete[:-1]
    run_ids = np.cumsum(new_run) - 1
    rows = np.flatnonzero(complete)
    return rows, run_ids[rows]


def check_same_place(fitted, X, what):
    """Refuse ``X`` in another namespace or on another device than ``fitted``."""
    if array_ops(fitted) is not array_ops(X):
        fitted_xp, _, fitted_device = get_namespace_and_device(fitted)
        xp, _, device = get_namespace_and_device(X)
        raise TypeError(
            f"{what} {fitted_xp.__name__} arrays on {fitted_device!r}, but X is "
            f"{xp.__name__} on {device!r}. Pass X in the model's namespace and on "
            "its device, or move the model first with "
            "sklearn.utils._array_api.move_estimator_to(model, xp, device) (the "
            "model, or the fitted imputer)."
        )
