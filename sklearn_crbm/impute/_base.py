"""What both imputers share: input checks and the missing-value mask."""

import numpy as np
from sklearn.utils._array_api import (
    _convert_to_numpy,
    _is_numpy_namespace,
    get_namespace,
    get_namespace_and_device,
)
from sklearn.utils._mask import _get_mask
from sklearn.utils._missing import is_scalar_nan
from sklearn.utils.validation import FLOAT_DTYPES, validate_data

from ..utils._array_api import array_ops
from ..utils._sequences import check_sequence_ids


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


def to_numpy(array):
    """``array`` as a numpy array (a copy off the host)."""
    return _convert_to_numpy(array, get_namespace_and_device(array)[0])


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
