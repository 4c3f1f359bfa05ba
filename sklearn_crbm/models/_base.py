"""What every model of the package shares: inference, scoring, generation.

:class:`BaseCRBM` is the base of :class:`~sklearn_crbm.ConditionalRBM`,
:class:`~sklearn_crbm.StackedCRBM` and, through
:class:`~sklearn_crbm.models._one_layer.BaseLayerModel`, of the style models
:class:`~sklearn_crbm.FactoredCRBM` and :class:`~sklearn_crbm.LabelledCRBM`.
"""

import inspect
from abc import ABCMeta, abstractmethod
from numbers import Integral, Real

import numpy as np
from sklearn.base import (
    BaseEstimator,
    ClassNamePrefixFeaturesOutMixin,
    TransformerMixin,
)
from sklearn.utils import Bunch
from sklearn.utils._array_api import check_same_namespace, get_namespace
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import (
    _check_sample_weight,
    _is_fitted,
    check_is_fitted,
    validate_data,
)

from .._engines._gibbs import stacked_prediction
from .._engines._likelihood import (
    LogLikelihood,
    frame_log_likelihood,
    stack_log_likelihood_bound,
)
from ..layers._base import sequence_frame_rbms, sequence_hidden_probabilities
from ..utils._array_api import array_ops, array_random, is_numpy
from ..utils._persistence import VersionedPickleMixin
from ..utils._random import rng_from
from ..utils._sequences import check_sequence_ids
from ..utils._threads import frame_rows, limit_blas_threads
from ._context import ContextMixin
from ._sampling import SamplingMixin

__all__ = ["BaseCRBM", "FittedParameter"]

# Mean-field iterations of the one-step-ahead prediction (``predict_next``).
SCORE_MEAN_FIELD_STEPS = 10
# Annealing of ``score`` for a model without ``ais_steps``/``ais_chains``.
AIS_STEPS, AIS_CHAINS = 50, 2
# Draws of the lower layers' hidden units per frame in a stack's bound.
BOUND_SAMPLES = 10


class BaseCRBM(
    ContextMixin,
    SamplingMixin,
    VersionedPickleMixin,
    ClassNamePrefixFeaturesOutMixin,
    TransformerMixin,
    BaseEstimator,
    metaclass=ABCMeta,
):
    """Base class of the conditional RBMs: one layer or a stack of them.

    A fitted model is a stack of conditional layers
    (:mod:`sklearn_crbm.layers`), bottom first (one for
    :class:`ConditionalRBM`); the visible units of layer ``k + 1`` are the
    hidden units of layer ``k``.  This class holds everything that is the
    same for any such stack: input checks, :meth:`transform`,
    :meth:`predict_next`, :meth:`score`, :meth:`score_samples` and
    :meth:`estimate_log_likelihood`, :meth:`sample` with its seed windows,
    and the constants.  Subclasses fit, and provide the hooks
    :attr:`history_length`, ``_fitted_layers`` (every fitted layer) and,
    where they differ from the defaults, ``_ais_settings`` and ``_chain_rng``.

    Every method that depends on time takes the same per-frame ``context``
    (shape ``(n_frames, n_context)``, real-valued), which every layer gets
    with the frame's past.  A model fitted with a context needs one
    wherever it computes; the style models also take labels (``y`` in
    :meth:`fit` and :meth:`score`, ``style`` elsewhere), which the hooks
    ``_labels_context`` and ``_style_context`` turn into context, and infer
    the context of frames given none (``_inference_context``,
    ``_frame_log_likelihoods``).
    """

    _parameter_constraints: dict = {
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
        "momentum": [Interval(Real, 0, 1, closed="left")],
        "momentum_delay": [Interval(Integral, 0, None, closed="left")],
        "weight_decay": [Interval(Real, 0, None, closed="left")],
        "cd_steps": [Interval(Integral, 1, None, closed="left")],
        "batch_size": [Interval(Integral, 1, None, closed="left")],
        "batching": [StrOptions({"balanced", "shuffled"})],
        "history_noise": [Interval(Real, 0, None, closed="left")],
        "n_iter": [Interval(Integral, 1, None, closed="left"), StrOptions({"auto"})],
        "n_mean_field": [Interval(Integral, 1, None, closed="left")],
        "hidden_drift": [Interval(Real, 0, None, closed="left")],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    # With sklearn.set_config(enable_metadata_routing=True) a Pipeline or a
    # search passes ``sequence_ids`` and ``context`` to these methods without
    # being asked.
    __metadata_request__fit = {"sequence_ids": True, "context": True}
    __metadata_request__partial_fit = {"sequence_ids": True, "context": True}
    __metadata_request__transform = {"sequence_ids": True, "context": True}
    __metadata_request__score = {"sequence_ids": True, "context": True}

    def __init__(
        self,
        n_components,
        *,
        order,
        learning_rate,
        momentum,
        momentum_delay,
        weight_decay,
        cd_steps,
        batch_size,
        batching,
        history_noise,
        history_noise_fraction,
        average_fraction,
        n_iter,
        n_mean_field,
        hidden_drift,
        random_state,
        verbose,
    ):
        # The parameters every model has. Each subclass lists all of its own
        # in its __init__ (scikit-learn's get_params reads them there) and
        # passes these on, as sklearn.mixture's BaseMixture has it.
        self.n_components = n_components
        self.order = order
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
        self.n_mean_field = n_mean_field
        self.hidden_drift = hidden_drift
        self.random_state = random_state
        self.verbose = verbose

    def __setstate__(self, state):
        # Models pickled before sample's settings became parameters sampled
        # with the class's default mean-field steps and no drift.
        state = dict(state)
        parameters = inspect.signature(type(self).__init__).parameters
        if "n_mean_field" in parameters and "n_mean_field" not in state:
            state["n_mean_field"] = parameters["n_mean_field"].default
        if "hidden_drift" in parameters:
            state.setdefault("hidden_drift", 0.0)
        super().__setstate__(state)

    # ---------------------------------------------------------------- hooks

    @abstractmethod
    def _fitted_layers(self):
        """The fitted :class:`~sklearn_crbm.layers.ConditionalLayer` s, bottom first."""

    @abstractmethod
    def _planned_layers(self, n_features):
        """The layers ``fit`` would make for ``n_features`` (not initialised)."""

    @property
    def history_length(self):
        """Past frames a frame's top-layer representation depends on.

        The sum of the layers' past frames (``max(order, hidden_order)``
        each; before fit, those of the layers ``fit`` would make):
        :meth:`sample` needs this many seed frames (at least one), and
        :meth:`score` judges frames with this many past frames in their
        sequence.
        """
        # the past a layer takes does not depend on its number of features
        layers = self._fitted_layers() if _is_fitted(self) else self._planned_layers(1)
        return sum(layer.n_lags for layer in layers)

    def _matrix_product_size(self, n_features=None):
        """Multiply-adds per frame of the largest matrix product of the layers.

        Those fitted, or (``n_features`` given, before the first fit) those
        ``fit`` would make; the package sizes its BLAS threads by it
        (:mod:`sklearn_crbm.utils._threads`).
        """
        fitted = _is_fitted(self)
        layers = self._fitted_layers() if fitted else self._planned_layers(n_features)
        return max(layer.product_size() for layer in layers)

    def _ais_settings(self):
        """Intermediate distributions and chains per frame of the annealing."""
        return AIS_STEPS, AIS_CHAINS

    def _frame_log_likelihoods(self, X, sequences, context):
        """Every frame's log-likelihood given its context (checked)."""
        context = self._inference_context(X, sequences, context)
        return self._log_likelihood(X, sequences, context=context).log_likelihood

    def _chain_rng(self, rng):
        """The generator of ``sample``'s chains, given the one that picked seeds."""
        return rng

    @property
    def n_context_(self):
        """Columns of the per-frame ``context`` the model was fitted with (0: none)."""
        check_is_fitted(self)
        return self._fitted_layers()[0].n_context

    # ------------------------------------------------------------------ fit

    def fit_transform(self, X, y=None, *, sequence_ids=None, context=None):
        """Fit, then return the top layer's hidden probabilities of ``X``.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,) or (n_frames, n_outputs), default=None
            The labels of every frame, for the style models (see :meth:`fit`);
            ignored by the others.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's real-valued context (see :meth:`fit`).

        Returns
        -------
        H : ndarray of shape (n_frames, n_components_out)
            Hidden probabilities, as :meth:`transform` gives them.
        """
        self.fit(X, y, sequence_ids=sequence_ids, context=context)
        return self._transform_training_data(X, y, sequence_ids, context)

    @limit_blas_threads(frame_rows)
    def _transform_training_data(self, X, y, sequence_ids, context):
        X, sequences = self._check_inference_input(X, sequence_ids)
        context = self._context_for_fit(X, y, context, reset=False)
        return self._representations(X, sequences, self._fitted_layers(), context)[-1]

    # ------------------------------------------------------------ inference

    @property
    def _packed_parameters(self):
        """The bottom layer's parameter buffer: the fitted namespace and device."""
        return self._fitted_layers()[0].flat

    def _check_namespace(self, X, method):
        """A clear error unless ``X`` can meet the fitted parameters."""
        flat = self._packed_parameters
        if not is_numpy(flat) and not get_namespace(X)[1]:
            raise ValueError(
                f"{type(self).__name__} was fitted on {type(flat).__module__} "
                f"arrays; {method} needs sklearn.set_config(array_api_dispatch=True) "
                "and input of that namespace and device, or a model moved to numpy "
                "with sklearn.utils._array_api.move_estimator_to(model, numpy, "
                "'cpu')."
            )
        check_same_namespace(X, self, attribute="_packed_parameters", method=method)

    def _check_inference_input(self, X, sequence_ids, method="transform"):
        check_is_fitted(self)
        self._check_namespace(X, method)
        xp = get_namespace(X)[0]
        X = validate_data(self, X, dtype=[xp.float64, xp.float32], reset=False)
        ops = array_ops(X)
        X = ops.astype(X, self._fitted_layers()[0].dtype, copy=False)
        return X, check_sequence_ids(sequence_ids, X.shape[0])

    def _representations(self, X, sequences, layers, context=None):
        """The data, then ``layers``' hidden probabilities of it, bottom first."""
        representations = [X]
        for layer in layers:
            representations.append(
                sequence_hidden_probabilities(
                    layer, representations[-1], sequences, context
                )
            )
        return representations

    def _stack_chunks(self, X, sequences, frames=None, context=None):
        """Yield ``(rows, stack)``: every layer's frame RBMs of chunks of frames."""
        layers = self._fitted_layers()
        representations = self._representations(X, sequences, layers[:-1], context)
        chunks = zip(
            *(
                sequence_frame_rbms(layer, values, sequences, frames, context)
                for layer, values in zip(layers, representations, strict=True)
            ),
            strict=True,
        )
        for per_layer in chunks:
            yield per_layer[0][0], [rbms for _, rbms in per_layer]

    @limit_blas_threads(frame_rows)
    def transform(self, X, *, sequence_ids=None, context=None, style=None):
        """Hidden probabilities of the top layer, frame by frame.

        Each layer's hidden probabilities ``p(h = 1 | x_t, history)`` are the
        next layer's visible data (a :class:`ConditionalRBM` has one layer).
        Inside a layer, the first ``max(order, hidden_order)`` frames of each
        sequence have their missing past frames replaced by the sequence's
        first frame (edge padding), so every frame gets a row; a frame's
        output is exact (as during training) once it has
        :attr:`history_length` past frames in its sequence.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`fit`; needed by a model
            fitted with one (a style model fitted on labels infers each
            sequence's style instead: its posterior, :meth:`predict_proba`,
            as label weights).
        style : label or array-like of shape (n_frames,) or (n_frames, \
n_classes), default=None
            A style model's labels (one for every frame, one per frame, or
            label weights per frame) in place of ``context``.  For a model
            of several label factors: one row of labels, one per factor,
            for every frame, or one row per frame ``(n_frames,
            n_outputs)``, as ``y`` of :meth:`fit`.

        Returns
        -------
        H : ndarray of shape (n_frames, n_components_out)
            Hidden probabilities of the top layer, in the dtype of the model.
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        context = self._given_context(X, sequences, context, style)
        return self._representations(X, sequences, self._fitted_layers(), context)[-1]

    @limit_blas_threads(frame_rows)
    def predict_next(self, X, *, sequence_ids=None, context=None, style=None):
        """One-step-ahead prediction of every frame from its history alone.

        A deterministic estimate of ``E[x_t | history]``: the top layer
        starts from its autoregressive mean and alternates hidden
        probabilities and visible means ten times (mean field); each layer
        below turns the predicted probabilities of its hidden units into its
        visible mean given its own history, down to the data.  The
        histories of the upper layers are the representations of the past
        frames (hidden probabilities).  Frame ``t`` itself is not used.
        Frames with fewer than :attr:`history_length` past frames in their
        sequence use edge padding, as :meth:`transform` does.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`transform`.
        style : label or array-like, default=None
            A style model's labels in place of ``context``, as in
            :meth:`transform`.

        Returns
        -------
        X_pred : ndarray of shape (n_frames, n_features)
            Predicted frames.
        """
        X, sequences = self._check_inference_input(X, sequence_ids, "predict_next")
        context = self._given_context(X, sequences, context, style)
        return self._predict_frames(X, sequences, context=context)

    def _predict_frames(self, X, sequences, frames=None, context=None):
        frames = np.arange(X.shape[0]) if frames is None else frames
        predicted = array_ops(X).empty((len(frames), X.shape[1]), dtype=X.dtype)
        position = 0
        for rows, stack in self._stack_chunks(X, sequences, frames, context):
            predicted[position : position + len(rows), ...] = stacked_prediction(
                stack, SCORE_MEAN_FIELD_STEPS
            )
            position += len(rows)
        return predicted

    @limit_blas_threads(frame_rows)
    def score_samples(self, X, *, sequence_ids=None, context=None, style=None):
        """Conditional log-likelihood ``log p(x_t | history)`` of every frame, in nats.

        One layer (:class:`ConditionalRBM`): exact when enumerating the
        ``2 ** n_components`` hidden configurations costs less than
        annealing; otherwise estimated by annealed importance sampling with
        ``ais_steps`` intermediate distributions and ``ais_chains`` chains
        per frame, seeded by ``random_state`` (see
        :meth:`ConditionalRBM.estimate_log_likelihood` for the estimate's
        standard error and a conservative reverse estimate).

        A stack (:class:`StackedCRBM`) generates a frame top-down, so its
        likelihood sums over the hidden units of every lower layer: with
        their hidden probabilities as the proposal (as in training), ten
        draws per frame give the importance-weighted lower bound (Burda,
        Grosse & Salakhutdinov, 2016; one draw would give the variational
        bound of Hinton, Osindero & Teh, 2006), whose top term is the top
        layer's exact or annealed log-likelihood.  Low on average: a stack
        that scores above a single :class:`ConditionalRBM` is better.

        Frames with fewer than :attr:`history_length` past frames in their
        sequence use edge padding, as :meth:`transform` does.

        A style model fitted on labels and given neither ``context`` nor
        ``style`` scores each frame under the mixture of the styles, each
        weighted by its posterior given the sequence's frames before it
        (from ``priors``): ``log sum_k p(k | x_<t) p(x_t | past, k)``.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`transform`.
        style : label or array-like, default=None
            A style model's labels in place of ``context``, as in
            :meth:`transform`.

        Returns
        -------
        log_likelihood : ndarray of shape (n_frames,)
            Log density (Gaussian visibles) or log probability (binary) of
            each frame given its history, in the dtype of the model.
        """
        X, sequences = self._check_inference_input(X, sequence_ids, "score_samples")
        context = self._method_context(context, style, X.shape[0], X)
        log_likelihood = self._frame_log_likelihoods(X, sequences, context)
        return array_ops(X).astype(log_likelihood, X.dtype)

    def _log_likelihood(
        self,
        X,
        sequences,
        method="auto",
        reverse=False,
        rng=None,
        context=None,
        frames=None,
    ):
        """:class:`~sklearn_crbm._engines._likelihood.LogLikelihood` of every frame
        (of ``frames`` only, in their order, when given)."""
        layers = self._fitted_layers()
        n_steps, n_chains = self._ais_settings()
        rng = rng_from(self.random_state) if rng is None else rng
        rng = array_random(rng, X)  # numpy's own stream for numpy input
        if len(layers) == 1:
            return frame_log_likelihood(
                X,
                sequence_frame_rbms(
                    layers[0], X, sequences, frames=frames, context=context
                ),
                method=method,
                n_steps=n_steps,
                n_chains=n_chains,
                reverse=reverse,
                rng=rng,
            )
        ops = array_ops(X)
        bounds = [
            stack_log_likelihood_bound(
                stack,
                ops.take(X, rows, axis=0),
                n_samples=BOUND_SAMPLES,
                rng=rng,
                method=method,
                n_steps=n_steps,
                n_chains=n_chains,
            )
            for rows, stack in self._stack_chunks(X, sequences, context=context)
        ]
        bound = ops.concatenate(bounds)
        if frames is not None:  # a stack's bound needs every frame's past anyway
            bound = ops.take(bound, ops.asarray(frames), axis=0)
        return LogLikelihood(bound, None, ops.zeros_like(bound), "bound")

    @limit_blas_threads(frame_rows)
    def estimate_log_likelihood(
        self,
        X,
        *,
        sequence_ids=None,
        context=None,
        style=None,
        method="auto",
        reverse=True,
        random_state=None,
    ):
        """``log p(x_t | history)`` of every frame, with how far to trust it.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`transform`.
        style : label or array-like, default=None
            A style model's labels in place of ``context``, as in
            :meth:`transform`.
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
                exact; None if not ``reverse``, or for a stack, whose
                estimate is a bound).  When the annealing is good the two
                bracket the truth, and their gap bounds the error of either.
            standard_error : ndarray of shape (n_frames,)
                Standard error of the forward estimate across chains (0
                when exact; for a model without history, that of its one
                partition function).
            method : str
                ``"exact"``, ``"ais"`` or (a stack) ``"bound"``.

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
        X, sequences = self._check_inference_input(
            X, sequence_ids, "estimate_log_likelihood"
        )
        context = self._given_context(X, sequences, context, style)
        if method not in ("auto", "exact", "ais"):
            raise ValueError(
                f"method must be 'auto', 'exact' or 'ais', got {method!r}."
            )
        rng = rng_from(self.random_state if random_state is None else random_state)
        result = self._log_likelihood(
            X, sequences, method=method, reverse=reverse, rng=rng, context=context
        )
        return Bunch(**result._asdict())

    @limit_blas_threads(frame_rows)
    def score(self, X, y=None, *, sequence_ids=None, context=None, sample_weight=None):
        """Mean held-out log-likelihood per frame, in nats; higher is better.

        The mean of :meth:`score_samples` over every frame with
        :attr:`history_length` past frames in its own sequence: the
        conditional log-likelihood ``log p(x_t | x_{t-1}, ..., x_{t-order})``
        per frame (for a stack, a lower bound on it).  Comparable across
        ``n_components``, ``order``, ``hidden_order``, visible types and
        variances, one layer or a stack, on the same frames, so that
        ``GridSearchCV(scoring=None)`` picks among them (give them the same
        frames, e.g. by scoring on sequences longer than every
        ``history_length``).  The one-step prediction error is
        :func:`~sklearn_crbm.model_selection.make_prediction_scorer`.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,) or (n_frames, n_outputs), default=None
            A style model's labels of every frame, as ``y`` of :meth:`fit`
            (a model of one factor also takes label weights, shape
            ``(n_frames, n_classes)``; None: unknown, see
            :meth:`score_samples`); ignored by the other models.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`fit`.
        sample_weight : array-like of shape (n_frames,), default=None
            Weight of each frame in the mean; frames without a full history
            are left out whatever their weight.

        Returns
        -------
        score : float
            Mean log-likelihood per frame.
        """
        X, sequences = self._check_inference_input(X, sequence_ids, "score")
        frames = sequences.frames_with_past(self.history_length, "score")
        ops = array_ops(X)
        context = self._score_context(X, y, context)
        # every frame, as score_samples draws them: the same random numbers
        log_likelihood = self._frame_log_likelihoods(X, sequences, context)
        log_likelihood = ops.take(log_likelihood, frames, axis=0)
        if sample_weight is None:
            return float(ops.mean(log_likelihood))
        weights = ops.take(_check_sample_weight(sample_weight, X), frames, axis=0)
        return float(ops.sum(log_likelihood * weights) / ops.sum(weights))

    # ------------------------------------------------------ on-line fill-in

    def conditional_layers(self):
        """The fitted conditional layers, bottom first: what on-line fill-in runs.

        Returns
        -------
        layers : list of ConditionalLayer
            One for a one-layer model, one per layer for a stack (see
            :mod:`sklearn_crbm.layers` for their interface).
        """
        check_is_fitted(self)
        return list(self._fitted_layers())

    def fill_in_context(self, X, *, context=None, style=None):
        """What on-line fill-in of the frames ``X`` conditions on.

        Parameters
        ----------
        X : ndarray of shape (n_frames, n_features)
            The frames, checked, in the namespace of the model.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`transform`.
        style : label or array-like, default=None
            A style model's labels in place of ``context``.

        Returns
        -------
        frame_context : ndarray of shape (n_frames, n_context) or None
            Every frame's context, given (or from ``style``); None for a
            model without one, or where it is to be inferred.
        hypotheses : ndarray of shape (n_hypotheses, n_context) or None
            With ``frame_context`` None, the contexts that the particles of
            a filter carry and resampling weighs (a style model fitted on
            labels: one per style); else None.
        """
        check_is_fitted(self)
        context = self._method_context(context, style, X.shape[0], X)
        return self._online_context(X, context)

    # ---------------------------------------------------------------- misc

    @property
    def _n_features_out(self):
        return self._fitted_layers()[-1].n_components

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.transformer_tags.preserves_dtype = ["float64", "float32"]
        return tags


class FittedParameter:
    """A fitted attribute that views a group of the packed parameters.

    ``components_ = FittedParameter("weights")`` on the class makes
    ``model.components_`` the ``weights`` view of ``model._layer`` (a
    :class:`~sklearn_crbm.layers.ConditionalLayer`); an unfitted model
    has no such attribute.  Assigning to it writes into the view (same
    shape only), so the model computes with what was assigned.  A group that
    the parameters compute (``visible_variance``, from
    ``log_visible_variance``) is a new array; assigning to it sets what it
    is computed from.
    """

    def __init__(self, group):
        self.group = group

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, instance, owner=None):
        if instance is None:
            return self
        try:
            params = vars(instance)["_layer"]
        except KeyError:
            raise AttributeError(
                f"{type(instance).__name__!r} object has no attribute {self.name!r}"
            ) from None
        return getattr(params, self.group)

    def __set__(self, instance, value):
        view = self.__get__(instance)
        value = array_ops(view).asarray(value)
        if value.shape != view.shape:
            raise ValueError(
                f"{self.name} has shape {view.shape}; got an array of shape "
                f"{value.shape}. Set the size parameters and refit to change it."
            )
        params = vars(instance)["_layer"]
        computed = getattr(type(params), self.group, None)
        if isinstance(computed, property) and computed.fset is not None:
            setattr(params, self.group, value)  # visible_variance, not a view
        else:
            view[...] = value
