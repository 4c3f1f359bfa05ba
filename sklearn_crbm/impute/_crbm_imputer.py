"""On-line filling of missing channels with a conditional RBM (paper §4.4)."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context, clone
from sklearn.frozen import FrozenEstimator
from sklearn.utils import check_random_state, get_tags
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions
from sklearn.utils.validation import _is_fitted, _num_samples, check_is_fitted

from .._engines._online import WHOLE_STACK, Observed, collect_fills, run_online
from ..models._crbm import ConditionalRBM
from ..models._label_factors import as_entries
from ..utils._array_api import array_ops, array_random, copy_array
from ..utils._fitting import unfitted_on_error
from ..utils._parallel import BLOCK_SEQUENCES, map_sequence_blocks
from ..utils._random import rng_from
from ..utils._sequences import Sequences, check_sequence_ids
from ..utils._threads import chain_rows, limit_blas_threads
from ..utils._validation import check_context, check_count
from ._base import BaseMotionImputer, check_same_place
from ._base import to_numpy as _to_numpy


def _default_model(random_state):
    """``ConditionalRBM()`` with a training seed drawn from ``random_state``.

    ``None`` stays ``None``; an int or RandomState gives one int, the way
    scikit-learn's ensembles seed the estimators they build.
    """
    if random_state is None:
        return ConditionalRBM()
    seed = check_random_state(random_state).randint(np.iinfo(np.int32).max)
    return ConditionalRBM(random_state=seed)


class CRBMImputer(BaseMotionImputer):
    """Fill missing channels on-line with a conditional RBM (paper §4.4).

    ``fit`` trains a clone of ``estimator`` on complete sequences.
    ``transform`` fills the frames of each sequence in time order, as they
    would arrive from a motion-capture system: frame ``t`` is filled from the
    filled frames before it and from its own observed channels, never from
    later frames.  The observed channels are clamped, the missing ones start
    at their value in the previous frame, and ``n_gibbs`` alternating Gibbs
    iterations follow, then one mean-field step (the original code's
    generation scheme with the observed channels held fixed).

    Read more in the :ref:`User Guide <filling_in>`.

    Parameters
    ----------
    estimator : estimator of the package, default=None
        The model (:class:`~sklearn_crbm.ConditionalRBM`,
        :class:`~sklearn_crbm.StackedCRBM`, a style model, or any model of
        conditional layers), cloned and trained by :meth:`fit`; a fitted
        model wrapped in :class:`sklearn.frozen.FrozenEstimator` is used as
        it is.  ``None`` means ``ConditionalRBM()`` seeded from
        ``random_state``.  The imputer runs the model's layers
        (``conditional_layers()``) given each frame's context
        (``fill_in_context``).  The visible units have unit variance:
        standardise the data first.
    n_gibbs : int, default=30
        Alternating Gibbs iterations per frame.
    n_draws : int, default=1
        Number of independent fills that :meth:`transform` averages (an
        estimate of the posterior mean).
    n_particles : int, default=20
        Chains per draw: a particle filter that, before every frame,
        resamples the chains by how well each one's past predicts the frame's
        observed channels, and fills the frame with their mean.  ``1`` is the
        paper's single chain.
    offset_shrinkage : float or None, default=30.0
        Correct the fills for the model's systematic error on the sequence at
        hand: a missing entry of channel ``j`` is shifted by ``sum(r) / (n +
        lam)``, ``r`` the channel's one-step residuals over the ``n`` frames
        in which it was observed so far, ``lam`` this value.  ``None``: no
        correction.
    observation_gain : float, default=2.5
        The hidden units see an observed channel at ``x_hat + g * (x -
        x_hat)``, ``x_hat`` the chain's one-step prediction of it and ``g``
        this gain (per channel, see ``observation_weighting``).  ``1`` is the
        model's own conditional; ``0`` ignores the frame's observed values.
    observation_weighting : {"residual", "uniform"}, default="residual"
        ``"uniform"``: every observed channel gets ``observation_gain``.
        ``"residual"``: channel ``j`` gets ``1 + (observation_gain - 1) *
        min(m / v_j, 3)`` (at least 0), ``v_j`` its :attr:`residual_variance_`
        and ``m`` their median, so well-predicted channels count more.
    missing_values : int, float, str, np.nan or None, default=np.nan
        The placeholder for missing values; all its occurrences are filled.
    random_state : int, RandomState instance or None, default=None
        Seeds the sampling of :meth:`transform` and, with ``estimator=None``,
        the training of the default model.
    n_jobs : int, default=None
        Number of jobs filling blocks of up to 32 sequences in parallel; the
        fills are the same for every ``n_jobs``.
    verbose : int, default=0
        Training progress every ``verbose`` epochs.

    Attributes
    ----------
    estimator_ : estimator of the package
        The fitted clone of ``estimator``, or the model inside a
        ``FrozenEstimator`` (not a copy).
    mean_ : ndarray of shape (`n_features_in_`,)
        Mean training frame: where the missing channels of a sequence's first
        frame start.
    residual_variance_ : ndarray of shape (`n_features_in_`,)
        Variance of each channel's one-step residuals (the frame minus the
        model's ``predict_next``) on the training frames with a full past.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    AutoregressiveImputer : The strong simple baseline.
    NearestNeighborImputer : The paper's baseline.

    Notes
    -----
    The first frame of a sequence has no past: its missing channels start at
    ``mean_`` and the frame stands in for its own past (edge padding), three
    times over; frames ``1`` to ``order - 1`` use the past they have.  Wholly
    missing frames are generated from their past alone.  With
    ``CRBMImputer(n_particles=1, offset_shrinkage=None, observation_gain=1)``
    the fill is the paper's.  With a :class:`~sklearn_crbm.StackedCRBM`, each
    Gibbs iteration passes the frame up the layers and back down, the
    observed channels clamped at the bottom.  Under
    ``sklearn.set_config(array_api_dispatch=True)`` the imputer fills arrays
    of other namespaces on their device; the fills agree with numpy's in
    distribution, not digit for digit.

    References
    ----------
    G. W. Taylor, G. E. Hinton and S. Roweis. Modeling Human Motion Using
    Binary Latent Variables. NIPS 19, 2006, Section 4.4.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> from sklearn_crbm.impute import CRBMImputer
    >>> X, ids = make_oscillations(n_sequences=6, n_frames=60, random_state=0)
    >>> model = ConditionalRBM(n_components=16, order=2, n_iter=30,
    ...                        history_noise=0.4, random_state=0)
    >>> imputer = CRBMImputer(model, n_draws=5, random_state=0)
    >>> imputer.fit(X[ids < 5], sequence_ids=ids[ids < 5])
    CRBMImputer(...)
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
        "estimator": [HasMethods(["fit", "transform"]), None],
        "n_gibbs": [Interval(Integral, 0, None, closed="left")],
        "n_draws": [Interval(Integral, 1, None, closed="left")],
        "n_particles": [Interval(Integral, 1, None, closed="left")],
        "offset_shrinkage": [Interval(Real, 0, None, closed="left"), None],
        "observation_gain": [Interval(Real, 0, None, closed="left")],
        "observation_weighting": [StrOptions({"residual", "uniform"})],
        "random_state": ["random_state"],
        "n_jobs": [None, Integral],
        "verbose": ["verbose"],
    }

    _fitted_attribute = "_packed_parameters"

    __metadata_request__fit = {"sequence_ids": True, "context": True}
    __metadata_request__transform = {
        "sequence_ids": True,
        "context": True,
        "style": True,
    }

    def __init__(
        self,
        estimator=None,
        *,
        n_gibbs=30,
        n_draws=1,
        n_particles=20,
        offset_shrinkage=30.0,
        observation_gain=2.5,
        observation_weighting="residual",
        missing_values=np.nan,
        random_state=None,
        n_jobs=None,
        verbose=0,
    ):
        self.estimator = estimator
        self.n_gibbs = n_gibbs
        self.n_draws = n_draws
        self.n_particles = n_particles
        self.offset_shrinkage = offset_shrinkage
        self.observation_gain = observation_gain
        self.observation_weighting = observation_weighting
        self.missing_values = missing_values
        self.random_state = random_state
        self.n_jobs = n_jobs
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y=None, *, sequence_ids=None, context=None):
        """Train the model on complete sequences.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Training sequences, stacked, each contiguous and in time order.
            The model learns from complete frames only: a frame with a
            missing value is left out and splits its sequence in two.
        y : array-like of shape (n_frames,) or (n_frames, n_outputs), default=None
            The labels of every frame, for a model of styles
            (:class:`~sklearn_crbm.FactoredCRBM`), which needs them (one
            column per label factor, as the model's ``fit`` takes them);
            ignored by a model without styles.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's real-valued context, for the model to train on
            (see :meth:`ConditionalRBM.fit`); :meth:`transform` then needs
            the context of the frames it fills.

        Returns
        -------
        self : CRBMImputer
            The fitted imputer.
        """
        with unfitted_on_error(self):
            complete, run_ids, rows = self._complete_frames(X, sequence_ids)
            n_frames, X = _num_samples(X), complete
            ops = array_ops(X)
            estimator = self.estimator
            if estimator is None:
                estimator = _default_model(self.random_state)
            styles = _complete_styles(estimator, y, rows, n_frames, context)
            if context is not None:
                context = _complete_rows(context, rows, n_frames, X)
            if isinstance(estimator, FrozenEstimator):
                self.estimator_ = _check_frozen(estimator.estimator, X)
            else:
                self.estimator_ = self._train(
                    clone(estimator), X, run_ids, styles, context
                )
            self.mean_ = ops.mean(X, axis=0)
            self.residual_variance_ = _residual_variance(
                self.estimator_, X, run_ids, styles, context
            )
        return self

    def _train(self, estimator, X, sequence_ids, styles, context):
        if self.verbose:
            if estimator.get_params().get("verbose", 1) == 0:
                estimator.set_params(verbose=self.verbose)
            print(
                f"[{type(self).__name__}] training {estimator!r} on {len(X)} "
                f"complete frames in {len(np.unique(sequence_ids))} sequences"
            )
        if context is None:  # a model that takes no context is not given one
            return estimator.fit(X, styles, sequence_ids=sequence_ids)
        return estimator.fit(X, styles, sequence_ids=sequence_ids, context=context)

    @limit_blas_threads(chain_rows)
    def transform(self, X, *, sequence_ids=None, context=None, style=None):
        """Fill every missing value of ``X`` on-line.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Sequences with missing values, stacked, each contiguous and in
            time order.  Observed values come back unchanged.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, for a model fitted with one (which needs
            it); frame ``t`` is filled given its own context.
        style : label or array-like of shape (n_frames,) or (n_frames, \
n_classes), default=None
            A model of styles only: the style of every frame (for a model
            of several label factors, a row of labels for every frame or
            one per frame).  None infers it on-line: the particles of each
            draw carry one style each (one combination of a label of each
            factor; ``n_particles`` at least the number of styles, or of
            combinations, covers them all), and resampling by how well each
            explains the observed channels keeps the particles of the
            styles that do.

        Returns
        -------
        X_filled : ndarray of shape (n_frames, n_features)
            ``X`` with each missing value replaced by the average of
            ``n_draws`` on-line fills; no missing value is left.
        """
        return self._impute(
            X, sequence_ids, context, style, self.n_draws, self.random_state, True
        )

    @limit_blas_threads(chain_rows)
    def sample(
        self,
        X,
        n_samples=1,
        *,
        sequence_ids=None,
        context=None,
        style=None,
        random_state=None,
    ):
        """Draw independent on-line fills of ``X`` (multiple imputation).

        Each fill is one run of the procedure of :meth:`transform` with a
        single draw (with ``n_particles > 1``, one run of the particle
        filter: the mean of its particles); :meth:`transform` with
        ``n_draws=k`` and the same ``random_state`` returns the mean of the
        ``k`` fills this method draws.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Sequences with missing values.
        n_samples : int, default=1
            Number of fills.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context (see :meth:`transform`).
        style : label or array-like, default=None
            A model of styles only: every frame's style (see
            :meth:`transform`).
        random_state : int, RandomState instance or None, default=None
            Seeds the sampling; ``None`` uses the imputer's ``random_state``.

        Returns
        -------
        X_filled : ndarray of shape (n_samples, n_frames, n_features)
            The fills; observed values are unchanged in each.
        """
        n_samples = check_count(n_samples, "n_samples", minimum=1)
        random_state = self.random_state if random_state is None else random_state
        return self._impute(
            X, sequence_ids, context, style, n_samples, random_state, False
        )

    @property
    def _packed_parameters(self):
        """The model's parameter buffer: its namespace and device."""
        return self.estimator_.conditional_layers()[0].flat

    def _matrix_product_size(self, n_features=None):
        """The model's (:mod:`sklearn_crbm.utils._threads`)."""
        if _is_fitted(self):
            return self.estimator_._matrix_product_size(n_features)
        model = ConditionalRBM() if self.estimator is None else self.estimator
        return model._matrix_product_size(n_features)

    def _impute(self, X, sequence_ids, context, style, n_draws, random_state, average):
        X, mask, sequences = self._check_transform_input(X, sequence_ids)
        ops = array_ops(X)
        context = self.estimator_.fill_in_context(X, context=context, style=style)
        if not bool(ops.any(mask)):
            return (
                X if average else copy_array(ops.broadcast_to(X, (n_draws, *X.shape)))
            )
        rng = rng_from(random_state)
        draws = self._fill_blocks(X, mask, sequences, context, n_draws, rng)
        if average:
            draws = ops.mean(draws, axis=0)
        return ops.where(mask, ops.astype(draws, X.dtype), X)

    def _fill_blocks(self, X, mask, sequences, context, n_draws, rng):
        """:meth:`_fill` on blocks of whole sequences, in parallel with ``n_jobs``.

        The blocks and their random streams depend on the data only
        (:func:`~sklearn_crbm.utils._parallel.map_sequence_blocks`), so
        ``n_jobs`` never changes the fills.
        """

        def fill_block(block, block_rng):
            lo, hi = int(sequences.starts[block[0]]), int(sequences.stops[block[-1]])
            block_sequences = Sequences(
                starts=sequences.starts[block] - lo,
                lengths=sequences.lengths[block],
                ids=sequences.ids[block],
            )
            frame_context, hypotheses = context
            if frame_context is not None:
                frame_context = frame_context[lo:hi, ...]
            return self._fill(
                X[lo:hi, ...],
                mask[lo:hi, ...],
                block_sequences,
                (frame_context, hypotheses),
                n_draws,
                block_rng,
            )

        ops = array_ops(X)
        blocks = map_sequence_blocks(
            fill_block,
            sequences.n_sequences,
            rng,
            self.n_jobs,
            # an accelerator fills every sequence in one pass
            block_size=BLOCK_SEQUENCES if ops is np else sequences.n_sequences,
        )
        return ops.concatenate(blocks, axis=1)

    def _fill(self, X, mask, sequences, context, n_draws, rng):
        """``n_draws`` on-line fills, all sequences and draws advancing together.

        Every draw runs ``n_particles`` chains (:func:`~sklearn_crbm._engines._online.
        run_online` with the observed channels clamped); a draw's fill of a
        frame is the mean of its particles'.  ``context`` is the model's
        ``(frame_context, hypotheses)``.  Returns an array of shape
        ``(n_draws, n_frames, n_features)`` in the model's dtype.
        """
        layers = self.estimator_.conditional_layers()
        dtype, ops = layers[0].dtype, layers[0].ops
        X = ops.astype(X, dtype)
        frame_context, hypotheses = context
        n_chains = n_draws * self.n_particles
        chain_context = None
        if hypotheses is not None:  # particle i of every draw: hypothesis i mod K
            picks = np.arange(n_chains) % self.n_particles % hypotheses.shape[0]
            chain_context = ops.take(hypotheses, picks, axis=0)[:, None, :]
            chain_context = ops.broadcast_to(
                chain_context, (n_chains, sequences.n_sequences, hypotheses.shape[1])
            )
        # a sequence's first frame starts its missing channels at the mean
        observed = Observed(
            X=ops.where(mask, ops.astype(self.mean_, dtype), X),
            missing=mask,
            sequences=sequences,
            context=frame_context,
        )
        run = run_online(
            layers,
            array_random(rng, X),
            observed=observed,
            chain_context=chain_context,
            n_chains=n_chains,
            n_particles=self.n_particles,
            n_gibbs=self.n_gibbs,
            scheme=WHOLE_STACK,
            offset_shrinkage=self.offset_shrinkage,
            observation_gain=self._observation_gains(ops, X),
        )

        def mean_of_particles(frames):
            frames = ops.reshape(frames, (n_draws, self.n_particles, *frames.shape[1:]))
            return ops.mean(frames, axis=1)

        return collect_fills(run, sequences, mean_of_particles)

    def _observation_gains(self, ops, X):
        """``observation_gain`` per channel (see ``observation_weighting``).

        A number when every channel gets the same gain, else an array of
        shape ``(n_features,)`` in ``X``'s namespace, dtype and device.
        """
        gain = float(self.observation_gain)
        if self.observation_weighting == "uniform" or gain == 1:
            return gain
        variance = _to_numpy(self.residual_variance_).astype(np.float64)
        weights = np.minimum(
            np.median(variance) / np.maximum(variance, np.finfo(np.float64).tiny),
            MAX_CHANNEL_WEIGHT,
        )
        return ops.asarray(np.maximum(1 + (gain - 1) * weights, 0), dtype=X.dtype)


# The most a channel's weight in observation_weighting="residual" may be.
MAX_CHANNEL_WEIGHT = 3.0


def _complete_styles(estimator, y, rows, n_frames, context):
    """The styles of the complete frames, for a model of styles (else None)."""
    if not get_tags(estimator).target_tags.required:
        return None
    if y is None:
        if context is None:
            raise ValueError(
                f"CRBMImputer around {type(estimator).__name__} needs y in fit: "
                "the style of every training frame (or a real-valued context=)."
            )
        return None
    y = as_entries(y)
    if y.ndim == 0 or len(y) != n_frames:
        raise ValueError(
            f"y must hold one style label per frame of X ({n_frames}); got an "
            f"array of shape {y.shape} (several label factors: one row of labels "
            "per frame)."
        )
    return y[rows]


def _complete_rows(context, rows, n_frames, X):
    """The rows of the complete frames ``X`` of the context of ``n_frames``."""
    context = check_context(context, n_frames, None, X)
    return array_ops(X).take(context, rows, axis=0)


def _residual_variance(model, X, sequence_ids, styles, context):
    """Each channel's variance of ``X - model.predict_next(X)``.

    Over the frames with a full past in their sequence (all frames if none
    has one), given the frames' ``styles`` (a model of styles) or context.
    """
    ops = array_ops(X)
    residuals = X - model.predict_next(
        X, sequence_ids=sequence_ids, context=context, style=styles
    )
    sequences = check_sequence_ids(sequence_ids, X.shape[0])
    rows = sequences.valid_frames(model.history_length)
    if len(rows):
        residuals = ops.take(residuals, rows, axis=0)
    centred = residuals - ops.mean(residuals, axis=0)
    return ops.mean(centred * centred, axis=0)


def _check_frozen(model, X):
    """The fitted model inside a ``FrozenEstimator``, checked against the data."""
    check_is_fitted(
        model,
        msg="CRBMImputer got FrozenEstimator(%(name)s) with an unfitted model: "
        "fit the model first, or pass it without FrozenEstimator to train it.",
    )
    n_features = X.shape[1]
    if model.n_features_in_ != n_features:
        raise ValueError(
            f"The frozen {type(model).__name__} was fitted on "
            f"{model.n_features_in_} features but X has {n_features}: fit the "
            "imputer on data with the model's features (same preprocessing)."
        )
    check_same_place(
        model.conditional_layers()[0].flat,
        X,
        f"The frozen {type(model).__name__} holds",
    )
    return model
