"""Greedy layer-wise stack of conditional RBMs (Taylor, Hinton & Roweis 2006, §5)."""

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

from ._crbm import (
    ConditionalRBM,
    _check_count,
    _evenly_spaced,
    _rng_from,
    seed_frames,
)
from ._crbm_math import (
    CRBMParameters,
    dynamic_biases,
    mean_field_prediction,
    visible_means,
)
from .utils._persistence import VersionedPickleMixin
from .utils._sequences import check_sequence_ids, frame_history
from .utils._threads import batch_rows, frame_rows, limit_blas_threads, sequence_rows

__all__ = ["StackedCRBM"]

# Mean-field iterations of the top layer's one-step-ahead prediction (score).
_SCORE_MEAN_FIELD_STEPS = 10
# How many windows of training frames ``fit`` keeps to seed ``sample``.
_MAX_SEED_WINDOWS = 500


def _layer_params(layer, dtype=None):
    """The math module's packed parameters of a fitted ConditionalRBM."""
    return CRBMParameters.from_arrays(
        layer.components_,
        layer.intercept_hidden_,
        layer.intercept_visible_,
        layer.autoregressive_,
        layer.past_to_hidden_,
        layer.visible_type,
        dtype=dtype,
    )


class StackedCRBM(
    VersionedPickleMixin,
    ClassNamePrefixFeaturesOutMixin,
    TransformerMixin,
    BaseEstimator,
):
    """Deep stack of conditional RBMs trained greedily, layer by layer.

    The first layer is a :class:`ConditionalRBM` with Gaussian visible units
    on the data.  Every higher layer is a :class:`ConditionalRBM` with
    binary visible units whose "data" is the sequence of hidden
    probabilities of the layer below, taken over that layer's valid frames
    (the first ``max(order, hidden_order)`` frames of each sequence, which
    lack a full history, are dropped, and ``sequence_ids`` is carried
    along).  All layers share the training hyper-parameters (paper §5;
    Taylor's ``getfilteringdist.m`` and ``binarycrbm.m``).

    Data are in long format: ``X`` stacks all sequences, each contiguous and
    in time order, and ``sequence_ids`` marks which frames belong together.

    Parameters
    ----------
    n_components : int or sequence of int, default=(200, 200)
        Hidden units of each layer, bottom first; an int gives one layer.
    order : int, default=3
        Past frames feeding each layer's visible units (autoregressive
        connections).
    hidden_order : int, default=None
        Past frames feeding each layer's hidden units; ``None`` means
        ``order``.
    learning_rate : float, default=1e-3
        Step size for every parameter group of every layer.
    momentum : float, default=0.9
        Momentum used after the first ``momentum_delay`` epochs.
    momentum_delay : int, default=5
        Number of epochs trained without momentum.
    weight_decay : float, default=2e-4
        L2 penalty on the symmetric and directed weights (not on biases).
    cd_steps : int, default=1
        Number of reconstructions per update (CD-k).
    batch_size : int, default=100
        Frames per minibatch.
    batching : {"balanced", "shuffled"}, default="balanced"
        Minibatch scheme of every layer; see :class:`ConditionalRBM`.
    history_noise : float or sequence of float, default=0.0
        Standard deviation of the Gaussian noise added to the past frames of
        each layer during training (see :class:`ConditionalRBM`); one value
        for every layer, or one per layer, bottom first.  Higher layers see
        hidden probabilities in [0, 1], whose spread is smaller than that of
        standardised data, so they call for smaller values.
    n_iter : int, default=200
        Epochs per layer.
    random_state : int, RandomState instance or None, default=None
        Seeds every layer (each gets its own integer seed drawn from it) and,
        unless ``sample`` is given its own, generation.
    verbose : int, default=0
        Passed to every layer: print progress every ``verbose`` epochs.

    Attributes
    ----------
    layers_ : list of ConditionalRBM
        The fitted layers, bottom (Gaussian visibles) first.
    seed_windows_ : ndarray of shape (n_windows, history_length, n_features)
        Windows of consecutive training frames kept to seed :meth:`sample`.
    random_state_ : RandomState instance
        Random generator that seeded the layers.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    ConditionalRBM : One layer.

    Notes
    -----
    A frame's top-layer representation depends on more of its past than one
    layer's: layer ``k`` looks at ``max(order, hidden_order)`` past frames
    of the representation below, so the whole stack needs
    :attr:`history_length` = the sum of every layer's
    ``max(order, hidden_order)`` past frames (``2 * order`` for two layers).
    :meth:`sample` therefore takes that many seed frames, :meth:`score`
    judges only frames with that much history in their own sequence, and
    :meth:`fit` needs at least one sequence longer than that.

    References
    ----------
    G. W. Taylor, G. E. Hinton and S. Roweis. Modeling Human Motion Using
    Binary Latent Variables. NIPS 19, 2006.

    Examples
    --------
    >>> from sklearn_crbm import StackedCRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, sequence_ids = make_oscillations(n_sequences=4, n_frames=50, random_state=0)
    >>> stack = StackedCRBM((16, 8), order=2, n_iter=10, random_state=0)
    >>> stack.fit(X, sequence_ids=sequence_ids)
    StackedCRBM(n_components=(16, 8), n_iter=10, order=2, random_state=0)
    >>> [layer.visible_type for layer in stack.layers_]
    ['gaussian', 'binary']
    >>> stack.transform(X, sequence_ids=sequence_ids).shape
    (200, 8)
    >>> stack.history_length
    4
    >>> stack.sample(30, n_sequences=3, random_state=0).shape
    (90, 6)
    """

    _parameter_constraints: dict = {
        "n_components": [Interval(Integral, 1, None, closed="left"), "array-like"],
        "order": [Interval(Integral, 0, None, closed="left")],
        "hidden_order": [None, Interval(Integral, 0, None, closed="left")],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
        "momentum": [Interval(Real, 0, 1, closed="left")],
        "momentum_delay": [Interval(Integral, 0, None, closed="left")],
        "weight_decay": [Interval(Real, 0, None, closed="left")],
        "cd_steps": [Interval(Integral, 1, None, closed="left")],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "batching": [StrOptions({"balanced", "shuffled"})],
        "history_noise": [Interval(Real, 0, None, closed="left"), "array-like"],
        "n_iter": [Interval(Integral, 1, None, closed="left")],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    # With sklearn.set_config(enable_metadata_routing=True) a Pipeline or a
    # search passes ``sequence_ids`` to these methods without being asked.
    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__partial_fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}
    __metadata_request__score = {"sequence_ids": True}

    def __init__(
        self,
        n_components=(200, 200),
        *,
        order=3,
        hidden_order=None,
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=100,
        batching="balanced",
        history_noise=0.0,
        n_iter=200,
        random_state=None,
        verbose=0,
    ):
        self.n_components = n_components
        self.order = order
        self.hidden_order = hidden_order
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

    # ------------------------------------------------------------ structure

    def _layer_sizes(self):
        sizes = self.n_components
        if isinstance(sizes, Integral) and not isinstance(sizes, bool):
            return [int(sizes)]
        sizes = list(np.asarray(sizes, dtype=object).ravel())
        if not sizes or not all(
            isinstance(s, Integral) and not isinstance(s, bool) and s >= 1
            for s in sizes
        ):
            raise ValueError(
                "n_components must be a positive int or a non-empty sequence of "
                f"positive ints (hidden units per layer), got {self.n_components!r}."
            )
        return [int(s) for s in sizes]

    @property
    def _n_lags(self):
        hidden_order = self.order if self.hidden_order is None else self.hidden_order
        return max(self.order, hidden_order)

    @property
    def history_length(self):
        """Past frames the whole stack looks at: the sum of its layers' lags.

        :meth:`sample` needs this many seed frames and :meth:`score` judges
        frames with this many past frames in their sequence; ``2 * order``
        for two layers.
        """
        return self._n_lags * len(self._layer_sizes())

    def _history_noises(self, n_layers):
        noise = self.history_noise
        if isinstance(noise, Real) and not isinstance(noise, bool):
            return [float(noise)] * n_layers
        values = list(np.asarray(noise, dtype=object).ravel())
        if len(values) != n_layers or not all(
            isinstance(v, Real) and not isinstance(v, bool) and v >= 0 for v in values
        ):
            raise ValueError(
                "history_noise must be a number >= 0 or one such number per layer "
                f"({n_layers} layers), got {self.history_noise!r}."
            )
        return [float(v) for v in values]

    def _new_layer(self, n_components, visible_type, seed, history_noise):
        return ConditionalRBM(
            n_components,
            order=self.order,
            hidden_order=self.hidden_order,
            visible_type=visible_type,
            learning_rate=self.learning_rate,
            momentum=self.momentum,
            momentum_delay=self.momentum_delay,
            weight_decay=self.weight_decay,
            cd_steps=self.cd_steps,
            batch_size=self.batch_size,
            batching=self.batching,
            history_noise=history_noise,
            n_iter=self.n_iter,
            random_state=seed,
            verbose=self.verbose,
        )

    def _check_fit_input(self, X, sequence_ids, reset):
        X = validate_data(
            self,
            X,
            dtype=[np.float64, np.float32]
            if reset
            else self.layers_[0].components_.dtype,
            reset=reset,
        )
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        needed = self.history_length + 1
        longest = int(sequences.lengths.max()) if len(sequences.lengths) else 0
        if longest < needed:
            noun = "sample" if longest == 1 else "samples"
            raise ValueError(
                f"A stack of {len(self._layer_sizes())} layers of order "
                f"{self._n_lags} needs sequences of at least {needed} frames (each "
                f"layer drops the first {self._n_lags} frames of every sequence), "
                f"but the longest sequence has {longest} {noun}. Pass longer "
                "sequences (check sequence_ids), fewer layers or a lower order."
            )
        return X, sequences

    def _pass_up(self, layer, X, ids):
        """Hidden probabilities of ``layer`` on its valid frames, with their ids."""
        valid = check_sequence_ids(ids, X.shape[0]).valid_frames(layer._n_lags)
        hidden = layer.transform(X, sequence_ids=ids)
        return hidden[valid], ids[valid]

    # ------------------------------------------------------------------ fit

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Train the layers greedily, bottom first.

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
        self : StackedCRBM
            The fitted stack.
        """
        sizes = self._layer_sizes()
        noises = self._history_noises(len(sizes))
        X, sequences = self._check_fit_input(X, sequence_ids, reset=True)
        self.random_state_ = check_random_state(self.random_state)
        ids = sequences.per_frame_ids()
        self.layers_ = []
        data = X
        for k, size in enumerate(sizes):
            seed = int(self.random_state_.randint(np.iinfo(np.int32).max))
            layer = self._new_layer(
                size, "gaussian" if k == 0 else "binary", seed, noises[k]
            )
            layer.fit(data, sequence_ids=ids)
            self.layers_.append(layer)
            if k + 1 < len(sizes):
                data, ids = self._pass_up(layer, data, ids)
        self.seed_windows_ = self._pick_seed_windows(X, sequences)
        return self

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def partial_fit(self, X, y=None, *, sequence_ids=None):
        """Train every layer for one epoch on the given sequences.

        The first call creates the layers.  Each call trains the bottom
        layer for one epoch on ``X``, then each higher layer for one epoch on
        the hidden probabilities of the (just updated) layer below, so that
        repeated calls train all layers together rather than greedily.

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
        self : StackedCRBM
            The updated stack.
        """
        sizes = self._layer_sizes()
        noises = self._history_noises(len(sizes))
        first_call = not hasattr(self, "layers_")
        X, sequences = self._check_fit_input(X, sequence_ids, reset=first_call)
        if first_call:
            self.random_state_ = check_random_state(self.random_state)
            self.layers_ = [
                self._new_layer(
                    size,
                    "gaussian" if k == 0 else "binary",
                    int(self.random_state_.randint(np.iinfo(np.int32).max)),
                    noises[k],
                )
                for k, size in enumerate(sizes)
            ]
        ids = sequences.per_frame_ids()
        data = X
        for k, layer in enumerate(self.layers_):
            layer.partial_fit(data, sequence_ids=ids)
            if k + 1 < len(self.layers_):
                data, ids = self._pass_up(layer, data, ids)
        windows = self._pick_seed_windows(X, sequences)
        if not first_call:
            windows = np.concatenate((self.seed_windows_, windows))
            windows = windows[
                _evenly_spaced(np.arange(len(windows)), _MAX_SEED_WINDOWS)
            ]
        self.seed_windows_ = windows
        return self

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit, then return the top layer's hidden probabilities of ``X``.

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
        H : ndarray of shape (n_frames, n_components[-1])
            As :meth:`transform` gives them.
        """
        return self.fit(X, sequence_ids=sequence_ids).transform(
            X, sequence_ids=sequence_ids
        )

    def _pick_seed_windows(self, X, sequences):
        """Up to ``_MAX_SEED_WINDOWS`` evenly spaced windows of real frames."""
        width = max(self.history_length, 1)
        ends = _evenly_spaced(sequences.valid_frames(width - 1) + 1, _MAX_SEED_WINDOWS)
        rows = ends[:, None] - np.arange(width, 0, -1)
        return X[rows].astype(self.layers_[0].components_.dtype, copy=True)

    # ------------------------------------------------------------ inference

    def _check_inference_input(self, X, sequence_ids):
        check_is_fitted(self)
        X = validate_data(self, X, dtype=[np.float64, np.float32], reset=False)
        X = X.astype(self.layers_[0].components_.dtype, copy=False)
        return X, check_sequence_ids(sequence_ids, X.shape[0])

    def _representations(self, X, sequence_ids):
        """The data, then the hidden probabilities of every layer but the top."""
        representations = [X]
        for layer in self.layers_[:-1]:
            representations.append(
                layer.transform(representations[-1], sequence_ids=sequence_ids)
            )
        return representations

    @limit_blas_threads(frame_rows)
    def transform(self, X, *, sequence_ids=None):
        """Top-layer hidden probabilities of every frame.

        Each layer's hidden probabilities are passed up as the next layer's
        visible data.  Inside a layer, the first ``max(order, hidden_order)``
        frames of each sequence have their missing past frames replaced by
        the sequence's first frame (edge padding), so every frame gets a
        row; a frame's output is exact (as during training) once it has
        :attr:`history_length` past frames in its sequence.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        H : ndarray of shape (n_frames, n_components[-1])
            Hidden probabilities of the top layer, in the dtype of the model.
        """
        X, _ = self._check_inference_input(X, sequence_ids)
        representations = self._representations(X, sequence_ids)
        return self.layers_[-1].transform(
            representations[-1], sequence_ids=sequence_ids
        )

    @limit_blas_threads(frame_rows)
    def predict_next(self, X, *, sequence_ids=None):
        """One-step-ahead prediction of every frame through the whole stack.

        The representations of the past frames are passed up through the
        layers (hidden probabilities); the top layer predicts its visible
        units of frame ``t`` from their history by mean field (as
        :meth:`ConditionalRBM.predict_next` does), and each layer below turns
        the predicted probabilities of its hidden units into its visible
        mean given its own history, down to the data.  Frame ``t`` itself is
        not used.  Frames with fewer than :attr:`history_length` past frames
        in their sequence use edge padding as :meth:`transform` does.

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
        return self._predict_frames(X, sequence_ids, sequences)

    def _predict_frames(self, X, sequence_ids, sequences, frames=None):
        frames = np.arange(X.shape[0]) if frames is None else frames
        representations = self._representations(X, sequence_ids)
        starts = sequences.frame_starts()[frames]
        params = [_layer_params(layer) for layer in self.layers_]
        histories = [
            frame_history(r, frames, p.n_lags, starts)
            for r, p in zip(representations, params, strict=True)
        ]
        top = params[-1]
        visible_bias, hidden_bias = dynamic_biases(top, histories[-1])
        predicted = mean_field_prediction(
            top, visible_bias, hidden_bias, _SCORE_MEAN_FIELD_STEPS
        )
        for p, history in zip(params[-2::-1], histories[-2::-1], strict=True):
            visible_bias, _ = dynamic_biases(p, history)
            predicted = visible_means(p, predicted, visible_bias)
        return predicted

    @limit_blas_threads(frame_rows)
    def score(self, X, y=None, *, sequence_ids=None, sample_weight=None):
        """Negative one-step-ahead prediction error of the stack; higher is better.

        The mean, over every frame with :attr:`history_length` past frames
        in its own sequence and over features, of the squared difference
        between the frame and :meth:`predict_next`'s prediction.  In the
        units of ``X``, like :meth:`ConditionalRBM.score`, so a stack and a
        single layer can be compared on the same held-out sequences (give
        the single layer the same frames, e.g. by scoring both on sequences
        longer than ``history_length``).

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
        frames = sequences.valid_frames(self.history_length)
        if len(frames) == 0:
            raise ValueError(
                f"score needs frames with {self.history_length} past frames in "
                "their own sequence; every sequence given is shorter. Pass longer "
                "sequences."
            )
        weights = None
        if sample_weight is not None:
            weights = _check_sample_weight(sample_weight, X)[frames]
        predicted = self._predict_frames(X, sequence_ids, sequences, frames)
        errors = np.mean(np.square(X[frames] - predicted), axis=1)
        return -float(np.average(errors, weights=weights))

    # ----------------------------------------------------------- generation

    @limit_blas_threads(sequence_rows)
    def sample(
        self,
        n_samples,
        *,
        history=None,
        n_sequences=1,
        n_gibbs=30,
        hidden_noise=0.0,
        random_state=None,
    ):
        """Generate new frames top-down, as the original two-level code did.

        The seed frames are passed up the stack (hidden probabilities of each
        layer over the seed frames that have a full history at that layer).
        The top layer then generates its own sequence with
        :meth:`ConditionalRBM.sample` (each frame started at the previous
        one, ``n_gibbs`` alternating Gibbs iterations, a final mean-field
        step); its visible units are the hidden probabilities of the layer
        below.  Each layer below turns those into its visible means given
        its own generated past, one deterministic pass down to the data
        (Taylor's ``gen2.m``).

        Parameters
        ----------
        n_samples : int
            Number of new frames per sequence.
        history : array-like, default=None
            Seed frames, oldest first; at least :attr:`history_length` frames
            (the sum of every layer's ``max(order, hidden_order)``, so
            ``2 * order`` for two layers), of which the last that many are
            used.  Shape ``(n_frames, n_features)`` seeds every sequence
            alike; shape ``(n_sequences, n_frames, n_features)`` gives each
            sequence its own seed.  ``None`` draws windows of real training
            frames kept by :meth:`fit` (``seed_windows_``).
        n_sequences : int, default=1
            Number of sequences to generate; with a 3-D ``history`` it is
            taken from the history.
        n_gibbs : int, default=30
            Alternating Gibbs iterations per frame in the top layer.
        hidden_noise : float, default=0.0
            Standard deviation of Gaussian noise added to the top layer's
            hidden biases each time its hidden states are chosen (paper
            §4.3).
        random_state : int, RandomState instance or None, default=None
            Seeds the generation; ``None`` uses the estimator's
            ``random_state``.

        Returns
        -------
        X_new : ndarray of shape (n_sequences * n_samples, n_features)
            The generated frames only (not the seed), in long format: rows
            ``k * n_samples`` to ``(k + 1) * n_samples - 1`` are sequence
            ``k``.
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
            width=max(self.history_length, 1),
            n_features=self.n_features_in_,
            dtype=self.layers_[0].components_.dtype,
            seed_windows=self.seed_windows_,
            rng=rng,
        )
        n_sequences, width, n_features = seed.shape

        # Pass the seed up: level k holds the frames of layer k's visibles
        # that have a full history at every layer below.
        levels = [seed]
        for layer in self.layers_[:-1]:
            below = levels[-1]
            flat = below.reshape(-1, below.shape[2])
            ids = np.repeat(np.arange(n_sequences), below.shape[1])
            hidden = layer.transform(flat, sequence_ids=ids)
            hidden = hidden.reshape(n_sequences, below.shape[1], -1)
            levels.append(np.ascontiguousarray(hidden[:, layer._n_lags :]))

        top = self.layers_[-1]
        generated = top.sample(
            n_samples,
            history=levels[-1],
            n_gibbs=n_gibbs,
            hidden_noise=hidden_noise,
            random_state=int(rng.integers(np.iinfo(np.int32).max)),
        ).reshape(n_sequences, n_samples, -1)

        for layer, past in zip(self.layers_[-2::-1], levels[-2::-1], strict=True):
            generated = self._pass_down(layer, past, generated)
        return generated.reshape(n_sequences * n_samples, n_features)

    @staticmethod
    def _pass_down(layer, past, hidden):
        """Visible means of ``layer`` given generated hidden probabilities.

        ``past`` (n_sequences, n_past, n_visible) holds the layer's visible
        frames before the first generated one; each new frame's dynamic
        visible bias comes from the frames before it, generated ones
        included.
        """
        params = _layer_params(layer)
        n_sequences, n_samples, _ = hidden.shape
        n_lags = params.n_lags
        n_visible = past.shape[2]
        frames = np.empty(
            (n_sequences, n_lags + n_samples, n_visible), dtype=past.dtype
        )
        frames[:, :n_lags] = past[:, past.shape[1] - n_lags :]
        for t in range(n_samples):
            history = frames[:, t : t + n_lags][:, ::-1].reshape(n_sequences, -1)
            visible_bias, _ = dynamic_biases(params, history)
            frames[:, n_lags + t] = visible_means(params, hidden[:, t], visible_bias)
        return frames[:, n_lags:]

    # ---------------------------------------------------------------- misc

    @property
    def _n_features_out(self):
        return self.layers_[-1].components_.shape[0]

    def __sklearn_is_fitted__(self):
        # a fit that failed part-way leaves no layers: still "not fitted"
        return hasattr(self, "layers_") and hasattr(self, "seed_windows_")

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.transformer_tags.preserves_dtype = ["float64", "float32"]
        return tags
