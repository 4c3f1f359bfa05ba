"""On-line filling of missing channels with a conditional RBM (paper §4.4)."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context, clone
from sklearn.frozen import FrozenEstimator
from sklearn.utils import check_random_state, get_tags
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions
from sklearn.utils.validation import check_is_fitted

from .._base import check_count
from .._crbm import ConditionalRBM
from .._online import WHOLE_STACK, Observed, collect_fills, run_online
from ..utils._array_api import array_ops, array_random, copy_array
from ..utils._fitting import unfitted_on_error
from ..utils._parallel import BLOCK_SEQUENCES, map_sequence_blocks
from ..utils._random import rng_from
from ..utils._sequences import Sequences, check_sequence_ids
from ..utils._threads import chain_rows, limit_blas_threads
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
    ``transform`` then fills the frames of each sequence in time order, as
    they would arrive from a motion-capture system: frame ``t`` is filled
    from the already filled frames before it (through the directed
    connections) and from its own observed channels (through the symmetric
    ones), never from later frames.  The observed channels are clamped, the
    missing ones start at their value in the previous frame, and alternating
    Gibbs sampling follows: hidden units sampled given the frame and its
    history, visibles set to their mean given the hidden units, ``n_gibbs``
    times, then one mean-field step (the generation scheme of the original
    code, with the observed channels held fixed).

    Parameters
    ----------
    estimator : ConditionalRBM or StackedCRBM, default=None
        The model, cloned and trained by :meth:`fit`.  A model fitted
        already is used as it is, without training, when wrapped in
        :class:`sklearn.frozen.FrozenEstimator`:
        ``CRBMImputer(FrozenEstimator(model))``.  ``None`` means
        ``ConditionalRBM()``, seeded from ``random_state`` (see there), whose
        default ``history_noise`` trains on
        noisy histories so that on-line fills do not drift (see Notes; with
        :meth:`ConditionalRBM.paper_schedule` the filled upper body of a
        walk drifts for some training seeds).  Standardise the data first (e.g. with
        :class:`~sklearn_crbm.preprocessing.StandardScaler`): the visible
        units have unit variance.
    n_gibbs : int, default=30
        Alternating Gibbs iterations per frame.
    n_draws : int, default=1
        Number of independent fills averaged by :meth:`transform`: one
        draw is one sample of the model's on-line fill, the average of many
        estimates its posterior mean, which has a lower squared error.
    n_particles : int, default=20
        Chains per draw.  With more than one, each draw is a particle
        filter: before every frame, the draw's particles are resampled in
        proportion to how well each one's past predicts the frame's observed
        channels, and the draw's fill of the frame is the mean of its
        particles' fills (see Notes).  ``1`` is the paper's single chain.
        Mostly the mean of many chains lowers the squared error; with the
        offset correction, on the 40 cells of
        ``benchmarks/fillin_baselines.py`` (three random streams each),
        1, 10, 20 and 40 chains beat every simple baseline in 9, 23-27,
        26-29 and 27-29 cells.  Twenty cost about twenty times one chain
        (still several times real time).
    offset_shrinkage : float or None, default=30.0
        Correct each fill for the model's systematic error on the sequence
        at hand (see Notes).  ``None``: no correction (with
        ``n_particles=1`` and ``observation_gain=1``, the paper's fill-in
        exactly).  A number ``lam >=
        0``: a missing entry of channel ``j`` is shifted by ``sum(r) / (n +
        lam)``, where ``r`` are the channel's one-step residuals (observed
        value minus the chain's mean-field prediction from its past) over
        the ``n`` frames of the sequence in which it was observed so far:
        the mean residual, shrunk towards 0 as if ``lam`` frames of zero
        residual had been seen.  Binary visibles' fills are probabilities
        and are kept in [0, 1].  ``30`` suits CMU subject 35 at 30 frames
        per second (see Notes).
    observation_gain : float, default=2.5
        How strongly a frame's observed channels steer the fill of its
        missing ones (see Notes).  In the Gibbs run the hidden units see an
        observed channel at ``x_hat + observation_gain * (x - x_hat)``,
        where ``x`` is its value and ``x_hat`` the chain's one-step
        prediction of it from its past: its surprise counts
        ``observation_gain`` times.  ``1`` is the model's own conditional
        (with ``n_particles=1`` and ``offset_shrinkage=None``, the paper's
        fill-in exactly); ``0`` ignores the frame's observed values
        (a pure prediction from the past).  ``2.5`` suits CMU subject 35
        (see Notes).
    observation_weighting : {"residual", "uniform"}, default="residual"
        How ``observation_gain`` is spread over the channels.
        ``"uniform"``: every observed channel gets ``observation_gain``.
        ``"residual"``: channel ``j`` gets ``1 + (observation_gain - 1) *
        w_j`` (at least 0), with ``w_j = min(m / v_j, 3)``, where ``v_j`` is
        the variance of the model's one-step residuals of the channel on
        the training frames (:attr:`residual_variance_`) and ``m`` their
        median over the channels: a channel the model predicts well (a slow
        posture channel) speaks up to three times as loud, a fast one whose
        surprise is mostly noise (a jogging leg) less.  With
        ``observation_gain=1`` both are the model's own conditional.
    missing_values : int, float, str, np.nan or None, default=np.nan
        The placeholder for missing values; all its occurrences are filled.
    random_state : int, RandomState instance or None, default=None
        Seeds the Gibbs sampling of :meth:`transform`; pass an int for
        reproducible fills.  A given ``estimator`` keeps its own
        ``random_state`` for training; with ``estimator=None`` the default
        ``ConditionalRBM`` is trained with a seed drawn from this one, so the
        same int gives the same model and the same fills.
    n_jobs : int, default=None
        Number of jobs filling blocks of sequences in parallel (joblib).
        Up to 32 sequences are filled together, vectorised, as one block;
        more are split into near-equal blocks of consecutive sequences,
        each with its own random stream drawn from ``random_state``.  The
        split depends on the data only, so the fills are the same for every
        ``n_jobs``.  ``None`` means 1 unless in a
        :func:`joblib.parallel_backend` context; ``-1`` means all processors.
    verbose : int, default=0
        With ``verbose > 0``, :meth:`fit` says what it trains and the model
        reports its progress every ``verbose`` epochs (the model's own
        ``verbose``, when that is 0, is set to this value for training).

    Attributes
    ----------
    estimator_ : ConditionalRBM or StackedCRBM
        The fitted clone of ``estimator``, or the model inside a
        ``FrozenEstimator`` (not a copy).
    mean_ : ndarray of shape (`n_features_in_`,)
        Mean training frame: where the missing channels of the first frame
        of a sequence start.
    residual_variance_ : ndarray of shape (`n_features_in_`,)
        Variance of each channel's one-step residuals on the training
        frames that have a full past: the frame minus the model's
        ``predict_next``.  ``observation_weighting="residual"`` weights the
        channels by it.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    NearestNeighborImputer : The paper's baseline.
    ConditionalRBM : The model.

    Notes
    -----
    *Start of a sequence.*  The first frame of a sequence has no past: its
    missing channels start at the training mean and the model is run with
    the frame standing in for its own past (edge padding, as
    :meth:`ConditionalRBM.transform`), three times over, each time with the
    latest fill as the past.  Frames ``1`` to ``order - 1`` use the frames
    they have, the first frame repeated for the rest.

    *Drift, and how to avoid it.*  On-line, each frame is filled given the
    model's own fills of the frames before it, so fill errors feed back
    through the directed connections.  A model trained, as in the paper,
    on clean histories only has never seen a past with its own errors in
    it and need not correct them: with the upper body of a walk missing,
    the filled arms can slide into the jogging arm carriage and stay there,
    for some training seeds and not others, although the same model fills
    every frame well when given the *true* past.  Train the estimator with
    noisy histories (``ConditionalRBM(history_noise=0.4)`` for standardised
    motion) so that it learns to pull a perturbed past back towards the
    data; on CMU subject 35 this removes the drift for every seed (see
    ``benchmarks/paper_fillin.py``).

    *Particles.*  A drifting chain also predicts the *observed* channels
    badly.  With ``n_particles > 1`` every draw is a sequential Monte Carlo
    filter with the clamped Gibbs run as proposal: before frame ``t`` each
    particle is weighted by the likelihood of frame ``t``'s observed
    channels under its own one-step prediction (mean field from its past;
    Gaussian with the model's unit variance), the particles are resampled
    (systematic resampling), and each then fills frame ``t`` by clamped
    Gibbs sampling.  Particles that have drifted are replaced by copies of
    those that explain the data.  The filter stays on-line: frame ``t``'s
    fill never changes afterwards.

    *Offset correction.*  Filled from its own past, a model drifts towards
    its own typical values: on CMU subject 35 (``benchmarks/
    fillin_baselines.py``) about 40% of the error of a filled upper body is
    a constant offset of slow posture channels (lower back, thorax, head:
    the subject's forward lean in this trial), which the model, trained on
    every trial's posture and on noisy histories, pulls towards the
    average posture.  Before a channel went missing, the model's one-step
    predictions of it showed that pull as a residual of constant sign;
    ``offset_shrinkage`` carries it on, as the posterior mean of a constant
    offset behind the residuals (Gaussian, with a prior worth ``lam``
    frames), added to the fill and so fed back into the chain's past.  A
    fast channel's residuals average out and its correction stays small.
    With the defaults around ``ConditionalRBM(200, order=3, n_iter=1000)``
    it lowers the error on most cells of that benchmark; ``lam = 30`` was
    the best of 0, 10, 30, 100 and 300 on the training trials themselves.

    *Observation gain.*  The model's visible units have unit variance, but
    its real one-step residuals on standardised motion are about ten times
    smaller (median variance 0.06 per channel on CMU subject 35), so the
    model takes the observed channels of a frame for much noisier evidence
    than they are: filled from the *true* past, the missing channels come
    out nearly as well without the frame's observed channels as with them
    (``benchmarks/fillin_baselines.py``, second split, walk, left leg
    missing, models of seeds 0-2: 3.93-4.35 against 3.85-4.17).  A leg
    that falls out of step with the observed body is then not pulled back.
    ``observation_gain=g`` multiplies what the hidden units see of the
    observed channels' deviation from the chain's one-step prediction by
    ``g``, a first-order version of conditioning on them with variance
    ``1 / g`` (the exact tempered conditional couples the hidden units).
    The prediction, not the chain's current state, is the reference, so
    the amplified input is fixed during the Gibbs run and cannot
    oscillate; the observed values themselves are kept.  The first frame
    of a sequence, with no past, is filled with ``g = 1``.  The same gain
    on every channel (``observation_weighting="uniform"``, ``g = 2``, the
    best of 1, 1.5, 2, 2.5 and 3 on the training trials of CMU subject 35)
    re-anchors the filled leg of a walk to the observed body
    (``benchmarks/fillin_baselines.py``, second split, walk leg, seeds 0-4:
    4.43-5.37 against 4.88-6.08 with ``g = 1``) but fills the fast leg of
    a jog worse (5.09-7.17 against 4.79-5.60): there the observed leg's
    surprise is mostly noise.  ``observation_weighting="residual"`` gives
    each channel a gain by how well the model predicts it on the training
    frames, so that posture channels, predicted well, count most.  With it,
    on the training trials (models retrained, seeds 0-2, total error),
    ``g = 1.5, 2, 2.5, 3`` give 1374.6, 1359.1, 1348.9, 1347.7 against
    1368.3 for the uniform ``g = 2``; 2.5 and 3 tie (better than the
    uniform gain on 131 and 119 of 186 trial-cells), and 2.5, the smaller
    step, is the default.

    *Wholly missing frames* are generated from their past alone by the same
    on-line loop as :meth:`ConditionalRBM.sample`
    (:func:`~sklearn_crbm._online.run_online`), starting from the previous
    frame (without ``sample``'s small jitter).  Frames without missing
    channels are copied and cost nothing.

    *Array API.*  With ``sklearn.set_config(array_api_dispatch=True)``,
    :meth:`fit`, :meth:`transform` and :meth:`sample` take PyTorch (or
    array-api-strict, CuPy) arrays and work on their device; the output is in
    the input's namespace, on its device, in its dtype.  A frozen model must
    be there already (``sklearn.utils._array_api.move_estimator_to``).  There
    every sequence advances at every step, drawing frames with nothing
    missing too (they come back unchanged), so the random numbers, and the
    fills, differ from numpy's but agree with them in distribution.

    All sequences advance frame by frame together, and so do the
    ``n_draws * n_particles`` chains: the cost is about ``2 * n_gibbs``
    matrix products of ``n_draws * n_particles`` rows per frame of the
    longest sequence.  Memory is ``O(n_draws * n_frames * n_features)``
    for the output plus the recent past of every chain.

    The estimator may be a :class:`ConditionalRBM` or a
    :class:`~sklearn_crbm.StackedCRBM`.  With a stack each Gibbs iteration
    passes the frame up the lower layers (hidden probabilities), takes one
    alternating step of the top layer and passes the result down as visible
    means, with the observed channels clamped; every layer's directed
    connections see that layer's own on-line past (the frame's hidden
    probabilities in the layer below).  This is the ``"whole_stack"``
    scheme of :func:`~sklearn_crbm._online.run_online`: the clamped
    channels live at the bottom, so the frame itself must be the chain's
    state.  :meth:`StackedCRBM.sample`, with nothing to clamp, runs the
    chain in the top layer alone and passes it down once (``"top_layer"``,
    the original two-level code's scheme).

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

    __metadata_request__transform = {"sequence_ids": True, "style": True}

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
    def fit(self, X, y=None, *, sequence_ids=None):
        """Train the model on complete sequences.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Training sequences, stacked, each contiguous and in time order.
            The model learns from complete frames only: a frame with a
            missing value is left out and splits its sequence in two.
        y : array-like of shape (n_frames,) or (n_frames, n_classes), default=None
            The style of every frame, for a model of styles
            (:class:`~sklearn_crbm.FactoredCRBM`), which needs it; ignored
            by a model without styles.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        self : CRBMImputer
            The fitted imputer.
        """
        with unfitted_on_error(self):
            X, run_ids, rows = self._complete_frames(X, sequence_ids)
            ops = array_ops(X)
            estimator = self.estimator
            if estimator is None:
                estimator = _default_model(self.random_state)
            styles = _complete_styles(estimator, y, rows)
            if isinstance(estimator, FrozenEstimator):
                self.estimator_ = _check_frozen(estimator.estimator, X)
            else:
                self.estimator_ = self._train(clone(estimator), X, run_ids, styles)
            self.mean_ = ops.mean(X, axis=0)
            self.residual_variance_ = _residual_variance(
                self.estimator_, X, run_ids, styles
            )
        return self

    def _train(self, estimator, X, sequence_ids, styles):
        if self.verbose:
            if estimator.get_params().get("verbose", 1) == 0:
                estimator.set_params(verbose=self.verbose)
            print(
                f"[{type(self).__name__}] training {estimator!r} on {len(X)} "
                f"complete frames in {len(np.unique(sequence_ids))} sequences"
            )
        return estimator.fit(X, styles, sequence_ids=sequence_ids)

    @limit_blas_threads(chain_rows)
    def transform(self, X, *, sequence_ids=None, style=None):
        """Fill every missing value of ``X`` on-line.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Sequences with missing values, stacked, each contiguous and in
            time order.  Observed values come back unchanged.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        style : label or array-like of shape (n_frames,) or (n_frames, \
n_classes), default=None
            A model of styles only: the style of every frame.  None infers
            it on-line: the particles of each draw carry one style each
            (``n_particles`` at least the number of styles covers them all),
            and resampling by how well each explains the observed channels
            keeps the particles of the styles that do.

        Returns
        -------
        X_filled : ndarray of shape (n_frames, n_features)
            ``X`` with each missing value replaced by the average of
            ``n_draws`` on-line fills; no missing value is left.
        """
        return self._impute(
            X, sequence_ids, style, self.n_draws, self.random_state, True
        )

    @limit_blas_threads(chain_rows)
    def sample(
        self, X, n_samples=1, *, sequence_ids=None, style=None, random_state=None
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
        return self._impute(X, sequence_ids, style, n_samples, random_state, False)

    @property
    def _packed_parameters(self):
        """The model's parameter buffer: its namespace and device."""
        return self.estimator_._packed_parameters

    def _impute(self, X, sequence_ids, style, n_draws, random_state, average):
        X, mask, sequences = self._check_transform_input(X, sequence_ids)
        ops = array_ops(X)
        context = self.estimator_._online_context(X, style)
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

        Every draw runs ``n_particles`` chains (:func:`~sklearn_crbm._online.
        run_online` with the observed channels clamped); a draw's fill of a
        frame is the mean of its particles'.  ``context`` is the model's
        ``(frame_context, hypotheses)``.  Returns an array of shape
        ``(n_draws, n_frames, n_features)`` in the model's dtype.
        """
        layers = self.estimator_._layers()
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


def _complete_styles(estimator, y, rows):
    """The styles of the complete frames, for a model of styles (else None)."""
    if not get_tags(estimator).target_tags.required:
        return None
    if y is None:
        raise ValueError(
            f"CRBMImputer around {type(estimator).__name__} needs y in fit: the "
            "style of every training frame."
        )
    return np.asarray(y)[rows]


def _residual_variance(model, X, sequence_ids, styles):
    """Each channel's variance of ``X - model.predict_next(X)``.

    Over the frames with a full past in their sequence (all frames if none
    has one), given the frames' ``styles`` for a model of styles.
    """
    ops = array_ops(X)
    sequences = check_sequence_ids(sequence_ids, X.shape[0])
    context = model._online_context(X, styles)[0]
    residuals = X - model._predict_frames(X, sequences, context=context)
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
        model._packed_parameters, X, f"The frozen {type(model).__name__} holds"
    )
    return model
