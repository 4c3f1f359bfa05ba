"""Scoring imputers by masking channels of held-out sequences."""

from inspect import signature

import numpy as np
from sklearn import get_config
from sklearn.metrics import mean_squared_error
from sklearn.utils.metadata_routing import (
    UNCHANGED,
    MetadataRequest,
    get_routing_for_object,
)
from sklearn.utils.validation import check_array

from ..utils._sequences import check_sequence_ids
from ._fillin import check_erasure, erasure_mask

__all__ = ["make_imputation_scorer", "make_prediction_scorer"]


def make_imputation_scorer(
    score_func=mean_squared_error,
    *,
    columns=None,
    bones=None,
    start=0.5,
    stop=None,
    feature_names=None,
    missing_values=np.nan,
    greater_is_better=False,
    **kwargs,
):
    """Make a scorer that erases channels of held-out sequences and scores the fill.

    The scorer is called as ``scorer(estimator, X, sequence_ids=...)`` on
    complete frames, as :class:`~sklearn.model_selection.GridSearchCV` and
    :func:`~sklearn.model_selection.cross_validate` call a scorer on a test
    fold.  It erases the chosen channels (``columns`` and ``bones``) in the
    chosen part (``start`` to ``stop``) of every sequence, writing
    ``missing_values`` there, asks the fitted imputer to fill them with
    ``estimator.transform``, and compares the fill with the erased truth::

        score_func(X[mask], X_filled[mask], **kwargs)

    or, when ``score_func`` takes a ``missing_mask`` keyword (as
    :func:`sklearn_crbm.metrics.fillin_error` does),
    ``score_func(X, X_filled, missing_mask=mask, **kwargs)``.  The result is
    negated when ``greater_is_better=False`` (the default: the default
    ``score_func`` is an error), so that higher is always better, as
    :func:`sklearn.metrics.make_scorer` does.

    Any fitted transformer that fills ``missing_values`` works:
    :class:`~sklearn_crbm.impute.CRBMImputer`,
    :class:`~sklearn_crbm.impute.NearestNeighborImputer`,
    :class:`sklearn.impute.SimpleImputer`, or a Pipeline ending in one whose
    output has the columns of its input.

    Parameters
    ----------
    score_func : callable, default=sklearn.metrics.mean_squared_error
        ``score_func(y_true, y_pred, **kwargs)`` on the erased entries
        (1-D arrays), or ``score_func(y_true, y_pred, missing_mask=mask,
        **kwargs)`` on whole frames when it has a ``missing_mask``
        parameter.
    columns : array-like of int, bool or str, default=None
        Channels to erase: indices, a boolean mask over the features, or
        feature names.
    bones : str or array-like of str, default=None
        Bones whose channels to erase: every feature named
        ``"{bone}_{channel}"``, such as ``lfemur_ex`` for ``"lfemur"``
        (the naming of :mod:`sklearn_crbm.preprocessing` and of raw
        channels).  Added to ``columns``; give at least one of the two.
    start : float or int, default=0.5
        Where the erased part of every sequence begins: a float in
        ``[0, 1]`` is a position relative to the sequence's length (frame
        ``i`` of ``n`` is erased when ``start <= i / n``, so the default
        erases the last ``n // 2`` frames, as the paper does), an int a
        frame index counted from the sequence's first frame.  See
        :func:`erasure_mask`, which builds the mask.
    stop : float or int, default=None
        Where it ends (excluded), in the units of ``start``; ``None`` erases
        to the end of every sequence.
    feature_names : array-like of str, default=None
        Names of the features of ``X``, to resolve ``bones`` and names in
        ``columns``.  ``None`` takes the estimator's ``feature_names_in_``.
    missing_values : float or int, default=np.nan
        The marker written into the erased entries; the imputer must have
        the same ``missing_values``.
    greater_is_better : bool, default=False
        Whether ``score_func`` is a score (True) or an error (False).
    **kwargs : dict
        Passed on to ``score_func``.

    Returns
    -------
    scorer : callable
        ``scorer(estimator, X, y=None, *, sequence_ids=None)`` returns a
        float, higher is better.  It requests ``sequence_ids`` for
        ``score`` through metadata routing (change it with
        ``scorer.set_score_request``), and passes them on to
        ``estimator.transform`` when the estimator requests them (with
        routing enabled) or takes them as a parameter (without).
        ``scorer.missing_mask(X, sequence_ids=None)`` gives the erased
        entries.

    See Also
    --------
    sklearn.metrics.make_scorer : Scorers from prediction metrics.
    sklearn_crbm.metrics.fillin_error : The paper's fill-in error.

    Notes
    -----
    With metadata routing enabled
    (``sklearn.set_config(enable_metadata_routing=True)``), a search routes
    ``sequence_ids`` to the scorer, which then erases the same part of every
    held-out sequence and lets a sequence-aware imputer see where sequences
    begin.  Without routing the scorer gets no ids, and every test fold is
    treated as a single sequence.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn.impute import SimpleImputer
    >>> from sklearn_crbm.model_selection import make_imputation_scorer
    >>> X = np.arange(24, dtype=float).reshape(8, 3)
    >>> ids = np.repeat([0, 1], 4)
    >>> scorer = make_imputation_scorer(columns=[2], start=0.5)
    >>> scorer.missing_mask(X, sequence_ids=ids)[:, 2]
    array([False, False,  True,  True, False, False,  True,  True])
    >>> imputer = SimpleImputer().fit(X)
    >>> scorer(imputer, X, sequence_ids=ids)  # minus the MSE of the mean fill
    -47.25
    """
    return _ImputationScorer(
        score_func,
        columns=columns,
        bones=bones,
        start=start,
        stop=stop,
        feature_names=feature_names,
        missing_values=missing_values,
        sign=1 if greater_is_better else -1,
        kwargs=kwargs,
    )


class _SequenceScorer:
    """A scorer that requests ``sequence_ids`` through metadata routing."""

    def __init__(self):
        self._score_request = {"sequence_ids": True}

    def get_metadata_routing(self):
        """The metadata the scorer requests: ``sequence_ids`` for ``score``.

        Returns
        -------
        request : sklearn.utils.metadata_routing.MetadataRequest
            What a search routes to the scorer.
        """
        request = MetadataRequest(owner=self)
        for param, alias in self._score_request.items():
            request.score.add_request(param=param, alias=alias)
        return request

    def set_score_request(self, *, sequence_ids=UNCHANGED):
        """Choose whether a search routes ``sequence_ids`` to the scorer.

        Only available with ``sklearn.set_config(enable_metadata_routing=True)``.

        Parameters
        ----------
        sequence_ids : bool, str or None, default=UNCHANGED
            True (the default request): route ``sequence_ids``; False or
            None: do not; a string: route the metadata of that name as
            ``sequence_ids``; ``UNCHANGED``
            (:data:`sklearn.utils.metadata_routing.UNCHANGED`) keeps the
            current request.

        Returns
        -------
        self : object
            The scorer.
        """
        if not _routing_enabled():
            raise RuntimeError(
                "set_score_request is only available when metadata routing is "
                "enabled: sklearn.set_config(enable_metadata_routing=True)."
            )
        if sequence_ids is not UNCHANGED:
            self._score_request["sequence_ids"] = sequence_ids
        return self


class _ImputationScorer(_SequenceScorer):
    """Erase a pattern of channels, fill them with the estimator, score the fill."""

    def __init__(
        self,
        score_func,
        *,
        columns,
        bones,
        start,
        stop,
        feature_names,
        missing_values,
        sign,
        kwargs,
    ):
        if not callable(score_func):
            raise TypeError(f"score_func must be callable, got {score_func!r}.")
        check_erasure(columns, bones, start, stop)
        if bones is not None:
            bones = [bones] if isinstance(bones, str) else [str(b) for b in bones]
        self._score_func = score_func
        self._columns = None if columns is None else np.asarray(columns)
        self._bones = bones
        self._start = start
        self._stop = stop
        self._feature_names = (
            None if feature_names is None else np.asarray(feature_names, dtype=object)
        )
        self._missing_values = missing_values
        self._sign = sign
        self._kwargs = kwargs
        super().__init__()

    def __repr__(self):
        parts = [getattr(self._score_func, "__name__", repr(self._score_func))]
        if self._sign < 0:
            parts.append("greater_is_better=False")
        if self._columns is not None:
            parts.append(f"columns={self._columns.tolist()!r}")
        if self._bones is not None:
            parts.append(f"bones={self._bones!r}")
        parts.append(f"start={self._start!r}")
        if self._stop is not None:
            parts.append(f"stop={self._stop!r}")
        parts += [f"{key}={value!r}" for key, value in self._kwargs.items()]
        return f"make_imputation_scorer({', '.join(parts)})"

    def __call__(self, estimator, X, y=None, *, sequence_ids=None):
        """Erase the pattern in ``X``, fill it with ``estimator``, score the fill.

        Parameters
        ----------
        estimator : object
            A fitted imputer: ``estimator.transform`` fills the entries that
            hold ``missing_values``.
        X : array-like of shape (n_frames, n_features)
            Complete held-out frames, stacked sequences in time order.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        score : float
            Higher is better.
        """
        X = check_array(X, dtype=np.float64, copy=False)
        mask = self._mask(X, sequence_ids, estimator)
        X_missing = X.copy()
        X_missing[mask] = self._missing_values
        params = _transform_params(estimator, sequence_ids)
        X_filled = np.asarray(estimator.transform(X_missing, **params))
        if X_filled.shape != X.shape:
            raise ValueError(
                f"{type(estimator).__name__}.transform returned shape "
                f"{X_filled.shape} for input of shape {X.shape}: an imputation "
                "scorer needs the filled frames in the columns of the input."
            )
        if "missing_mask" in signature(self._score_func).parameters:
            score = self._score_func(X, X_filled, missing_mask=mask, **self._kwargs)
        else:
            score = self._score_func(X[mask], X_filled[mask], **self._kwargs)
        return self._sign * float(score)

    def missing_mask(self, X, *, sequence_ids=None, estimator=None):
        """The entries of ``X`` the scorer erases.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Stacked sequences.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        estimator : object, default=None
            A fitted estimator whose ``feature_names_in_`` resolve names,
            when the scorer was given no ``feature_names``.

        Returns
        -------
        mask : ndarray of bool of shape (n_frames, n_features)
            True where the scorer writes ``missing_values``.
        """
        X = check_array(X, dtype=None, ensure_all_finite=False)
        return self._mask(X, sequence_ids, estimator)

    def _mask(self, X, sequence_ids, estimator):
        names = None
        if self._bones is not None or (
            self._columns is not None and self._columns.dtype.kind in "OUS"
        ):
            names = self._names(X.shape[1], estimator)
        return erasure_mask(
            X,
            columns=self._columns,
            bones=self._bones,
            feature_names=names,
            sequence_ids=sequence_ids,
            start=self._start,
            stop=self._stop,
        )

    def _names(self, n_features, estimator):
        names = self._feature_names
        if names is None:
            names = getattr(estimator, "feature_names_in_", None)
        if names is None:
            raise ValueError(
                "Selecting channels by name needs feature names: pass "
                "feature_names= to make_imputation_scorer (e.g. "
                "preprocessor.get_feature_names_out()) or fit the estimator on "
                "a DataFrame."
            )
        names = np.asarray(names, dtype=object)
        if len(names) != n_features:
            raise ValueError(
                f"{len(names)} feature names were given for X with {n_features} "
                "features."
            )
        return names


def make_prediction_scorer(score_func=mean_squared_error, *, greater_is_better=False):
    """Make a scorer of the one-step-ahead prediction of held-out frames.

    The scorer compares every frame that has a complete history in its own
    sequence with the model's deterministic prediction of it from that
    history alone (``predict_next``)::

        score_func(X[frames], X_pred[frames])

    negated when ``greater_is_better=False`` (the default), so higher is
    better.  It is what :meth:`ConditionalRBM.score
    <sklearn_crbm.ConditionalRBM.score>` returned before it became the
    held-out log-likelihood: pass it as ``scoring=`` to choose a model by
    how well it predicts the next frame.  It works on a
    :class:`~sklearn_crbm.ConditionalRBM`, a
    :class:`~sklearn_crbm.StackedCRBM`, or a Pipeline ending in one (the
    error is then measured in the space of the model's input, e.g. z-scores).

    Parameters
    ----------
    score_func : callable, default=sklearn.metrics.mean_squared_error
        ``score_func(y_true, y_pred)`` on 2-D arrays of frames.
    greater_is_better : bool, default=False
        Whether ``score_func`` is a score (True) or an error (False).

    Returns
    -------
    scorer : callable
        ``scorer(estimator, X, y=None, *, sequence_ids=None)`` returns a
        float, higher is better; it requests ``sequence_ids`` through
        metadata routing.

    See Also
    --------
    make_imputation_scorer : Score how an imputer fills erased channels.

    Examples
    --------
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> from sklearn_crbm.model_selection import make_prediction_scorer
    >>> X, ids = make_oscillations(n_sequences=4, n_frames=40, random_state=0)
    >>> model = ConditionalRBM(8, order=2, n_iter=20, random_state=0)
    >>> model = model.fit(X, sequence_ids=ids)
    >>> scorer = make_prediction_scorer()
    >>> bool(scorer(model, X, sequence_ids=ids) < 0)
    True
    """
    return _PredictionScorer(score_func, sign=1 if greater_is_better else -1)


class _PredictionScorer(_SequenceScorer):
    """Score ``predict_next`` on the frames that have a full history."""

    def __init__(self, score_func, *, sign):
        if not callable(score_func):
            raise TypeError(f"score_func must be callable, got {score_func!r}.")
        self._score_func = score_func
        self._sign = sign
        super().__init__()

    def __repr__(self):
        name = getattr(self._score_func, "__name__", repr(self._score_func))
        flag = ", greater_is_better=False" if self._sign < 0 else ""
        return f"make_prediction_scorer({name}{flag})"

    def __call__(self, estimator, X, y=None, *, sequence_ids=None):
        """Predict every frame from its history and score the prediction.

        Parameters
        ----------
        estimator : object
            A fitted ConditionalRBM, StackedCRBM or Pipeline ending in one.
        X : array-like of shape (n_frames, n_features)
            Held-out frames, stacked sequences in time order.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        score : float
            Higher is better.
        """
        model = estimator
        if hasattr(estimator, "steps"):
            model = estimator[-1]
            for _, step in estimator.steps[:-1]:
                if step is not None and step != "passthrough":
                    X = step.transform(X, **_transform_params(step, sequence_ids))
        if not hasattr(model, "predict_next"):
            raise TypeError(
                f"{type(model).__name__} has no predict_next: the prediction "
                "scorer needs a ConditionalRBM or StackedCRBM (or a Pipeline "
                "ending in one)."
            )
        X = check_array(X, dtype=np.float64)
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        frames = sequences.frames_with_past(
            model.history_length, "The prediction scorer"
        )
        predicted = model.predict_next(X, sequence_ids=sequence_ids)
        score = self._score_func(X[frames], np.asarray(predicted)[frames])
        return self._sign * float(score)


def _routing_enabled():
    return get_config().get("enable_metadata_routing", False)


def _transform_params(estimator, sequence_ids):
    """``{"sequence_ids": ...}`` if ``estimator.transform`` wants them, else ``{}``."""
    if sequence_ids is None:
        return {}
    if _routing_enabled():
        wanted = get_routing_for_object(estimator).consumes(
            method="transform", params=["sequence_ids"]
        )
    else:
        wanted = "sequence_ids" in signature(estimator.transform).parameters
    return {"sequence_ids": sequence_ids} if wanted else {}
