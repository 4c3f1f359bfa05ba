"""Ridge regression of frames on their past: the linear autoregressive model."""

import numpy as np
from scipy import linalg
from sklearn.utils import Bunch

from ._array_api import array_ops
from ._sequences import frame_history

__all__ = ["ridge_autoregression", "solve_positive"]


def ridge_autoregression(X, frames, order, alpha):
    """Fit ``x_t = intercept + sum_q A_q x_{t-q}`` by ridge regression.

    Parameters
    ----------
    X : ndarray of shape (n_frames, n_features)
        Sequences stacked, each contiguous and in time order; any array API
        namespace's array (the results are in it).
    frames : ndarray of int
        The frames regressed on their past; each must have ``order`` past
        frames in its own sequence.
    order : int
        Number of past frames; ``0`` fits the mean frame.
    alpha : float
        Ridge penalty on the weights (not the intercept), in the units of
        the summed squared error over ``frames``.

    Returns
    -------
    result : :class:`~sklearn.utils.Bunch`
        coef : ndarray of shape (order, n_features, n_features)
            ``coef[q - 1] @ x[t - q]`` adds to the prediction of frame ``t``.
        intercept : ndarray of shape (n_features,)
        residual : ndarray of shape (len(frames), n_features)
            ``x_t`` minus its prediction, for every frame of ``frames``.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._autoregression import ridge_autoregression
    >>> X = np.arange(10.0)[:, None]          # x_t = x_{t-1} + 1
    >>> fit = ridge_autoregression(X, np.arange(1, 10), order=1, alpha=0.0)
    >>> print(fit.coef.ravel(), fit.intercept, abs(fit.residual).max() < 1e-12)
    [1.] [1.] True
    """
    n_features = X.shape[1]
    ops = array_ops(X)
    target = ops.take(X, frames, axis=0)
    history = frame_history(X, frames, order)
    history_mean = ops.mean(history, axis=0)
    centred = history - history_mean
    gram = centred.T @ centred
    gram += alpha * ops.eye(gram.shape[0], dtype=gram.dtype)
    target_mean = ops.mean(target, axis=0)
    weights = (
        solve_positive(gram, centred.T @ (target - target_mean))
        if order
        else ops.zeros((0, n_features), dtype=X.dtype)
    )
    intercept = target_mean - history_mean @ weights
    coef = ops.reshape(weights.T, (n_features, order, n_features))
    # numpy < 2 has no permute_dims
    coef = coef.transpose(1, 0, 2) if ops is np else ops.permute_dims(coef, (1, 0, 2))
    return Bunch(
        coef=ops.ascontiguousarray(coef),
        intercept=intercept,
        residual=target - history @ weights - intercept,
    )


def solve_positive(a, b):
    """``a^{-1} b`` for a symmetric positive definite ``a``, in its namespace.

    scipy's Cholesky-based solver on numpy; the namespace's
    ``linalg.solve`` elsewhere.
    """
    if isinstance(a, np.ndarray):
        return linalg.solve(a, b, assume_a="pos")
    return array_ops(a).xp.linalg.solve(a, b)
