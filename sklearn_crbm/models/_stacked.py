"""Greedy layer-wise stack of conditional RBMs (Taylor, Hinton & Roweis 2006, §5)."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context, clone
from sklearn.utils import check_random_state, get_tags
from sklearn.utils._array_api import get_namespace
from sklearn.utils._param_validation import HasMethods, Interval
from sklearn.utils.validation import validate_data

from ..utils._array_api import array_ops
from ..utils._random import rng_from
from ..utils._sequences import check_sequence_ids
from ..utils._threads import batch_rows, limit_blas_threads
from ._base import BaseCRBM
from ._crbm import ConditionalRBM
from ._label_factors import as_entries

__all__ = ["StackedCRBM"]


class StackedCRBM(BaseCRBM):
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
    history_noise_fraction : float in (0, 1], default=1.0
        Probability with which each channel of a training frame's history
        gets that noise, in every layer (see :class:`ConditionalRBM`, whose
        default is 0.5); ``1`` noises every channel.
    average_fraction : float in [0, 1), default=0.0
        Every layer's :meth:`~ConditionalRBM.fit` keeps the mean of its
        parameters over the last ``ceil(average_fraction * n_iter)`` epochs
        (see :class:`ConditionalRBM`, whose default is 0.25); ``0`` keeps
        the last epoch's.
    n_iter : int, default=200
        Epochs per layer.
    n_mean_field : int, default=10
        Mean-field steps (hidden probabilities, then visible means) that end
        every frame :meth:`sample` generates, after its Gibbs iterations.
        One (the original code's) leaves the frame where the last sampled
        hidden states put it, and the frames shake; more settle it at the
        mean-field fixed point of the mode the chain ended in: smooth, but
        deterministic given the past, so that without ``hidden_drift``
        sequences generated from one seed become copies of each other.
    hidden_drift : float, default=0.0
        Standard deviation of a random offset of the hidden biases of every
        sequence :meth:`sample` generates, which changes smoothly over a
        few frames and holds through all of a frame's steps: randomness that
        keeps sequences from one seed apart without shaking the frames, in
        the units of the hidden units' input (as ``hidden_noise``); ``0``:
        none.
    random_state : int, RandomState instance or None, default=None
        Seeds every layer (each gets its own integer seed drawn from it) and,
        unless ``sample`` is given its own, generation.
    verbose : int, default=0
        Passed to every layer: print progress every ``verbose`` epochs.
    estimator : estimator, default=None
        The model of every layer, for a stack of another kind: an unfitted
        model of one conditional layer (:class:`LabelledCRBM`,
        :class:`FactoredCRBM`, a model of a new kind of layer), cloned for
        each layer with its ``n_components`` from ``n_components``, its
        ``random_state`` drawn from the stack's and, above the bottom,
        binary visibles where it has a ``visible_type``; its other
        parameters are its own (the stack's ``order`` to ``verbose``
        configure the default).  None: a :class:`ConditionalRBM` with the
        stack's parameters.  Labels ``y`` given to :meth:`fit` reach every
        layer.

    Attributes
    ----------
    layers_ : list of ConditionalRBM
        The fitted layers, bottom (Gaussian visibles) first.
    n_context_ : int
        Columns of the context the stack was fitted with (0: none).
    context_mean_ : ndarray of shape (n_context,)
        Mean of each column of a real-valued context in ``fit``, which the
        model subtracts from every context it is given (absent when fitted
        without one).
    context_scale_ : ndarray of shape (n_context,)
        Standard deviation of each column (1 for a constant one), by which
        the model divides every context it is given.
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

    # The hyper-parameters every layer takes from the stack as they are.
    _layer_parameters = (
        "order",
        "hidden_order",
        "learning_rate",
        "momentum",
        "momentum_delay",
        "weight_decay",
        "cd_steps",
        "batch_size",
        "batching",
        "history_noise_fraction",
        "average_fraction",
        "n_iter",
        "verbose",
    )

    _parameter_constraints: dict = {
        **{
            name: ConditionalRBM._parameter_constraints[name]
            for name in _layer_parameters
        },
        "n_components": [Interval(Integral, 1, None, closed="left"), "array-like"],
        "history_noise": [Interval(Real, 0, None, closed="left"), "array-like"],
        "n_mean_field": ConditionalRBM._parameter_constraints["n_mean_field"],
        "hidden_drift": ConditionalRBM._parameter_constraints["hidden_drift"],
        "random_state": ["random_state"],
        "estimator": [HasMethods(["fit", "transform", "conditional_layers"]), None],
    }

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
        history_noise_fraction=1.0,
        average_fraction=0.0,
        n_iter=200,
        n_mean_field=10,
        hidden_drift=0.0,
        random_state=None,
        verbose=0,
        estimator=None,
    ):
        super().__init__(
            n_components,
            order=order,
            learning_rate=learning_rate,
            momentum=momentum,
            momentum_delay=momentum_delay,
            weight_decay=weight_decay,
            cd_steps=cd_steps,
            batch_size=batch_size,
            batching=batching,
            history_noise=history_noise,
            history_noise_fraction=history_noise_fraction,
            average_fraction=average_fraction,
            n_iter=n_iter,
            n_mean_field=n_mean_field,
            hidden_drift=hidden_drift,
            random_state=random_state,
            verbose=verbose,
        )
        self.hidden_order = hidden_order
        self.estimator = estimator

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

    def _new_layer_estimator(self, n_components, visible_type, seed, history_noise):
        if self.estimator is None:
            params = self.get_params(deep=False)
            layer = ConditionalRBM(
                n_components,
                visible_type=visible_type,
                history_noise=history_noise,
                random_state=seed,
                **{name: params[name] for name in self._layer_parameters},
            )
        else:
            layer = clone(self.estimator)
            own = dict(n_components=n_components, random_state=seed)
            if "visible_type" in layer.get_params(deep=False):
                own["visible_type"] = visible_type
            layer.set_params(**own)
        # the stack standardises a real-valued context once, for every layer
        return layer._take_context_as_given()

    def _check_fit_input(self, X, sequence_ids, context, reset):
        xp = get_namespace(X)[0]
        if not reset:
            self._check_namespace(X, "partial_fit")
        X = validate_data(
            self,
            X,
            dtype=[xp.float64, xp.float32] if reset else self._fitted_layers()[0].dtype,
            reset=reset,
        )
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        lags = [layer.n_lags for layer in self._planned_layers(X.shape[1])]
        needed = sum(lags) + 1
        longest = int(sequences.lengths.max()) if len(sequences.lengths) else 0
        if longest < needed:
            noun = "sample" if longest == 1 else "samples"
            raise ValueError(
                f"A stack of {len(self._layer_sizes())} layers of order "
                f"{lags[0]} needs sequences of at least {needed} frames (each "
                f"layer drops the first {lags[0]} frames of every sequence), "
                f"but the longest sequence has {longest} {noun}. Pass longer "
                "sequences (check sequence_ids), fewer layers or a lower order."
            )
        return X, sequences, self._context_for_fit(X, None, context, reset)

    def _pass_up(self, layer, X, y, ids, context):
        """Hidden probabilities of ``layer`` on its valid frames, with their
        labels, ids and contexts."""
        valid = check_sequence_ids(ids, X.shape[0]).valid_frames(layer.history_length)
        # the labels as fit took them (a model without labels ignores them)
        hidden = layer._transform_training_data(X, y, ids, context)
        ops = array_ops(hidden)
        if context is not None:
            context = ops.take(context, valid, axis=0)
        # labels go up to layers that take them (a style model requires them)
        takes_labels = y is not None and get_tags(layer).target_tags.required
        y = as_entries(y)[valid] if takes_labels else None
        return ops.take(hidden, valid, axis=0), y, ids[valid], context

    # ------------------------------------------------------------------ fit

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None, context=None):
        """Train the layers greedily, bottom first.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,), default=None
            Labels for the layers of a style model (``estimator``); ignored
            by :class:`ConditionalRBM` layers.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's real-valued context, which every layer takes (a
            :class:`ConditionalRBM` adds it to its dynamic biases).

        Returns
        -------
        self : StackedCRBM
            The fitted stack.
        """
        sizes = self._layer_sizes()
        noises = self._history_noises(len(sizes))
        X, sequences, context = self._check_fit_input(
            X, sequence_ids, context, reset=True
        )
        self.random_state_ = check_random_state(self.random_state)
        ids = sequences.per_frame_ids()
        self.layers_ = []
        data = X
        for k, size in enumerate(sizes):
            seed = int(self.random_state_.randint(np.iinfo(np.int32).max))
            layer = self._new_layer_estimator(
                size, "gaussian" if k == 0 else "binary", seed, noises[k]
            )
            layer.fit(data, y, sequence_ids=ids, context=context)
            self.layers_.append(layer)
            if k + 1 < len(sizes):
                data, y, ids, context = self._pass_up(layer, data, y, ids, context)
        self._keep_seeds(X, sequences)
        return self

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def partial_fit(self, X, y=None, *, sequence_ids=None, context=None):
        """Train every layer for one epoch on the given sequences.

        The first call creates the layers.  Each call trains the bottom
        layer for one epoch on ``X``, then each higher layer for one epoch on
        the hidden probabilities of the (just updated) layer below, so that
        repeated calls train all layers together rather than greedily.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,), default=None
            Labels for the layers of a style model (``estimator``); ignored
            by :class:`ConditionalRBM` layers.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's real-valued context, which every layer takes (a
            :class:`ConditionalRBM` adds it to its dynamic biases).

        Returns
        -------
        self : StackedCRBM
            The updated stack.
        """
        sizes = self._layer_sizes()
        noises = self._history_noises(len(sizes))
        first_call = not hasattr(self, "layers_")
        X, sequences, context = self._check_fit_input(
            X, sequence_ids, context, reset=first_call
        )
        if first_call:
            self.random_state_ = check_random_state(self.random_state)
            self.layers_ = [
                self._new_layer_estimator(
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
            layer.partial_fit(data, y, sequence_ids=ids, context=context)
            if k + 1 < len(self.layers_):
                data, y, ids, context = self._pass_up(layer, data, y, ids, context)
        self._keep_seeds(X, sequences, merge=True)
        return self

    def _fitted_layers(self):
        return [layer for model in self.layers_ for layer in model.conditional_layers()]

    def _planned_layers(self, n_features):
        layers = []
        for k, size in enumerate(self._layer_sizes()):
            visible_type = "gaussian" if k == 0 else "binary"
            model = self._new_layer_estimator(size, visible_type, None, 0.0)
            layers += model._planned_layers(n_features)
            n_features = size
        return layers

    def _chain_rng(self, rng):
        # the top layer's chains draw from a generator of their own, seeded
        # from ``rng`` after the seeds are picked (as the layers are seeded)
        return rng_from(int(rng.integers(np.iinfo(np.int32).max)))

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.array_api_support = True
        return tags

    def __sklearn_is_fitted__(self):
        # a fit that failed part-way leaves no layers: still "not fitted"
        return hasattr(self, "layers_") and hasattr(self, "seed_windows_")
