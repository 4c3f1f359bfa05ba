"""Conditional Restricted Boltzmann Machine (Taylor, Hinton & Roweis, 2006)."""

import time
from numbers import Integral, Real

import numpy as np
from sklearn.base import (
    BaseEstimator,
    ClassNamePrefixFeaturesOutMixin,
    TransformerMixin,
    _fit_context,
)
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import (
    _check_sample_weight,
    check_is_fitted,
    validate_data,
)

from ._crbm_math import (
    BINARY,
    CDWorkspace,
    CRBMParameters,
    MomentumUpdate,
    cd_gradients,
    dynamic_biases,
    free_energy,
    gibbs_frames,
    hidden_probabilities,
    mean_field_prediction,
)
from .utils._fitting import unfitted_on_error
from .utils._parallel import map_sequence_blocks
from .utils._persistence import VersionedPickleMixin
from .utils._sequences import (
    balanced_batches,
    check_sequence_ids,
    frame_history,
    shuffled_batches,
)

# Frames processed at once by transform / score: bounds the gathered history.
_CHUNK_FRAMES = 4096
# How many windows of training frames ``fit`` keeps to seed ``sample``.
_MAX_SEED_WINDOWS = 500
# Mean-field iterations of the one-step-ahead prediction behind ``score``.
_SCORE_MEAN_FIELD_STEPS = 10
# Sequences generated together in one vectorised pass by ``sample``: one
# frame of 100 sequences costs little more than one of 1, so blocks are large.
_SAMPLE_BLOCK = 256
# Standard deviation of the jitter added to the previous frame to start the
# Gibbs chain of a new frame (REFERENCE.md, gen.m).
_START_JITTER = 0.01


class TrainingDivergedError(FloatingPointError):
    """Training produced non-finite weights (the learning rate is too large)."""


def _rng_from(random_state):
    """A numpy Generator (fast float32 draws) seeded from a sklearn random_state."""
    seed = check_random_state(random_state).randint(np.iinfo(np.int32).max)
    return np.random.default_rng(seed)


class ConditionalRBM(
    VersionedPickleMixin,
    ClassNamePrefixFeaturesOutMixin,
    TransformerMixin,
    BaseEstimator,
):
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
    n_components : int, default=100
        Number of binary hidden units.
    order : int, default=3
        Number of past frames feeding the visible units (autoregressive
        connections).  ``order=0`` together with ``hidden_order=0`` is a plain
        RBM.
    hidden_order : int, default=None
        Number of past frames feeding the hidden units; ``None`` means
        ``order``.
    visible_type : {"gaussian", "binary"}, default="gaussian"
        Gaussian visible units with fixed unit variance (standardise the data
        first, e.g. with :class:`~sklearn_crbm.preprocessing.StandardScaler`),
        or binary/probability visible units for data in ``[0, 1]``.
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
        motion: every one of five training seeds then generates walks and
        jogs that keep their style and their leg movement
        (``benchmarks/generation_seeds.py``), at the price of a larger
        one-step prediction error.
    n_iter : int, default=200
        Number of epochs (passes over the trainable frames).
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
        frame ``t``.
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
    >>> model.transform(X, sequence_ids=sequence_ids).shape
    (200, 16)
    >>> model.sample(30, n_sequences=3, random_state=0).shape
    (90, 6)
    """

    _parameter_constraints: dict = {
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "order": [Interval(Integral, 0, None, closed="left")],
        "hidden_order": [None, Interval(Integral, 0, None, closed="left")],
        "visible_type": [StrOptions({"gaussian", "binary"})],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
        "momentum": [Interval(Real, 0, 1, closed="left")],
        "momentum_delay": [Interval(Integral, 0, None, closed="left")],
        "weight_decay": [Interval(Real, 0, None, closed="left")],
        "cd_steps": [Interval(Integral, 1, None, closed="left")],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "batching": [StrOptions({"balanced", "shuffled"})],
        "history_noise": [Interval(Real, 0, None, closed="left")],
        "n_iter": [Interval(Integral, 1, None, closed="left")],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    # Private state that a failed fit must forget with the fitted attributes.
    _training_state = ("_velocities",)

    # With sklearn.set_config(enable_metadata_routing=True) a Pipeline or a
    # search passes ``sequence_ids`` to these methods without being asked.
    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__partial_fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}
    __metadata_request__score = {"sequence_ids": True}

    def __init__(
        self,
        n_components=100,
        *,
        order=3,
        hidden_order=None,
        visible_type="gaussian",
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=100,
        batching="balanced",
        history_noise=0.8,
        n_iter=200,
        random_state=None,
        verbose=0,
    ):
        self.n_components = n_components
        self.order = order
        self.hidden_order = hidden_order
        self.visible_type = visible_type
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.momentum_delay = momentum_delay
        self.weight_decay = weight_decay
        self.cd_steps = cd_steps
        self.batch_size = batch_size
        self.batching = batching
        self.history_noise = history_noise
        self.n_iter = n_iter
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
            X = validate_data(self, X, dtype=[np.float64, np.float32], reset=True)
            sequences, frames = self._check_sequences(X, sequence_ids)
            self.random_state_ = check_random_state(self.random_state)
            self._initialize(X.shape[1], X.dtype)
            self._train(X, frames, self.n_iter)
            self.seed_windows_ = self._pick_seed_windows(X, sequences)
        return self

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
            X = validate_data(
                self,
                X,
                dtype=[np.float64, np.float32]
                if first_call
                else self.components_.dtype,
                reset=first_call,
            )
            sequences, frames = self._check_sequences(X, sequence_ids)
        with unfitted_on_error(self):
            if first_call:
                self.random_state_ = check_random_state(self.random_state)
                self._initialize(X.shape[1], X.dtype)
            self._train(X, frames, 1)
        new_windows = self._pick_seed_windows(X, sequences)
        if not first_call:
            new_windows = self._merge_seed_windows(self.seed_windows_, new_windows)
        self.seed_windows_ = new_windows
        return self

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit, then return the hidden probabilities of ``X``.

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
        H : ndarray of shape (n_frames, n_components)
            Hidden probabilities, as :meth:`transform` gives them.
        """
        return self.fit(X, sequence_ids=sequence_ids).transform(
            X, sequence_ids=sequence_ids
        )

    @property
    def _n_lags(self):
        return max(self.order, self._hidden_order)

    @property
    def _hidden_order(self):
        return self.order if self.hidden_order is None else self.hidden_order

    def _check_sequences(self, X, sequence_ids):
        """Validate ids and visible type; return the sequences and trainable frames."""
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        if self.visible_type == BINARY and (X.min() < 0 or X.max() > 1):
            raise ValueError(
                "visible_type='binary' needs data in [0, 1] (binary values or "
                f"probabilities); got values in [{X.min():g}, {X.max():g}]. Use "
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

    def _initialize(self, n_features, dtype):
        params = CRBMParameters.initialize(
            n_features,
            self.n_components,
            self.order,
            self._hidden_order,
            self.visible_type,
            dtype,
            _rng_from(self.random_state_),
        )
        self._velocities = [np.zeros_like(a) for a in params.arrays()]
        self.n_iter_ = 0
        self._store(params)

    def _params(self, dtype=None):
        """Pack the public fitted attributes for the math module."""
        return CRBMParameters.from_arrays(
            self.components_,
            self.intercept_hidden_,
            self.intercept_visible_,
            self.autoregressive_,
            self.past_to_hidden_,
            self.visible_type,
            dtype=dtype,
        )

    def _store(self, params):
        self.components_ = params.weights
        self.intercept_hidden_ = params.hidden_bias
        self.intercept_visible_ = params.visible_bias
        self.autoregressive_ = params.autoregressive()
        self.past_to_hidden_ = params.past_to_hidden()

    def _train(self, X, frames, n_epochs):
        params = self._params()
        # params' arrays become views of one buffer, updated in place
        update = MomentumUpdate(params, self._velocities)
        self._velocities = list(update.velocities)
        # Minibatches gather rows: from a Fortran-ordered X (what many
        # transformers return) every row would be a strided read.
        X = np.ascontiguousarray(X)
        plan_batches = (
            balanced_batches if self.batching == "balanced" else shuffled_batches
        )
        n_lags = params.n_lags
        # Buffers reused by every minibatch
        workspace = CDWorkspace(params, self.batch_size)
        start = time.perf_counter()
        for _ in range(n_epochs):
            rng = _rng_from(self.random_state_)
            momentum = self.momentum if self.n_iter_ >= self.momentum_delay else 0.0
            squared_error = 0.0
            for batch in plan_batches(frames, self.batch_size, rng):
                n = len(batch)
                visible = np.take(
                    X, batch, axis=0, out=workspace.visible(n), mode="clip"
                )
                batch_history = frame_history(
                    X, batch, n_lags, out=workspace.history[:n]
                )
                if self.history_noise:
                    batch_history += self.history_noise * rng.standard_normal(
                        batch_history.shape, dtype=batch_history.dtype
                    )
                _, error = cd_gradients(
                    params,
                    visible,
                    batch_history,
                    self.cd_steps,
                    rng,
                    out=update.statistics,
                    scale=self.learning_rate / n,
                    workspace=workspace,
                )
                squared_error += error
                update.apply(momentum, self.learning_rate, self.weight_decay)
            self.n_iter_ += 1
            self.reconstruction_error_ = squared_error / len(frames)
            if not params.is_finite() or not np.isfinite(squared_error):
                self._store(_c_ordered(params))
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
        self._store(_c_ordered(params))

    def _pick_seed_windows(self, X, sequences):
        """Keep up to ``_MAX_SEED_WINDOWS`` evenly spaced windows of real frames.

        Deterministic (no random draws), so that seeding ``sample`` does not
        disturb the training random stream.
        """
        width = max(self._n_lags, 1)
        ends = _evenly_spaced(sequences.valid_frames(width - 1) + 1, _MAX_SEED_WINDOWS)
        rows = ends[:, None] - np.arange(width, 0, -1)
        return X[rows].astype(self.components_.dtype, copy=True)

    @staticmethod
    def _merge_seed_windows(old, new):
        windows = np.concatenate((old, new))
        return windows[_evenly_spaced(np.arange(len(windows)), _MAX_SEED_WINDOWS)]

    # ------------------------------------------------------------ inference

    def _check_inference_input(self, X, sequence_ids):
        check_is_fitted(self)
        X = validate_data(self, X, dtype=[np.float64, np.float32], reset=False)
        X = X.astype(self.components_.dtype, copy=False)
        return X, check_sequence_ids(sequence_ids, X.shape[0])

    def _iter_dynamic_biases(self, params, X, sequences, frames=None, padded=True):
        """Yield ``(rows, visible_bias, hidden_bias)`` chunk by chunk.

        With ``padded=True`` a lag reaching before the start of a sequence
        reads the sequence's first frame instead.
        """
        frames = np.arange(X.shape[0]) if frames is None else frames
        starts = sequences.frame_starts() if padded else None
        for lo in range(0, len(frames), _CHUNK_FRAMES):
            rows = frames[lo : lo + _CHUNK_FRAMES]
            history = frame_history(
                X, rows, params.n_lags, None if starts is None else starts[rows]
            )
            yield (rows, *dynamic_biases(params, history))

    def transform(self, X, *, sequence_ids=None):
        """Hidden probabilities ``p(h = 1 | x_t, history)`` of every frame.

        For the first ``max(order, hidden_order)`` frames of each sequence the
        missing past frames are replaced by the sequence's first frame (edge
        padding), so every frame gets a row.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        H : ndarray of shape (n_frames, n_components)
            Hidden probabilities, in the dtype of the model.
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        params = self._params()
        hidden = np.empty((X.shape[0], self.n_components), dtype=X.dtype)
        for rows, _, hidden_bias in self._iter_dynamic_biases(params, X, sequences):
            hidden[rows] = hidden_probabilities(params, X[rows], hidden_bias)
        return hidden

    def score_samples(self, X, *, sequence_ids=None):
        """Negative free energy ``-F(x_t | history)`` of every frame.

        ``exp(-F)`` is proportional to ``p(x_t | history)``; the constant of
        proportionality depends on the history and on the model, so compare
        values of one model on different frames, not across models (use
        :meth:`score` for that).  For the first ``max(order, hidden_order)``
        frames of each sequence the missing past frames are replaced by the
        sequence's first frame (edge padding).

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        scores : ndarray of shape (n_frames,)
            Negative free energy of each frame.
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        params = self._params()
        scores = np.empty(X.shape[0], dtype=X.dtype)
        for rows, visible_bias, hidden_bias in self._iter_dynamic_biases(
            params, X, sequences
        ):
            scores[rows] = -free_energy(params, X[rows], visible_bias, hidden_bias)
        return scores

    def predict_next(self, X, *, sequence_ids=None):
        """One-step-ahead prediction of every frame from its history alone.

        The prediction is a deterministic estimate of ``E[x_t | history]``:
        starting from the autoregressive mean, hidden probabilities and
        visible means are alternated ten times (mean field).  The frame
        itself is not used.  For the first ``max(order, hidden_order)`` frames
        of each sequence the missing past frames are replaced by the
        sequence's first frame (edge padding).

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        X_pred : ndarray of shape (n_frames, n_features)
            Predicted frames.
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        return self._predict_frames(self._params(), X, sequences)

    def _predict_frames(self, params, X, sequences, frames=None):
        frames = np.arange(X.shape[0]) if frames is None else frames
        predicted = np.empty((len(frames), X.shape[1]), dtype=X.dtype)
        position = 0
        for rows, visible_bias, hidden_bias in self._iter_dynamic_biases(
            params, X, sequences, frames
        ):
            predicted[position : position + len(rows)] = mean_field_prediction(
                params, visible_bias, hidden_bias, _SCORE_MEAN_FIELD_STEPS
            )
            position += len(rows)
        return predicted

    def score(self, X, y=None, *, sequence_ids=None, sample_weight=None):
        """Negative one-step-ahead prediction error; higher is better.

        The mean, over every frame that has a complete history in its own
        sequence and over features, of the squared difference between the
        frame and :meth:`predict_next`'s prediction from its history.  It is
        measured in the units of ``X`` (standardised data: fractions of a
        standard deviation), so models with any ``n_components``, ``order``
        or ``hidden_order`` can be compared on held-out sequences, e.g. by
        ``GridSearchCV(scoring=None)``.  A model without history
        (``order=0``) predicts the same frame everywhere and scores like a
        constant prediction.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        sample_weight : array-like of shape (n_frames,), default=None
            Weight of each frame in the mean; frames without a full history
            are left out whatever their weight.

        Returns
        -------
        score : float
            Negative mean squared one-step-ahead prediction error.
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        frames = sequences.valid_frames(self._n_lags)
        if len(frames) == 0:
            raise ValueError(
                f"score needs frames with {self._n_lags} past frames in their own "
                "sequence; every sequence given is shorter. Pass longer sequences."
            )
        weights = None
        if sample_weight is not None:
            weights = _check_sample_weight(sample_weight, X)[frames]
        predicted = self._predict_frames(self._params(), X, sequences, frames)
        errors = np.mean(np.square(X[frames] - predicted), axis=1)
        return -float(np.average(errors, weights=weights))

    # ----------------------------------------------------------- generation

    def sample(
        self,
        n_samples,
        *,
        history=None,
        n_sequences=1,
        n_gibbs=30,
        hidden_noise=0.0,
        sample_visibles=False,
        random_state=None,
        n_jobs=None,
    ):
        """Generate new frames by alternating Gibbs sampling (paper §4).

        Each new frame starts from the previous frame plus N(0, 0.01^2)
        jitter; ``n_gibbs`` alternating Gibbs iterations follow (hidden units
        sampled, visibles set to their mean), then one mean-field step with
        hidden probabilities.  All sequences are generated together.

        Parameters
        ----------
        n_samples : int
            Number of new frames per sequence.
        history : array-like, default=None
            Seed frames, oldest first: shape ``(n_frames, n_features)`` seeds
            every sequence with its last ``max(order, hidden_order, 1)`` rows;
            shape ``(n_sequences, n_frames, n_features)`` gives each sequence
            its own seed.  ``None`` draws windows of real training frames kept
            by :meth:`fit` (``seed_windows_``).
        n_sequences : int, default=1
            Number of sequences to generate; with a 3-D ``history`` it is
            taken from the history.
        n_gibbs : int, default=30
            Alternating Gibbs iterations per frame.
        hidden_noise : float, default=0.0
            Standard deviation of Gaussian noise added to the hidden biases
            each time hidden states are chosen (paper §4.3: transitions
            between styles).
        sample_visibles : bool, default=False
            If True, the visibles are drawn from ``p(v | h, history)`` at every
            Gibbs step (Gaussian noise of unit variance, or binary states) and
            each new frame is the last draw: an exact Gibbs sampler whose
            frames follow ``p(x_t | history)`` when ``n_gibbs`` is large.  The
            default keeps the original code's scheme (visible means, then a
            mean-field step), which gives smoother motion.
        random_state : int, RandomState instance or None, default=None
            Seeds the generation; ``None`` uses the estimator's
            ``random_state``, so repeated calls give the same frames when
            that is an int.
        n_jobs : int, default=None
            Number of jobs generating blocks of 256 sequences in parallel
            (joblib; ``None`` means 1 unless in a
            :obj:`joblib.parallel_backend` context).  Up to 256 sequences are
            generated together in one vectorised pass; the blocks and their
            random streams depend on ``n_sequences`` only, so the frames are
            the same for any ``n_jobs``.

        Returns
        -------
        X_new : ndarray of shape (n_sequences * n_samples, n_features)
            The generated frames only (not the seed), in long format:
            rows ``k * n_samples`` to ``(k + 1) * n_samples - 1`` are
            sequence ``k``.
        """
        check_is_fitted(self)
        n_samples = _check_count(n_samples, "n_samples", minimum=1)
        n_gibbs = _check_count(n_gibbs, "n_gibbs", minimum=0)
        n_sequences = _check_count(n_sequences, "n_sequences", minimum=1)
        if not isinstance(hidden_noise, Real) or not hidden_noise >= 0:
            raise ValueError(
                f"hidden_noise must be a non-negative number, got {hidden_noise!r}."
            )
        rng = _rng_from(self.random_state if random_state is None else random_state)
        seed = seed_frames(
            history,
            n_sequences,
            width=max(self._n_lags, 1),
            n_features=self.n_features_in_,
            dtype=self.components_.dtype,
            seed_windows=self.seed_windows_,
            rng=rng,
        )
        params = self._params()

        def generate_block(block, block_rng):
            return self._generate(
                params,
                seed[block],
                n_samples,
                n_gibbs,
                hidden_noise,
                sample_visibles,
                block_rng,
            )

        blocks = map_sequence_blocks(
            generate_block, len(seed), rng, n_jobs, block_size=_SAMPLE_BLOCK
        )
        return np.concatenate(blocks).reshape(-1, self.n_features_in_)

    def _generate(
        self, params, seed, n_samples, n_gibbs, hidden_noise, sample_visibles, rng
    ):
        n_sequences, width, n_features = seed.shape
        n_lags = params.n_lags
        frames = np.empty(
            (n_sequences, width + n_samples, n_features), dtype=seed.dtype
        )
        frames[:, :width] = seed
        for t in range(width, width + n_samples):
            history = frames[:, t - n_lags : t][:, ::-1].reshape(
                n_sequences, n_lags * n_features
            )
            visible_bias, hidden_bias = dynamic_biases(params, history)
            start = frames[:, t - 1] + _START_JITTER * rng.standard_normal(
                (n_sequences, n_features), dtype=seed.dtype
            )
            frames[:, t] = gibbs_frames(
                params,
                start,
                visible_bias,
                hidden_bias,
                n_gibbs,
                rng,
                hidden_noise=hidden_noise,
                sample_visibles=sample_visibles,
            )
        return frames[:, width:]

    # ---------------------------------------------------------------- misc

    @property
    def _n_features_out(self):
        return self.components_.shape[0]

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.transformer_tags.preserves_dtype = ["float64", "float32"]
        return tags


def _c_ordered(params):
    """``params`` with arrays of their own (2-D ones in C order), as fitted.

    During training they are views of one buffer (``MomentumUpdate``).
    """
    params.weights = np.ascontiguousarray(params.weights)
    params.dynamic = np.ascontiguousarray(params.dynamic)
    params.hidden_bias = params.hidden_bias.copy()
    params.visible_bias = params.visible_bias.copy()
    return params


def seed_frames(history, n_sequences, *, width, n_features, dtype, seed_windows, rng):
    """Check a ``sample`` history; seeds of shape (n_sequences, width, n_features).

    ``None`` draws windows of real training frames from ``seed_windows``; a
    2-D history seeds every sequence with its last ``width`` rows; a 3-D one
    gives one seed per sequence.  Oldest frame first.
    """
    if history is None:
        picks = rng.integers(len(seed_windows), size=n_sequences)
        return seed_windows[picks]
    if hasattr(history, "toarray") or hasattr(history, "tocsr"):
        raise TypeError("history must be a dense array, got a sparse matrix.")
    try:
        history = np.asarray(history, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"history must be an array of numbers, got {type(history).__name__}."
        ) from exc
    if history.ndim == 2:
        history = np.broadcast_to(history, (n_sequences, *history.shape))
    elif history.ndim == 3:
        if n_sequences not in (1, history.shape[0]):
            raise ValueError(
                f"history holds {history.shape[0]} seeds but n_sequences="
                f"{n_sequences}; give one seed per sequence or a 2-D history."
            )
    else:
        raise ValueError(
            "history must have shape (n_frames, n_features) or (n_sequences, "
            f"n_frames, n_features), got shape {history.shape}."
        )
    if history.shape[2] != n_features or history.shape[1] < width:
        raise ValueError(
            f"history must hold at least {width} frames of {n_features} features "
            f"each, got shape {history.shape}."
        )
    if not np.isfinite(history).all():
        raise ValueError("history contains NaN or infinity.")
    return np.ascontiguousarray(history[:, -width:])


def _evenly_spaced(values, at_most):
    if len(values) <= at_most:
        return values
    return values[np.linspace(0, len(values) - 1, at_most).round().astype(np.intp)]


def _check_count(value, name, minimum):
    if isinstance(value, bool) or not isinstance(value, Integral) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}.")
    return int(value)
