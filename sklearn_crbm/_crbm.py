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
    ParameterAverage,
    add_history_noise,
    cd_gradients,
    shift_centred,
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

    Models each frame with Gaussian or binary visible units and binary hidden
    units, conditioned on the previous frames of its sequence through
    autoregressive and past-to-hidden weights (Taylor, Hinton & Roweis, 2006).
    ``X`` stacks all sequences; ``sequence_ids`` marks the frames of each.

    Read more in the :ref:`User Guide <training>`.

    Parameters
    ----------
    n_components : int, default=200
        Number of binary hidden units.
    order : int, default=3
        Number of past frames feeding the visible units (0, 0: a plain RBM).
    hidden_order : int, default=None
        Number of past frames feeding the hidden units; ``None`` means ``order``.
    visible_type : {"gaussian", "binary"}, default="gaussian"
        Gaussian units for standardised data, binary units for data in [0, 1].
    visible_variance : {"unit", "learned", "residual"}, default="unit"
        Variance of the Gaussian visibles: 1 (the paper's), trained per channel,
        or fixed at the one-step residual of a ridge AR(``order``) per channel.
    init : {"random", "autoregressive"}, default="random"
        Small random weights (the original code's), or start the autoregressive
        part (and learned variances) from that ridge AR.
    centering : bool, default=False
        Take the gradient steps as if the hidden units saw the residual
        ``(v - c_hat) / s`` of the frame against its dynamic visible mean.
    learning_rate : float, default=1e-3
        Step size for every parameter group.
    momentum : float, default=0.9
        Momentum used after the first ``momentum_delay`` epochs.
    momentum_delay : int, default=5
        Number of epochs trained without momentum.
    weight_decay : float, default=2e-4
        L2 penalty on the symmetric and directed weights (not on biases).
    cd_steps : int, default=1
        Number of alternating Gibbs steps per reconstruction (CD-k).
    batch_size : int, default=100
        Frames per minibatch.
    batching : {"balanced", "shuffled"}, default="balanced"
        The paper's minibatches (one frame from each consecutive chunk of the
        data) or the released code's (all frames shuffled every epoch).
    history_noise : float, default=1.0
        Standard deviation of Gaussian noise added, in training only, to the
        past frames (keeps generated motion in its style); ``0``: the paper's.
    history_noise_fraction : float in (0, 1], default=0.5
        Probability with which each channel of a frame's history gets that
        noise (the same at every lag); the other channels stay clean.
    average_fraction : float in [0, 1), default=0.25
        :meth:`fit` keeps the mean of the parameters over this fraction of
        its last epochs (Polyak-Ruppert averaging); ``0``: the last epoch's.
    n_iter : int, default=1000
        Number of epochs (passes over the trainable frames).
    ais_steps : int, default=50
        Annealing steps of :meth:`score` where enumeration would cost more.
    ais_chains : int, default=2
        Annealing chains per frame.
    early_stopping : bool, default=False
        Hold out whole sequences in :meth:`fit`; keep the best-scoring epoch.
    validation_fraction : float, default=0.1
        Fraction of the frames, in whole sequences, held out.
    n_iter_no_change : int, default=50
        Epochs without an improvement of ``tol`` that stop training.
    validation_interval : int, default=10
        Epochs between two validation scores.
    tol : float, default=1e-3
        Improvement of the validation score, in nats per frame, that counts.
    random_state : int, RandomState instance or None, default=None
        Seeds training and, unless :meth:`sample` is given its own, generation.
    verbose : int, default=0
        Print the epoch, reconstruction error and time every ``verbose`` epochs.

    Attributes
    ----------
    components_ : ndarray of shape (n_components, n_features)
        Symmetric weights ``W`` between hidden and visible units.
    intercept_hidden_ : ndarray of shape (n_components,)
        Static hidden biases.
    intercept_visible_ : ndarray of shape (n_features,)
        Static visible biases.
    autoregressive_ : ndarray of shape (order, n_features, n_features)
        ``autoregressive_[q - 1] @ x[t - q]`` adds to frame ``t``'s visible mean.
    past_to_hidden_ : ndarray of shape (hidden_order, n_components, n_features)
        ``past_to_hidden_[q - 1] @ x[t - q]`` adds to frame ``t``'s hidden input.
    visible_variance_ : ndarray of shape (n_features,)
        Variance of each Gaussian visible unit (ones for ``"unit"``).
    seed_windows_ : ndarray of shape (n_windows, width, n_features)
        Windows of consecutive training frames that seed :meth:`sample`.
    reconstruction_error_ : float
        Mean squared reconstruction error per frame in the last epoch.
    random_state_ : RandomState instance
        Random generator state carried across :meth:`partial_fit` calls.
    n_iter_ : int
        Number of epochs trained so far.
    validation_scores_ : list of float
        With ``early_stopping``: the held-out score at every validation.
    best_validation_score_ : float
        With ``early_stopping``: the best of them, that of the parameters kept.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    StackedCRBM : Greedy layer-wise stack of conditional RBMs.

    References
    ----------
    G. W. Taylor, G. E. Hinton and S. Roweis. Modeling Human Motion Using
    Binary Latent Variables. NIPS 19, 2006.

    Examples
    --------
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, sequence_ids = make_oscillations(n_sequences=4, n_frames=50, random_state=0)
    >>> model = ConditionalRBM(n_components=16, order=2, n_iter=20, random_state=0)
    >>> model.fit(X, sequence_ids=sequence_ids)
    ConditionalRBM(n_components=16, n_iter=20, order=2, random_state=0)
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
        "visible_variance": [StrOptions({"unit", "learned", "residual"})],
        "init": [StrOptions({"random", "autoregressive"})],
        "centering": ["boolean"],
        "history_noise_fraction": [Interval(Real, 0, 1, closed="right")],
        "average_fraction": [Interval(Real, 0, 1, closed="left")],
    }

    _added_parameters = {
        "centering": False,
        "history_noise_fraction": 1.0,
        "average_fraction": 0.0,
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
        centering=False,
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=100,
        batching="balanced",
        history_noise=1.0,
        history_noise_fraction=0.5,
        average_fraction=0.25,
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
        self.centering = centering
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.momentum_delay = momentum_delay
        self.weight_decay = weight_decay
        self.cd_steps = cd_steps
        self.batch_size = batch_size
        self.batching = batching
        self.history_noise = history_noise
        self.history_noise_fraction = history_noise_fraction
        self.average_fraction = average_fraction
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

    # The training of the paper and of its released code.
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
        history_noise_fraction=1.0,
        average_fraction=0.0,
        visible_variance="unit",
        centering=False,
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
        experiments reproducible.

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
                n_averaged = math.ceil(self.average_fraction * self.n_iter)
                self._train(X, frames, self.n_iter, n_averaged)
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
        if self.visible_type == BINARY and self.visible_variance != "unit":
            raise ValueError(
                f"visible_variance={self.visible_variance!r} needs Gaussian "
                "visibles; binary visibles have no variance. Use "
                "visible_variance='unit'."
            )
        if self.centering and self.visible_type == BINARY:
            raise ValueError(
                "centering=True centres the hidden units' input on the Gaussian "
                "visible mean and needs Gaussian visibles. Use centering=False "
                "with binary visibles."
            )
        if self.centering and self._hidden_order < self.order:
            raise ValueError(
                f"centering=True needs hidden_order >= order (got hidden_order="
                f"{self._hidden_order}, order={self.order}): the centred hidden "
                "input is written back through the past-to-hidden weights of every "
                "autoregressive lag. Raise hidden_order or use centering=False."
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
            fixed_variance=self.visible_variance == "residual",
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
        """Start from the ridge AR of ``frames`` where the parameters ask for it.

        ``init="autoregressive"`` sets the autoregressive weights, the
        visible biases and (learned variances) the visible variances; the
        other groups keep their random start.  ``visible_variance="residual"``
        sets the visible variances, whatever ``init``.
        """
        residual = self.visible_variance == "residual"
        if self.init != "autoregressive" and not residual:
            return
        if not isinstance(X, np.ndarray):  # array API input: fitted with numpy
            X = _convert_to_numpy(X, array_api_compat.array_namespace(X))
        fit = ridge_autoregression(
            X.astype(np.float64), frames, self.order, _AUTOREGRESSIVE_ALPHA
        )
        if self.init == "autoregressive":
            self.autoregressive_ = fit.coef.astype(X.dtype)
            self.intercept_visible_ = fit.intercept.astype(X.dtype)
        learned = self._parameters.learned_variance
        if residual or (learned and self.init == "autoregressive"):
            variance = np.mean(np.square(fit.residual), axis=0)
            self.visible_variance_ = np.maximum(
                variance, np.exp(MIN_LOG_VARIANCE)
            ).astype(X.dtype)

    # Diverging weights overflow in the products before the epoch's check
    # raises TrainingDivergedError, which says what to do.
    @np.errstate(over="ignore", invalid="ignore")
    def _train(self, X, frames, n_epochs, n_averaged=0):
        """``n_epochs`` epochs of CD; the parameters kept are the mean of those
        at the ends of the last ``n_averaged`` epochs (0: the last epoch's)."""
        # trained in the layout BLAS runs fastest, kept in C order when fitted
        params = self._parameters.copy(layout="F")
        if self.centering:  # trained in centred coordinates, kept in the standard form
            shift_centred(params, 1)
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
        average = ParameterAverage()
        start = time.perf_counter()
        for epoch in range(n_epochs):
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
                    add_history_noise(
                        math_rng,
                        batch_history,
                        self.history_noise,
                        X.shape[1],
                        self.history_noise_fraction,
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
                    centered=self.centering,
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
                self._parameters = self._standard_form(params)
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
            if epoch >= n_epochs - n_averaged:
                average.add(self._standard_form(params))
        self._parameters = (
            average.mean if average.count else self._standard_form(params)
        )

    def _standard_form(self, params):
        """The trained parameters as the fitted model keeps them (C order)."""
        params = params.copy(layout="C")
        return shift_centred(params, -1) if self.centering else params

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
        -5.67 -5.67
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
