"""The strong simple baseline: a linear-Gaussian autoregressive model, on-line."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context
from sklearn.utils._param_validation import Interval, StrOptions

from ..utils._array_api import array_ops
from ..utils._autoregression import ridge_autoregression, solve_positive
from ..utils._fitting import unfitted_on_error
from ..utils._sequences import check_sequence_ids
from ._base import BaseMotionImputer, to_numpy

# Added to the diagonal of every covariance: keeps it invertible when a
# channel is (nearly) a linear function of the others or of the past.
_REG_COVAR = 1e-6


class AutoregressiveImputer(BaseMotionImputer):
    """Fill missing channels on-line with a linear-Gaussian autoregressive model.

    The model is ``x_t = intercept + sum_q A_q x_{t-q} + e_t`` with ``e_t ~
    N(0, covariance_)``: ridge regression of each frame on its ``order``
    past frames, and the covariance of its residuals.  ``transform`` fills
    the frames of each sequence in time order, as :class:`CRBMImputer` does:
    frame ``t``'s missing channels get their conditional mean given the
    already filled frames before it and frame ``t``'s observed channels,

    ``x_m = mu_m + S_mo S_oo^{-1} (x_o - mu_o)``,  ``mu = intercept + sum_q
    A_q x_{t-q}``,

    where ``S`` is the residual covariance.  It is the exact on-line
    posterior mean of a linear-Gaussian model (a Kalman filter with the
    frames as state), a fast and strong baseline for the conditional RBM.

    Parameters
    ----------
    order : int, default=3
        Number of past frames the prediction uses; ``0`` models frames as
        independent draws from one Gaussian.
    alpha : float, default=1.0
        Ridge penalty on the autoregressive weights (not the intercept), in
        the units of the summed squared error over the training frames.
    covariance_type : {"full", "diag"}, default="full"
        ``"full"``: the residual covariance captures how channels err
        together, so observed channels inform missing ones beyond the
        prediction from the past.  ``"diag"``: one variance per channel, so
        missing channels get the prediction from the past alone.
    missing_values : int, float, str, np.nan or None, default=np.nan
        The placeholder for missing values; all its occurrences are filled.

    Attributes
    ----------
    coef_ : ndarray of shape (order, n_features, n_features)
        ``coef_[q - 1] @ x[t - q]`` adds to the prediction of frame ``t``.
    intercept_ : ndarray of shape (n_features,)
    covariance_ : ndarray of shape (n_features, n_features)
        Residual covariance (diagonal for ``covariance_type="diag"``), with
        ``1e-6`` added to the diagonal.
    mean_ : ndarray of shape (n_features,)
        Mean training frame.
    frame_covariance_ : ndarray of shape (n_features, n_features)
        Covariance of the training frames (diagonal for ``"diag"``): the
        model of the first frame of a sequence, which has no past.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    CRBMImputer : Fills in on-line with a conditional RBM.
    NearestNeighborImputer : The paper's baseline.

    Notes
    -----
    The first frame of a sequence is filled from the Gaussian of all
    training frames (``mean_``, ``frame_covariance_``); frames ``1`` to
    ``order - 1`` use the frames they have, the first frame repeated for the
    rest (edge padding, as :class:`CRBMImputer`).  Frames that miss the same
    channels share one gain ``S_mo S_oo^{-1}``, computed once per call.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> from sklearn_crbm.impute import AutoregressiveImputer
    >>> X, ids = make_oscillations(n_sequences=6, n_frames=60, random_state=0)
    >>> imputer = AutoregressiveImputer(order=2)
    >>> imputer.fit(X[ids < 5], sequence_ids=ids[ids < 5])
    AutoregressiveImputer(order=2)
    >>> X_test = X[ids == 5].copy()
    >>> X_test[30:, :2] = np.nan           # two channels lost half-way through
    >>> X_filled = imputer.transform(X_test)
    >>> bool(np.isnan(X_filled).any())
    False
    >>> bool(np.array_equal(X_filled[:, 2:], X_test[:, 2:]))
    True
    """

    _parameter_constraints: dict = {
        **BaseMotionImputer._parameter_constraints,
        "order": [Interval(Integral, 0, None, closed="left")],
        "alpha": [Interval(Real, 0, None, closed="left")],
        "covariance_type": [StrOptions({"full", "diag"})],
    }

    _fitted_attribute = "coef_"

    def __init__(
        self, *, order=3, alpha=1.0, covariance_type="full", missing_values=np.nan
    ):
        self.order = order
        self.alpha = alpha
        self.covariance_type = covariance_type
        self.missing_values = missing_values

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Fit the autoregressive weights and the residual covariance.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Training sequences, stacked, each contiguous and in time order.
            A frame with a missing value is left out and splits its
            sequence in two.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        self : AutoregressiveImputer
            The fitted imputer.
        """
        with unfitted_on_error(self):
            X, run_ids, _ = self._complete_frames(X, sequence_ids)
            ops = array_ops(X)
            sequences = check_sequence_ids(run_ids, X.shape[0])
            frames = sequences.valid_frames(self.order)
            if len(frames) < 2:
                longest = int(sequences.lengths.max())
                noun = "sample" if longest == 1 else "samples"
                raise ValueError(
                    f"AutoregressiveImputer(order={self.order}) needs at least two "
                    f"complete frames with {self.order} complete past frames in "
                    f"their own sequence, but the longest complete sequence has "
                    f"{longest} {noun}. Pass longer sequences or lower order."
                )
            self.mean_ = ops.mean(X, axis=0)
            centred = X - self.mean_
            self.frame_covariance_ = self._regularised(centred.T @ centred / X.shape[0])
            fit = ridge_autoregression(X, frames, self.order, self.alpha)
            self.intercept_ = fit.intercept
            self.covariance_ = self._regularised(
                fit.residual.T @ fit.residual / len(frames)
            )
            self.coef_ = fit.coef
        return self

    def _regularised(self, covariance):
        ops = array_ops(covariance)
        eye = ops.eye(covariance.shape[0], dtype=covariance.dtype)
        if self.covariance_type == "diag":
            covariance = covariance * eye
        return covariance + _REG_COVAR * eye

    def transform(self, X, *, sequence_ids=None):
        """Fill every missing value of ``X`` on-line with its conditional mean.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Sequences with missing values, stacked, each contiguous and in
            time order.  Observed values come back unchanged.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        X_filled : ndarray of shape (n_frames, n_features)
            ``X`` with no missing value left.
        """
        X, mask, sequences = self._check_transform_input(X, sequence_ids)
        ops = array_ops(X)
        mask = to_numpy(mask)
        if not mask.any():
            return X
        n_steps, n_features = int(sequences.lengths.max()), X.shape[1]
        # step-major: frame t of every sequence in one slice; a sequence's
        # last frame pads it, never written and never read as a past
        present = np.arange(n_steps)[:, None] < sequences.lengths
        source = sequences.starts + np.minimum(
            np.arange(n_steps)[:, None], sequences.lengths - 1
        )
        steps = ops.reshape(
            ops.take(X, source.ravel(), axis=0), (*source.shape, n_features)
        )
        step_masks = mask[source] & present[..., None]
        # the prediction from the past: history @ weights, lag-major history
        weights = ops.reshape(self._lag_weights(), (-1, n_features))
        gains = {}
        for step in range(n_steps):
            if not step_masks[step].any():
                continue
            marginal = step == 0 or self.order == 0
            if marginal:
                mean = ops.broadcast_to(self.mean_, steps.shape[1:])
                covariance = self.frame_covariance_
            else:
                history = ops.concatenate(
                    [steps[max(step - q, 0), ...] for q in range(1, self.order + 1)],
                    axis=1,
                )
                mean = history @ weights + self.intercept_
                covariance = self.covariance_
            steps[step, ...] = _fill_conditional(
                steps[step, ...], step_masks[step], mean, covariance, gains, marginal
            )
        # back to the rows of X: frame t of sequence s is row t * n_sequences + s
        in_order = np.argsort(sequences.starts)
        sequence = np.repeat(in_order, sequences.lengths[in_order])
        step = np.arange(X.shape[0]) - sequences.starts[sequence]
        position = step * len(sequences.starts) + sequence
        return ops.take(ops.reshape(steps, (-1, n_features)), position, axis=0)

    def _lag_weights(self):
        """``coef_`` as ``(order, n_features, n_features)`` acting on row vectors."""
        if isinstance(self.coef_, np.ndarray):
            return self.coef_.transpose(0, 2, 1)
        return array_ops(self.coef_).permute_dims(self.coef_, (0, 2, 1))


def _fill_conditional(frames, mask, mean, covariance, gains, marginal):
    """Each row's ``x_m = mu_m + S_mo S_oo^{-1} (x_o - mu_o)``, by mask pattern.

    ``frames`` (shape ``(n, n_features)``, missing entries NaN) is filled
    where ``mask`` (numpy bool) is True; a new array is returned.  Each
    pattern's gain is kept in ``gains`` as a full ``(n_features,
    n_features)`` matrix, zero outside the (missing, observed) block, so
    that all rows go through one product and the pattern's own are kept.
    """
    ops = array_ops(frames)
    rows = np.flatnonzero(mask.any(axis=1))
    patterns, which = np.unique(mask[rows], axis=0, return_inverse=True)
    residual = frames - mean
    for k, missing in enumerate(patterns):
        key = (marginal, missing.tobytes())
        if key not in gains:
            gains[key] = _full_gain(covariance, missing)
        observed = ops.asarray(~missing)
        values = ops.where(observed, residual, 0.0) @ gains[key].T + mean
        chosen = np.zeros_like(mask)
        chosen[rows[which.ravel() == k]] = missing
        frames = ops.where(ops.asarray(chosen), values, frames)
    return frames


def _full_gain(covariance, missing):
    """``S_mo S_oo^{-1}`` placed in a ``(n_features, n_features)`` zero matrix."""
    ops = array_ops(covariance)
    n_features = covariance.shape[0]
    observed, missing = np.flatnonzero(~missing), np.flatnonzero(missing)
    if not len(observed):
        return ops.zeros((n_features, n_features), dtype=covariance.dtype)
    block = ops.take(covariance, observed, axis=0)
    gain = solve_positive(
        ops.take(block, observed, axis=1), ops.take(block, missing, axis=1)
    ).T
    # one-hot rows that put the block's rows and columns at these indices
    place_missing, place_observed = (
        ops.asarray(np.eye(n_features)[indices], dtype=covariance.dtype)
        for indices in (missing, observed)
    )
    return place_missing.T @ gain @ place_observed
