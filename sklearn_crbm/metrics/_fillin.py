"""Errors of filled-in motion: the paper's fill-in error and an angle RMSE."""

from numbers import Real

import numpy as np
from sklearn.utils._param_validation import Interval, validate_params
from sklearn.utils.validation import check_array, check_consistent_length

__all__ = ["fillin_angle_rmse", "fillin_error"]


def _check_fill(y_true, y_pred, missing_mask):
    y_true = check_array(y_true, ensure_2d=True, dtype="numeric", input_name="y_true")
    y_pred = check_array(y_pred, ensure_2d=True, dtype="numeric", input_name="y_pred")
    if y_true.shape != y_pred.shape:
        raise ValueError(
            f"y_true and y_pred must have the same shape, got {y_true.shape} and "
            f"{y_pred.shape}."
        )
    if missing_mask is None:
        return y_true, y_pred, np.ones(y_true.shape, dtype=bool)
    missing_mask = np.asarray(missing_mask)
    if missing_mask.dtype != bool:
        raise TypeError(
            "missing_mask must be an array of booleans, got dtype "
            f"{missing_mask.dtype}."
        )
    check_consistent_length(y_true, missing_mask)
    if missing_mask.shape != y_true.shape:
        raise ValueError(
            f"missing_mask must have the shape of y_true {y_true.shape}, got "
            f"{missing_mask.shape}."
        )
    if not missing_mask.any():
        raise ValueError("missing_mask marks no entry: there is no fill to score.")
    return y_true, y_pred, missing_mask


@validate_params(
    {
        "y_true": ["array-like"],
        "y_pred": ["array-like"],
        "missing_mask": ["array-like", None],
    },
    prefer_skip_nested_validation=True,
)
def fillin_error(y_true, y_pred, *, missing_mask=None):
    """The paper's fill-in error: per-frame MSE over erased channels, summed.

    For every frame with at least one erased channel, the mean squared error
    over that frame's erased channels; these are summed over the frames
    (Taylor, Hinton & Roweis 2006, §4.4: "mean squared reconstruction error
    per joint ... summed over the 62 frames of interest").  Compute it in the
    normalised space the model works in (z-scored channels).  Lower is
    better; it grows with the number of erased frames.

    Parameters
    ----------
    y_true : array-like of shape (n_frames, n_features)
        The true frames.
    y_pred : array-like of shape (n_frames, n_features)
        The filled frames.
    missing_mask : array-like of bool of shape (n_frames, n_features), default=None
        True where a value was erased and filled in; ``None`` scores every
        entry.  With an imputer, ``np.isnan(X_missing)``.

    Returns
    -------
    error : float
        The summed per-frame mean squared error.

    See Also
    --------
    fillin_angle_rmse : Root mean squared error in degrees.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import fillin_error
    >>> y_true = np.array([[0.0, 1.0, 2.0], [0.0, 1.0, 2.0], [0.0, 1.0, 2.0]])
    >>> y_pred = np.array([[0.0, 1.0, 2.0], [1.0, 1.0, 0.0], [0.0, 2.0, 2.0]])
    >>> mask = np.array([[False, False, False],
    ...                  [True, False, True],
    ...                  [True, True, False]])
    >>> # frame 1: (1 + 4) / 2 = 2.5; frame 2: (0 + 1) / 2 = 0.5
    >>> fillin_error(y_true, y_pred, missing_mask=mask)
    3.0
    """
    y_true, y_pred, missing_mask = _check_fill(y_true, y_pred, missing_mask)
    rows = missing_mask.any(axis=1)
    squared = np.where(missing_mask, np.square(y_true - y_pred), 0.0)[rows]
    per_frame = squared.sum(axis=1) / missing_mask[rows].sum(axis=1)
    return float(per_frame.sum())


@validate_params(
    {
        "y_true": ["array-like"],
        "y_pred": ["array-like"],
        "missing_mask": ["array-like", None],
        "period": [Interval(Real, 0, None, closed="neither"), None],
    },
    prefer_skip_nested_validation=True,
)
def fillin_angle_rmse(y_true, y_pred, *, missing_mask=None, period=360.0):
    """Root mean squared error of filled-in angles, wrapped around the circle.

    The square root of the mean, over the erased entries, of the squared
    difference between true and filled angles, each difference taken the
    short way round the circle (in ``[-period / 2, period / 2)``), so that
    179° against -179° is 2° off.  Use it on raw Euler channels: fill in the
    model's normalised space, map the fill back with the preprocessing's
    ``inverse_transform`` and mark the raw channels of the erased bones.

    Parameters
    ----------
    y_true : array-like of shape (n_frames, n_features)
        The true angles.
    y_pred : array-like of shape (n_frames, n_features)
        The filled angles.
    missing_mask : array-like of bool of shape (n_frames, n_features), default=None
        True where a value was erased and filled in; ``None`` scores every
        entry.
    period : float or None, default=360.0
        The period of the angles (360 for degrees, ``2 * np.pi`` for
        radians); ``None`` takes plain differences (e.g. for positions).

    Returns
    -------
    rmse : float
        In the unit of the angles.

    See Also
    --------
    fillin_error : The paper's error, in normalised space.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import fillin_angle_rmse
    >>> y_true = np.array([[179.0, 10.0], [0.0, 20.0]])
    >>> y_pred = np.array([[-179.0, 13.0], [4.0, 20.0]])
    >>> mask = np.array([[True, True], [True, False]])
    >>> # differences 2, 3 and 4 degrees: sqrt((4 + 9 + 16) / 3)
    >>> round(fillin_angle_rmse(y_true, y_pred, missing_mask=mask), 4)
    3.1091
    """
    y_true, y_pred, missing_mask = _check_fill(y_true, y_pred, missing_mask)
    difference = (y_pred - y_true)[missing_mask]
    if period is not None:
        difference = (difference + period / 2) % period - period / 2
    return float(np.sqrt(np.mean(np.square(difference))))
