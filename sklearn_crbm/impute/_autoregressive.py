"""The strong simple baseline: a linear-Gaussian autoregressive model, on-line."""

from numbers import Integral, Real

import numpy as np
from scipy import linalg
from sklearn.base import (
    BaseEstimator,
    OneToOneFeatureMixin,
    TransformerMixin,
    _fit_context,
)
from sklearn.utils._missing import is_scalar_nan
from sklearn.utils._param_validation import Interval, MissingValues, StrOptions
from sklearn.utils.validation import check_is_fitted

from ..utils._autoregression import ridge_autoregression
from ..utils._fitting import unfitted_on_error
from ..utils._persistence import VersionedPickleMixin
from ..utils._sequences import check_sequence_ids, frame_history
from ._base import check_imputer_input, complete_runs

# Added to the diagonal of every covariance: keeps it invertible when a
# channel is (nearly) a linear function of the others or of the past.
_REG_COVAR = 1e-6


class AutoregressiveImputer(
    VersionedPickleMixin, OneToOneFeatureMixin, TransformerMixin, BaseEstimator
):
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
        "order": [Interval(Integral, 0, None, closed="left")],
        "alpha": [Interval(Real, 0, None, closed="left")],
        "covariance_type": [StrOptions({"full", "diag"})],
        "missing_values": [MissingValues()],
    }

    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}

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
            X, mask = check_imputer_input(self, X, reset=True)
            rows, run_ids = complete_runs(mask, sequence_ids)
            X = X[rows]
            sequences = check_sequence_ids(run_ids, len(X))
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
            self.mean_ = X.mean(axis=0)
            self.frame_covariance_ = self._regularised(
                np.cov(X, rowvar=False, bias=True)
            )
            fit = ridge_autoregression(X, frames, self.order, self.alpha)
            self.intercept_ = fit.intercept
            self.covariance_ = self._regularised(
                fit.residual.T @ fit.residual / len(frames)
            )
            self.coef_ = fit.coef
        return self

    def _regularised(self, covariance):
        covariance = np.atleast_2d(covariance)
        if self.covariance_type == "diag":
            covariance = np.diag(np.diag(covariance))
        covariance[np.diag_indices_from(covariance)] += _REG_COVAR
        return covariance

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
        check_is_fitted(self)
        X, mask = check_imputer_input(self, X, reset=False)
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        frame_starts = sequences.frame_starts()
        gains = {}
        for step in range(int(sequences.lengths.max(initial=0))):
            rows = sequences.starts[sequences.lengths > step] + step
            rows = rows[mask[rows].any(axis=1)]
            if not len(rows):
                continue
            marginal = step == 0 or self.order == 0
            if marginal:
                mean = np.broadcast_to(self.mean_, (len(rows), X.shape[1]))
                covariance = self.frame_covariance_
            else:
                history = frame_history(X, rows, self.order, frame_starts[rows])
                mean = history @ self.coef_.transpose(0, 2, 1).reshape(-1, X.shape[1])
                mean += self.intercept_
                covariance = self.covariance_
            self._fill_conditional(X, mask, rows, mean, covariance, gains, marginal)
        return X

    @staticmethod
    def _fill_conditional(X, mask, rows, mean, covariance, gains, marginal):
        """Each row's ``x_m = mu_m + S_mo S_oo^{-1} (x_o - mu_o)``, by mask pattern."""
        patterns, which = np.unique(mask[rows], axis=0, return_inverse=True)
        for k, missing in enumerate(patterns):
            chosen = which.ravel() == k
            sub = rows[chosen]
            observed = ~missing
            key = (marginal, missing.tobytes())
            if key not in gains:
                gains[key] = (
                    linalg.solve(
                        covariance[np.ix_(observed, observed)],
                        covariance[np.ix_(observed, missing)],
                        assume_a="pos",
                    ).T
                    if observed.any()
                    else np.zeros((missing.sum(), 0))
                )
            residual = X[np.ix_(sub, observed)] - mean[chosen][:, observed]
            X[np.ix_(sub, missing)] = mean[chosen][:, missing] + residual @ gains[key].T

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = is_scalar_nan(self.missing_values)
        return tags
