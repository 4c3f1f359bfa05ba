"""What both imputers share: input checks and the missing-value mask."""

import numpy as np
from sklearn.utils._array_api import _is_numpy_namespace, get_namespace
from sklearn.utils._mask import _get_mask
from sklearn.utils._missing import is_scalar_nan
from sklearn.utils.validation import FLOAT_DTYPES, validate_data

from ..utils._sequences import check_sequence_ids


def check_imputer_input(imputer, X, *, reset, array_api=False):
    """Validate ``X`` the way :mod:`sklearn.impute` does.

    NaN is allowed when it is the missing-value marker; the returned array is
    a float copy (never the caller's array), so it can be filled in place.
    ``array_api=True``: ``X`` may be any array API namespace's array (with
    ``sklearn.set_config(array_api_dispatch=True)``), and stays in it.

    Returns
    -------
    X : ndarray of shape (n_frames, n_features)
    mask : ndarray of bool of shape (n_frames, n_features)
        True where ``X`` holds ``missing_values``.
    """
    xp = get_namespace(X)[0]
    if not (array_api or _is_numpy_namespace(xp)):
        raise TypeError(
            f"{type(imputer).__name__} fills numpy arrays only; got {xp.__name__} "
            "input under sklearn.set_config(array_api_dispatch=True). Pass X as a "
            "numpy array (e.g. X.cpu().numpy() for a torch tensor); a model trained "
            "on a GPU moves to numpy with sklearn.utils._array_api."
            "move_estimator_to(model, numpy, 'cpu')."
        )
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
