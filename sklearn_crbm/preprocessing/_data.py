"""Standardisation that drops constant channels and restores them."""

from numbers import Real

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval
from sklearn.utils.extmath import _incremental_mean_and_var
from sklearn.utils.validation import (
    FLOAT_DTYPES,
    _check_feature_names_in,
    check_array,
    check_is_fitted,
    validate_data,
)

from ..utils._persistence import VersionedPickleMixin

__all__ = ["StandardScaler"]


class StandardScaler(VersionedPickleMixin, TransformerMixin, BaseEstimator):
    """Standardise features and drop the constant ones.

    Like :class:`sklearn.preprocessing.StandardScaler` (``z = (x - u) / s``
    with the training mean ``u`` and the population standard deviation
    ``s``, ddof=0), but features whose standard deviation is at most
    ``constant_tol * max(1, |mean|)`` are *dropped* from the output and
    restored at their mean by :meth:`inverse_transform`.  This is the last
    step of the paper's preprocessing (§3, Taylor's ``preprocess2``): the
    unused exponential-map axes of one-degree-of-freedom joints, bone
    offsets and channels that never move carry no information.

    A kept feature that barely moves is not blown up to unit variance: its
    scale is at least ``scale_floor`` times the median standard deviation
    of the kept features (the typical channel's).  Without that floor a toe
    that stood still in the training takes gets a tiny scale, and the same
    toe in a held-out take of the same motion lands hundreds of standard
    deviations away, where no model trained on the z-scores can follow
    (seeds of generation, fill-in); with it, such a feature's z-scores stay
    small and its training variance below one.

    Parameters
    ----------
    copy : bool, default=True
        If False, try to avoid a copy of ``X`` in :meth:`inverse_transform`
        where possible (the output of :meth:`transform` is always new,
        since it has fewer columns).
    with_mean : bool, default=True
        Centre the kept features.
    with_std : bool, default=True
        Scale the kept features to unit variance.
    constant_tol : float >= 0 or None, default=1e-10
        A feature is constant when its standard deviation is at most
        ``constant_tol * max(1, |mean|)``: a relative tolerance, so that
        rounding noise (about 1e-16 times the magnitude) counts as constant.
        None keeps every feature, as scikit-learn's scaler does.
    scale_floor : float in [0, 1), default=0.01
        Lower bound of every kept feature's scale, as a fraction of the
        median standard deviation of the kept features; ``0`` scales every
        feature to unit variance, as scikit-learn's scaler does.

    Attributes
    ----------
    mean_ : ndarray of shape (`n_features_in_`,)
        Mean of every input feature, always computed: the constant features
        are restored at it.
    var_ : ndarray of shape (`n_features_in_`,)
        Variance (ddof=0) of every input feature, always computed: it
        decides which features are constant.
    scale_ : ndarray of shape (`n_features_in_`,) or None
        ``sqrt(var_)``, raised to the floor (``scale_floor`` times the median
        of the kept features' ``sqrt(var_)``), with 1 for constant features;
        None when ``with_std=False``.
    constant_mask_ : ndarray of bool of shape (`n_features_in_`,)
        True for the dropped (constant) features.
    n_samples_seen_ : int or ndarray of shape (`n_features_in_`,)
        Number of samples seen, per feature when some were NaN (NaN is
        ignored in fit and kept in transform, as in scikit-learn).
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    sklearn.preprocessing.StandardScaler : The same without dropping.
    make_motion_preprocessor : The paper's whole preprocessing as a Pipeline.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.preprocessing import StandardScaler
    >>> X = np.array([[0.0, 5.0, 1.0], [2.0, 5.0, 3.0], [4.0, 5.0, 5.0]])
    >>> scaler = StandardScaler().fit(X)
    >>> scaler.constant_mask_
    array([False,  True, False])
    >>> Z = scaler.transform(X)
    >>> Z.round(4)
    array([[-1.2247, -1.2247],
           [ 0.    ,  0.    ],
           [ 1.2247,  1.2247]])
    >>> scaler.inverse_transform(Z)
    array([[0., 5., 1.],
           [2., 5., 3.],
           [4., 5., 5.]])
    >>> scaler.get_feature_names_out()
    array(['x0', 'x2'], dtype=object)
    """

    _parameter_constraints: dict = {
        "copy": ["boolean"],
        "with_mean": ["boolean"],
        "with_std": ["boolean"],
        "constant_tol": [Interval(Real, 0, None, closed="left"), None],
        "scale_floor": [Interval(Real, 0, 1, closed="left")],
    }

    def __init__(
        self,
        *,
        copy=True,
        with_mean=True,
        with_std=True,
        constant_tol=1e-10,
        scale_floor=0.01,
    ):
        self.copy = copy
        self.with_mean = with_mean
        self.with_std = with_std
        self.constant_tol = constant_tol
        self.scale_floor = scale_floor

    def _reset(self):
        for attr in ("mean_", "var_", "scale_", "constant_mask_", "n_samples_seen_"):
            if hasattr(self, attr):
                delattr(self, attr)

    def fit(self, X, y=None):
        """Compute mean and variance, and find the constant features.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
            Training data.
        y : None
            Ignored.

        Returns
        -------
        self : StandardScaler
            The fitted scaler.
        """
        self._reset()
        return self.partial_fit(X, y)

    @_fit_context(prefer_skip_nested_validation=True)
    def partial_fit(self, X, y=None):
        """Update mean and variance with a batch of samples.

        The constant features are decided again from the running variance
        after every batch.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
            A batch of training data.
        y : None
            Ignored.

        Returns
        -------
        self : StandardScaler
            The updated scaler.
        """
        first_call = not hasattr(self, "n_samples_seen_")
        X = validate_data(
            self,
            X,
            dtype=FLOAT_DTYPES,
            ensure_all_finite="allow-nan",
            reset=first_call,
        )
        n_features = X.shape[1]
        if first_call:
            self.n_samples_seen_ = np.zeros(n_features, dtype=np.int64)
            self.mean_ = np.zeros(n_features, dtype=np.float64)
            self.var_ = np.zeros(n_features, dtype=np.float64)
        elif np.ndim(self.n_samples_seen_) == 0:
            self.n_samples_seen_ = np.repeat(self.n_samples_seen_, n_features)
        self.mean_, self.var_, self.n_samples_seen_ = _incremental_mean_and_var(
            X, self.mean_, self.var_, self.n_samples_seen_
        )
        self.n_samples_seen_ = self.n_samples_seen_.astype(np.int64, copy=False)
        if np.ptp(self.n_samples_seen_) == 0:
            self.n_samples_seen_ = int(self.n_samples_seen_[0])

        std = np.sqrt(self.var_)
        if self.constant_tol is None:
            self.constant_mask_ = np.zeros(n_features, dtype=bool)
        else:
            bound = self.constant_tol * np.maximum(1.0, np.abs(self.mean_))
            self.constant_mask_ = ~(std > bound)  # NaN statistics count as constant
        self.scale_ = self._scale(std) if self.with_std else None
        return self

    def _scale(self, std):
        """Every feature's scale: its standard deviation, at least the floor."""
        kept = ~self.constant_mask_ & (std > 0)
        scale = std.copy()
        if self.scale_floor and kept.any():
            floor = self.scale_floor * np.median(std[kept])
            scale[kept] = np.maximum(scale[kept], floor)
        scale[~kept] = 1.0
        return scale

    def transform(self, X, copy=None):
        """Standardise the kept features.

        Parameters
        ----------
        X : array-like of shape (n_samples, `n_features_in_`)
            Data to scale.  NaN stays NaN.
        copy : bool or None, default=None
            Ignored apart from validation (the output is always a new
            array); present for compatibility with scikit-learn's scaler.

        Returns
        -------
        X_out : ndarray of shape (n_samples, n_kept_features)
            The standardised non-constant features.
        """
        check_is_fitted(self)
        X = validate_data(
            self, X, reset=False, dtype=FLOAT_DTYPES, ensure_all_finite="allow-nan"
        )
        keep = ~self.constant_mask_
        out = X[:, keep]
        if self.with_mean:
            out -= self.mean_[keep].astype(out.dtype, copy=False)
        if self.with_std:
            out /= self.scale_[keep].astype(out.dtype, copy=False)
        return out

    def inverse_transform(self, X, copy=None):
        """Undo the scaling and put the constant features back.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_kept_features)
            Standardised data, as returned by :meth:`transform`.
        copy : bool or None, default=None
            Copy ``X`` before scaling back; None uses ``self.copy``.

        Returns
        -------
        X_original : ndarray of shape (n_samples, `n_features_in_`)
            Data in the original units, the constant features at their mean.
        """
        check_is_fitted(self)
        copy = self.copy if copy is None else copy
        # every feature may be constant (a one-frame file): then X has 0 columns
        X = check_array(
            X,
            dtype=FLOAT_DTYPES,
            copy=copy,
            ensure_all_finite="allow-nan",
            ensure_min_features=0,
        )
        keep = ~self.constant_mask_
        if X.shape[1] != keep.sum():
            raise ValueError(
                f"X has {X.shape[1]} features, but StandardScaler.inverse_transform "
                f"expects {keep.sum()} features (the non-constant ones)."
            )
        if self.with_std:
            X *= self.scale_[keep].astype(X.dtype, copy=False)
        if self.with_mean:
            X += self.mean_[keep].astype(X.dtype, copy=False)
        out = np.empty((X.shape[0], len(keep)), dtype=X.dtype)
        out[:, keep] = X
        out[:, ~keep] = self.mean_[~keep]
        return out

    def get_feature_names_out(self, input_features=None):
        """Names of the kept (non-constant) features.

        Parameters
        ----------
        input_features : array-like of str or None, default=None
            Input feature names; must match ``feature_names_in_`` if that is
            defined.  None uses ``feature_names_in_``, else ``x0, x1, ...``.

        Returns
        -------
        feature_names_out : ndarray of str objects
            The input names of the non-constant features.
        """
        check_is_fitted(self)
        names = _check_feature_names_in(self, input_features)
        return np.asarray(names, dtype=object)[~self.constant_mask_]

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        tags.transformer_tags.preserves_dtype = ["float64", "float32"]
        return tags
