"""Conditional Restricted Boltzmann Machine (Taylor, Hinton & Roweis, 2006)."""

import math
import time
from functools import partial
from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context
from sklearn.externals import array_api_compat
from sklearn.utils import Bunch, check_random_state
from sklearn.utils._array_api import (
    _convert_to_numpy,
    get_namespace_and_device,
    move_to,
)
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import validate_data

from ._base import BaseCRBM, FittedParameter
from ._crbm_math import (
    BINARY,
    MIN_LOG_VARIANCE,
    CDWorkspace,
    CRBMParameters,
    MomentumUpdate,
    add_normal_noise,
    cd_gradients,
)
from .utils._array_api import array_ops, array_random, to_device_batches
from .utils._autoregression import ridge_autoregression
from .utils._fitting import unfitted_on_error
from .utils._random import rng_from
from .utils._sequences import (
    balanced_batches,
    check_sequence_ids,
    frame_history,
    shuffled_batches,
    validation_split,
)
from .utils._threads import batch_rows, frame_rows, limit_blas_threads

# Ridge penalty of init="autoregressive": AutoregressiveImputer's default.
_AUTOREGRESSIVE_ALPHA = 1.0


class TrainingDivergedError(FloatingPointError):
    """Training produced non-finite weights (the learning rate is too large)."""


class ConditionalRBM(BaseCRBM):
    """Conditional Restricted Boltzmann Machine for sequences of frames.

    Models each frame ``v_t`` with visible units (Gaussian with unit variance
    or binary) and binary hidden units, conditioned on the previous frames of
    the same sequence through directed connections: autoregressive weights
    from the past ``order`` frames to the visible units and weights from the
    past ``hidden_order`` frames to the hidden units (Taylor, Hinton & Roweis,
    2006).  Trained with contrastive divergence on minibatches of frames whose
    history is gathered by index arithmetic.

    Data are in long format: ``X`` stacks all sequences, each contiguous and
    in time order, and ``sequence_ids`` marks which frames belong together.

    Parameters
    ----------
    n_components : int, default=200
        Number of binary hidden units: the paper's number for walking and
        jogging in one model.  On CMU subject 35, with the other defaults,
        fewer lose the jogs' leg movement (100 units: 13 of 30 generated
        jogs keep it over 1000 frames, 200 units: 23 to 30 of 30, see
        ``benchmarks/generation_seeds.py``).  More units cost linearly more
        time.
    order : int, default=3
        Number of past frames feeding the visible units (autoregressive
        connections).  ``order=0`` together with ``hidden_order=0`` is a plain
        RBM.
    hidden_order : int, default=None
        Number of past frames feeding the hidden units; ``None`` means
        ``order``.
    visible_type : {"gaussian", "binary"}, default="gaussian"
        Gaussian visible units (standardise the data first, e.g. with
        :class:`~sklearn_crbm.preprocessing.StandardScaler`), or
        binary/probability visible units for data in ``[0, 1]``.
    visible_variance : {"unit", "learned"}, default="unit"
        ``"unit"``: Gaussian visibles of variance 1, as in the paper.
        ``"learned"``: one variance per channel, trained with the other
        parameters (Cho, Raiko & Ilin, 2011; see Notes).  Learned variances
        model the data's density far better (held-out log-likelihood, see
        ``benchmarks/likelihood_baselines.py``; train them with more
        reconstruction steps, e.g. ``cd_steps=5``) but fill in and generate
        worse than unit variances with ``history_noise``
        (``benchmarks/fillin_baselines.py``).  Gaussian visibles only;
        variances are kept at or above 1e-4 (standardised data).
    init : {"random", "autoregressive"}, default="random"
        How the parameters start.  ``"random"``: the paper's (small random
        weights, see :meth:`CRBMParameters.initialize
        <sklearn_crbm._crbm_math.CRBMParameters.initialize>`).
        ``"autoregressive"``: the same, but the autoregressive weights and
        the visible biases are those of a ridge regression (penalty
        ``alpha=1``, as :class:`~sklearn_crbm.impute.AutoregressiveImputer`)
        of every trainable frame on its ``order`` past frames, and with
        ``visible_variance="learned"`` the variances are the per-channel
        mean squared residuals of that regression.  Were ``W`` and the
        past-to-hidden weights zero, the model would then be exactly that
        linear-Gaussian AR model; training starts there and refines it.
        On CMU 35, with learned variances, ``history_noise=0.2`` and 2-3
        epochs (chosen on held-out trials) it scores above that AR on
        held-out trials, mostly by widening its variances; with the other
        defaults it fills in no better than the random start
        (``benchmarks/likelihood_baselines.py``,
        ``benchmarks/fillin_baselines.py``).  Gaussian visibles only.
    learning_rate : float, default=1e-3
        Step size for every parameter group.
    momentum : float, default=0.9
        Momentum used after the first ``momentum_delay`` epochs.
    momentum_delay : int, default=5
        Number of epochs trained without momentum.
    weight_decay : float, default=2e-4
        L2 penalty on the symmetric and directed weights (not on biases),
        applied inside the learning-rate term as in the original code.
    cd_steps : int, default=1
        Number of reconstructions per update (CD-k).
    batch_size : int, default=100
        Frames per minibatch.
    batching : {"balanced", "shuffled"}, default="balanced"
        ``"balanced"``: the paper's scheme, every minibatch takes one frame
        from each consecutive chunk of the data, so it draws evenly from all
        sequences and holds no neighbouring frames.  ``"shuffled"``: the
        released code's scheme, all trainable frames shuffled each epoch.
    history_noise : float, default=0.8
        Standard deviation of Gaussian noise added, during training only, to
        the past frames that feed the directed connections (in the units of
        ``X``; the frame being modelled stays clean).  ``0`` is the paper's
        schedule (:meth:`paper_schedule`).  A model trained on clean
        histories predicts one step ahead well but, when it generates, its
        own small errors feed back through the directed connections (mostly
        near-unit-root autoregressive weights) and the generated motion
        drifts: a walk speeds up into a jog or freezes, differently for
        every training seed.  Noisy histories teach it to pull a perturbed past back
        towards the data and to carry the style in its hidden units, which
        keeps long generated sequences in their style; 0.8 for standardised
        motion: with the other defaults, of the walks and jogs that models
        of five training seeds generate, 239 of 240 sequence windows keep
        their style and 229 of 240 their leg movement and step frequency
        (two encodings, 300 and 1000 frames,
        ``benchmarks/generation_seeds.py``), at the price of a larger
        one-step prediction error.
    n_iter : int, default=1000
        Number of epochs (passes over the trainable frames).  On CMU subject
        35 (2813 frames, 62 channels) an epoch of 200 hidden units takes about
        17 ms in float32 and 36 ms in float64 on one core, so the default fit
        takes 17 to 36 seconds.  After 200 epochs no generated jog keeps its
        leg movement (0 of 30 over five training seeds); the paper trains
        for 4000 (:meth:`paper_schedule`).
    ais_steps : int, default=50
        Intermediate distributions of the annealed importance sampling
        behind :meth:`score` and :meth:`score_samples` (used when the hidden
        units are too many to enumerate).  On CMU 35, 50 distributions and
        2 chains stay within 0.01 nats/frame of 500 x 16 for a model with
        history, at a few percent of the cost of training it.  A model
        without history (``order=0`` and ``hidden_order=0``) has one
        partition function for all frames and anneals it once, with five
        times as many, from up to 256 of the frames scored.
    ais_chains : int, default=2
        Annealing chains per frame (per starting frame for a model without
        history).
    early_stopping : bool, default=False
        Hold out whole sequences (``validation_fraction`` of the frames) in
        :meth:`fit`, score them (:meth:`score`, the held-out
        log-likelihood) every ``validation_interval`` epochs, stop when it
        has not improved by ``tol`` for ``n_iter_no_change`` epochs (or
        after ``n_iter``), and keep the parameters that scored best.
        Needs several sequences; ignored by :meth:`partial_fit`.
    validation_fraction : float, default=0.1
        Fraction of the frames, in whole sequences drawn at random, held
        out when ``early_stopping`` is True.
    n_iter_no_change : int, default=50
        Epochs without an improvement of ``tol`` after which
        ``early_stopping`` stops training.
    validation_interval : int, default=10
        Epochs between two validation scores when ``early_stopping``.
    tol : float, default=1e-3
        Improvement of the validation score, in nats per frame, that counts
        when ``early_stopping``.
    random_state : int, RandomState instance or None, default=None
        Controls initialisation, minibatches, sampling during training and,
        unless ``sample`` is given its own, generation.  Pass an int for
        reproducible results.
    verbose : int, default=0
        Print the epoch, reconstruction error and elapsed time every
        ``verbose`` epochs.

    Attributes
    ----------
    components_ : ndarray of shape (n_components, n_features)
        Symmetric weights ``W`` between hidden and visible units.
    intercept_hidden_ : ndarray of shape (n_components,)
        Static hidden biases.
    intercept_visible_ : ndarray of shape (n_features,)
        Static visible biases.
    autoregressive_ : ndarray of shape (order, n_features, n_features)
        ``autoregressive_[q - 1] @ x[t - q]`` adds to the visible mean of
        frame ``t``.
    past_to_hidden_ : ndarray of shape (hidden_order, n_components, n_features)
        ``past_to_hidden_[q - 1] @ x[t - q]`` adds to the hidden input of
        frame ``t``.  This and the four attributes above are views of one
        packed parameter buffer; assigning an array of the same shape to
        one of them changes the model.
    visible_variance_ : ndarray of shape (n_features,)
        Variance ``s^2`` of each Gaussian visible unit given the hidden
        units: all ones unless ``visible_variance="learned"``.  Computed
        from the packed ``log s^2``; assigning to it sets that.
    seed_windows_ : ndarray of shape (n_windows, width, n_features)
        ``width = max(order, hidden_order, 1)``. Windows of consecutive
        training frames kept to seed :meth:`sample`.
    reconstruction_error_ : float
        Mean squared reconstruction error per trainable frame (summed over
        features) in the last epoch.
    random_state_ : RandomState instance
        Random generator state carried across :meth:`partial_fit` calls.
    n_iter_ : int
        Number of epochs trained so far.
    validation_scores_ : list of float
        With ``early_stopping``: the held-out score after every
        ``validation_interval`` epochs.
    best_validation_score_ : float
        With ``early_stopping``: the best of them, that of the parameters
        kept.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    sklearn.neural_network.BernoulliRBM : RBM of independent binary frames.

    Notes
    -----
    Training follows the paper's Section 2.2 approximations and the original
    code's schedule: CD-k with binary hidden states in the positive
    statistics, visible means in the reconstructions and hidden
    probabilities in the negative statistics; frames without ``max(order,
    hidden_order)`` past frames inside their own sequence are not trained
    on.  Memory for ``fit`` is ``O(n_frames * n_features)`` whatever the
    order: no history is ever materialised for the whole data set.

    With learned visible variances the energy of a frame given its history
    keeps the form of Hinton's practical guide, ``sum_i (v_i - c_hat_i)^2 /
    (2 s_i^2) - b_hat . h - (v / s) . (W.T h)``: the hidden units see ``v /
    s`` and the visible mean is ``c_hat + s * (W.T h)``.  Training learns
    ``log s^2``; the statistics are written out in
    :func:`sklearn_crbm._crbm_math.cd_gradients` (the visible bias and
    autoregressive steps are scaled by ``s^2``, the natural gradient of a
    Gaussian mean).

    References
    ----------
    G. W. Taylor, G. E. Hinton and S. Roweis. Modeling Human Motion Using
    Binary Latent Variables. NIPS 19, 2006.

    K. Cho, T. Raiko and A. Ilin. Improved Learning of Gaussian-Bernoulli
    Restricted Boltzmann Machines. ICANN 2011.

    G. E. Hinton. A Practical Guide to Training Restricted Boltzmann
    Machines. UTML TR 2010-003, 2010.

    Examples
    --------
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, sequence_ids = make_oscillations(n_sequences=4, n_frames=50, random_state=0)
    >>> model = ConditionalRBM(n_components=16, order=2, n_iter=20, random_state=0)
    >>> model.fit(X, sequence_ids=sequence_ids)
    ConditionalRBM(n_components=16, n_iter=20, order=2, random_state=0)
    >>> model.transform(X, sequence_ids=sequence_ids).shape
    (200, 16)
    >>> model.sample(30, n_sequences=3, random_state=0).shape
    (90, 6)
    """

    _parameter_constraints: dict = {
        **BaseCRBM._parameter_constraints,
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "visible_type": [StrOptions({"gaussian", "binary"})],
        "ais_steps": [Interval(Integral, 1, None, closed="left")],
        "ais_chains": [Interval(Integral, 1, None, closed="left")],
        "early_stopping": ["boolean"],
        "validation_fraction": [Interval(Real, 0, 1, closed="neither")],
        "n_iter_no_change": [Interval(Integral, 1, None, closed="left")],
        "validation_interval": [Interval(Integral, 1, None, closed="left")],
        "tol": [Interval(Real, 0, None, closed="left")],
        "visible_variance": [StrOptions({"unit", "learned"})],
        "init": [StrOptions({"random", "autoregressive"})],
    }

    # Private state that a failed fit must forget with the fitted attributes:
    # the packed parameters (which the public ones view) and the velocities.
    _training_state = ("_parameters", "_velocity")

    components_ = FittedParameter("weights")
    intercept_hidden_ = FittedParameter("hidden_bias")
    intercept_visible_ = FittedParameter("visible_bias")
    autoregressive_ = FittedParameter("autoregressive")
    past_to_hidden_ = FittedParameter("past_to_hidden")
    visible_variance_ = FittedParameter("visible_variance")

    def __init__(
        self,
        n_components=200,
        *,
        order=3,
        hidden_order=None,
        visible_type="gaussian",
        visible_variance="unit",
        init="random",
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=100,
        batching="balanced",
        history_noise=0.8,
        n_iter=1000,
        ais_steps=50,
        ais_chains=2,
        early_stopping=False,
        validation_fraction=0.1,
        n_iter_no_change=50,
        validation_interval=10,
        tol=1e-3,
        random_state=None,
        verbose=0,
    ):
        self.n_components = n_components
        self.order = order
        self.hidden_order = hidden_order
        self.visible_type = visible_type
        self.visible_variance = visible_variance
        self.init = init
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.momentum_delay = momentum_delay
        self.weight_decay = weight_decay
        self.cd_steps = cd_steps
        self.batch_size = batch_size
        self.batching = batching
        self.history_noise = history_noise
        self.n_iter = n_iter
        self.ais_steps = ais_steps
        self.ais_chains = ais_chains
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.validation_interval = validation_interval
        self.tol = tol
        self.random_state = random_state
        self.verbose = verbose

    # The training of the paper and its released code (REFERENCE.md).
    _PAPER_SCHEDULE = dict(
        n_components=200,
        order=3,
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=100,
        batching="shuffled",
        history_noise=0.0,
        visible_variance="unit",
        n_iter=4000,
    )

    @classmethod
    def paper_schedule(cls, **params):
        """A model with the exact training schedule of the paper.

        Taylor, Hinton & Roweis (2006) and their released code: 200 hidden
        units, order 3, CD-1 with learning rate 1e-3 for every parameter
        group, momentum 0.9 after 5 epochs, weight decay 2e-4 on the
        weights, minibatches of 100 frames shuffled each epoch, clean
        histories (``history_noise=0``), 4000 epochs.  The defaults differ
        where measurements showed better models for every training seed
        (``history_noise``, ``batching``); this keeps the paper's
        experiments reproducible (``benchmarks/paper_fillin.py``).

        Parameters
        ----------
        **params
            Parameters that replace those of the schedule, e.g.
            ``n_iter=1000`` or ``random_state=0``.

        Returns
        -------
        model : ConditionalRBM
            Unfitted.

        Examples
        --------
        >>> from sklearn_crbm import ConditionalRBM
        >>> model = ConditionalRBM.paper_schedule(n_iter=1000, random_state=0)
        >>> model.n_components, model.history_noise, model.batching
        (200, 0.0, 'shuffled')
        """
        return cls(**{**cls._PAPER_SCHEDULE, **params})

    # ------------------------------------------------------------------ fit

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Train the model on sequences of frames.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        self : ConditionalRBM
            The fitted model.
        """
        with unfitted_on_error(self):
            xp, _ = get_namespace_and_device(X)[:2]
            X = validate_data(self, X, dtype=[xp.float64, xp.float32], reset=True)
            sequences, frames = self._check_sequences(X, sequence_ids)
            self.random_state_ = check_random_state(self.random_state)
            self._initialize(X)
            if self.early_stopping:
                self._train_with_early_stopping(X, sequences)
            else:
                self._start_autoregressive(X, frames)
                self._train(X, frames, self.n_iter)
            self.seed_windows_ = self._pick_seed_windows(X, sequences)
        return self

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def partial_fit(self, X, y=None, *, sequence_ids=None):
        """Train for one epoch on the given sequences, keeping the current state.

        The first call initialises the model; later calls continue from the
        current parameters, momentum and epoch count.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        self : ConditionalRBM
            The updated model.
        """
        first_call = not hasattr(self, "components_")
        # bad input leaves a fitted model as it was; divergence unfits it
        with unfitted_on_error(self, Exception if first_call else ()):
            xp = get_namespace_and_device(X)[0]
            if not first_call:
                self._check_namespace(X, "partial_fit")
            X = validate_data(
                self,
                X,
                dtype=[xp.float64, xp.float32]
                if first_call
                else self._parameters.dtype,
                reset=first_call,
            )
            sequences, frames = self._check_sequences(X, sequence_ids)
        with unfitted_on_error(self):
            if first_call:
                self.random_state_ = check_random_state(self.random_state)
                self._initialize(X)
                self._start_autoregressive(X, frames)
            self._train(X, frames, 1)
        self.seed_windows_ = self._merge_seed_windows(
            self._pick_seed_windows(X, sequences)
        )
        return self

    @property
    def history_length(self):
        """Past frames a frame depends on: ``max(order, hidden_order)``.

        :meth:`sample` needs this many seed frames (at least one), and
        :meth:`score` judges frames with this many past frames in their
        sequence.
        """
        return self._n_lags

    def _layer_parameters(self):
        return [self._parameters]

    def _check_sequences(self, X, sequence_ids):
        """Validate ids and visible type; return the sequences and trainable frames."""
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        if self.visible_type == BINARY and self.visible_variance == "learned":
            raise ValueError(
                "visible_variance='learned' needs Gaussian visibles; binary "
                "visibles have no variance to learn. Use visible_variance='unit'."
            )
        if self.visible_type == BINARY and self.init == "autoregressive":
            raise ValueError(
                "init='autoregressive' starts from a linear-Gaussian model and "
                "needs Gaussian visibles. Use init='random' with binary visibles."
            )
        ops = array_ops(X)
        low, high = float(ops.min(X)), float(ops.max(X))
        if self.visible_type == BINARY and (low < 0 or high > 1):
            raise ValueError(
                "visible_type='binary' needs data in [0, 1] (binary values or "
                f"probabilities); got values in [{low:g}, {high:g}]. Use "
                "visible_type='gaussian' for standardised real-valued data."
            )
        frames = sequences.valid_frames(self._n_lags)
        if len(frames) == 0:
            longest = int(sequences.lengths.max()) if len(sequences.lengths) else 0
            noun = "sample" if longest == 1 else "samples"
            raise ValueError(
                f"No frame has {self._n_lags} past frames in its own sequence: the "
                f"longest sequence has {longest} {noun}, but a model of order "
                f"{self._n_lags} needs sequences of at least {self._n_lags + 1} "
                "frames. Pass longer sequences (check sequence_ids) or lower order."
            )
        return sequences, frames

    def _initialize(self, X):
        """Draw the start parameters, in the namespace and on the device of ``X``.

        They are drawn with numpy (the same numbers for every namespace) and
        moved to ``X``'s namespace and device.
        """
        ops = array_ops(X)
        params = CRBMParameters.initialize(
            X.shape[1],
            self.n_components,
            self.order,
            self._hidden_order,
            self.visible_type,
            np.float32 if X.dtype == ops.float32 else np.float64,
            rng_from(self.random_state_),
            learned_variance=self.visible_variance == "learned",
        )
        if ops is not np:
            xp, _, device = get_namespace_and_device(X)
            params = params.__sklearn_array_api_convert__(
                partial(move_to, xp=xp, device=device)
            )
        self.n_iter_ = 0
        self._parameters = params
        self._velocity = params.zeros_like(layout="F")

    def _start_autoregressive(self, X, frames):
        """With ``init="autoregressive"``: start from the ridge AR of ``frames``.

        Sets the autoregressive weights, the visible biases and (learned
        variances) the visible variances; the other groups keep their random
        start.
        """
        if self.init != "autoregressive":
            return
        if not isinstance(X, np.ndarray):  # array API input: fitted with numpy
            X = _convert_to_numpy(X, array_api_compat.array_namespace(X))
        fit = ridge_autoregression(
            X.astype(np.float64), frames, self.order, _AUTOREGRESSIVE_ALPHA
        )
        self.autoregressive_ = fit.coef.astype(X.dtype)
        self.intercept_visible_ = fit.intercept.astype(X.dtype)
        if self._parameters.learned_variance:
            variance = np.mean(np.square(fit.residual), axis=0)
            self.visible_variance_ = np.maximum(
                variance, np.exp(MIN_LOG_VARIANCE)
            ).astype(X.dtype)

    # Diverging weights overflow in the products before the epoch's check
    # raises TrainingDivergedError, which says what to do.
    @np.errstate(over="ignore", invalid="ignore")
    def _train(self, X, frames, n_epochs):
        # trained in the layout BLAS runs fastest, kept in C order when fitted
        params = self._parameters.copy(layout="F")
        update = MomentumUpdate(params, self._velocity)
        self._velocity = update.velocity
        # Minibatches gather rows: from a Fortran-ordered X (what many
        # transformers return) every row would be a strided read.
        ops = array_ops(X)
        X = ops.ascontiguousarray(X)
        plan_batches = (
            balanced_batches if self.batching == "balanced" else shuffled_batches
        )
        n_lags = params.n_lags
        # Buffers reused by every minibatch
        workspace = CDWorkspace(params, self.batch_size)
        noise_buffer = ops.empty_like(workspace.history) if self.history_noise else None
        start = time.perf_counter()
        for _ in range(n_epochs):
            rng = rng_from(self.random_state_)
            # minibatches are planned with numpy; the math draws on X's device
            math_rng = array_random(rng, X)
            momentum = self.momentum if self.n_iter_ >= self.momentum_delay else 0.0
            squared_error = 0.0
            batches = plan_batches(frames, self.batch_size, rng)
            if ops is not np:  # the epoch's plan reaches the device in one copy
                batches = to_device_batches(batches, ops)
            for batch in batches:
                n = batch.shape[0]
                visible = ops.take(
                    X, batch, axis=0, out=workspace.visible(n), mode="clip"
                )
                batch_history = frame_history(
                    X, batch, n_lags, out=workspace.history[:n, ...]
                )
                if self.history_noise:
                    add_normal_noise(
                        math_rng,
                        batch_history,
                        self.history_noise,
                        noise_buffer[:n, ...],
                    )
                _, error = cd_gradients(
                    params,
                    visible,
                    batch_history,
                    self.cd_steps,
                    math_rng,
                    out=update.statistics,
                    scale=self.learning_rate / n,
                    workspace=workspace,
                )
                squared_error += error
                update.apply(momentum, self.learning_rate, self.weight_decay)
                if params.learned_variance:
                    ops.maximum(
                        params.log_visible_variance,
                        MIN_LOG_VARIANCE,
                        out=params.log_visible_variance,
                    )
            squared_error = float(squared_error)  # one device sync per epoch
            self.n_iter_ += 1
            self.reconstruction_error_ = squared_error / len(frames)
            if not params.is_finite() or not math.isfinite(squared_error):
                self._parameters = params.copy(layout="C")
                raise TrainingDivergedError(
                    f"Training diverged at epoch {self.n_iter_}: the weights became "
                    f"non-finite with learning_rate={self.learning_rate}. Lower the "
                    "learning rate (and momentum), and standardise the data, e.g. "
                    "with sklearn_crbm.preprocessing.StandardScaler."
                )
            if self.verbose and self.n_iter_ % self.verbose == 0:
                print(
                    f"[{type(self).__name__}] Iteration {self.n_iter_}, "
                    f"reconstruction error = {self.reconstruction_error_:.4f}, "
                    f"time = {time.perf_counter() - start:.2f}s"
                )
        self._parameters = params.copy(layout="C")

    def _train_with_early_stopping(self, X, sequences):
        """Train on some sequences, keep the parameters that score best on the rest."""
        rng = rng_from(self.random_state_)
        held = validation_split(sequences, self.validation_fraction, rng)
        ids = sequences.per_frame_ids()
        parts = []
        for mask in (~held, held):
            part = check_sequence_ids(ids[mask], int(mask.sum()))
            frames = part.valid_frames(self._n_lags)
            if len(frames) == 0:
                raise ValueError(
                    f"early_stopping: no {'validation' if mask is held else 'training'}"
                    f" frame has {self._n_lags} past frames in its sequence; pass "
                    "longer sequences or raise validation_fraction."
                )
            rows = np.flatnonzero(mask)
            parts.append((array_ops(X).take(X, rows, axis=0), part, frames))
        (X_train, _, train_frames), (X_valid, valid, valid_frames) = parts
        self._start_autoregressive(X_train, train_frames)
        # the same random numbers at every check: changes are the model's
        seed = int(rng.integers(np.iinfo(np.int32).max))
        self.validation_scores_ = []
        best, best_iter, best_parameters = -np.inf, 0, None
        while self.n_iter_ < self.n_iter:
            epochs = min(self.validation_interval, self.n_iter - self.n_iter_)
            self._train(X_train, train_frames, epochs)
            log_likelihood = self._log_likelihood(
                X_valid, valid, rng=np.random.default_rng(seed)
            ).log_likelihood
            ops = array_ops(log_likelihood)
            score = float(ops.mean(ops.take(log_likelihood, valid_frames, axis=0)))
            self.validation_scores_.append(score)
            if score > best + self.tol or best_parameters is None:
                best, best_iter = float(score), self.n_iter_
                best_parameters = self._parameters.copy()
            elif self.n_iter_ - best_iter >= self.n_iter_no_change:
                break
        self._parameters = best_parameters
        self.best_validation_score_ = best

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.array_api_support = True
        return tags

    @limit_blas_threads(frame_rows)
    def estimate_log_likelihood(
        self, X, *, sequence_ids=None, method="auto", reverse=True, random_state=None
    ):
        """``log p(x_t | history)`` of every frame, with how far to trust it.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        method : {"auto", "exact", "ais"}, default="auto"
            ``"exact"`` enumerates the hidden configurations (at most 24
            hidden units), ``"ais"`` anneals (``ais_steps``,
            ``ais_chains``), ``"auto"`` takes the cheaper.
        reverse : bool, default=True
            Also run reverse annealing (RAISE, Burda, Grosse & Salakhutdinov,
            2015) from every frame: a conservative estimate, low on average,
            that costs as much again.
        random_state : int, RandomState instance or None, default=None
            Seeds the annealing; ``None`` uses the estimator's
            ``random_state`` (what :meth:`score` uses).

        Returns
        -------
        result : :class:`~sklearn.utils.Bunch`
            log_likelihood : ndarray of shape (n_frames,)
                As :meth:`score_samples` gives it: forward AIS, high on
                average (its partition function is low on average).
            lower : ndarray of shape (n_frames,) or None
                The reverse estimate (equal to ``log_likelihood`` when
                exact; None if not ``reverse``).  When the annealing is
                good the two bracket the truth, and their gap bounds the
                error of either.
            standard_error : ndarray of shape (n_frames,)
                Standard error of the forward estimate across chains (0
                when exact; for a model without history, that of its one
                partition function).
            method : str
                ``"exact"`` or ``"ais"``.

        Examples
        --------
        >>> from sklearn_crbm import ConditionalRBM
        >>> from sklearn_crbm.datasets import make_oscillations
        >>> X, ids = make_oscillations(n_sequences=4, n_frames=40, random_state=0)
        >>> model = ConditionalRBM(30, order=2, n_iter=20, random_state=0)
        >>> model = model.fit(X, sequence_ids=ids)
        >>> result = model.estimate_log_likelihood(X, sequence_ids=ids)
        >>> result.method
        'ais'
        >>> print(f"{result.log_likelihood.mean():.2f} {result.lower.mean():.2f}")
        -5.60 -5.60
        """
        if method not in ("auto", "exact", "ais"):
            raise ValueError(
                f"method must be 'auto', 'exact' or 'ais', got {method!r}."
            )
        X, sequences = self._check_inference_input(
            X, sequence_ids, "estimate_log_likelihood"
        )
        rng = rng_from(self.random_state if random_state is None else random_state)
        result = self._log_likelihood(
            X, sequences, method=method, reverse=reverse, rng=rng
        )
        return Bunch(**result._asdict())
