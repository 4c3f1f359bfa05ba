"""What every model of the package shares: inference, scoring, generation.

:class:`BaseCRBM` is the base of :class:`~sklearn_crbm.ConditionalRBM`,
:class:`~sklearn_crbm.StackedCRBM` and, through
:class:`~sklearn_crbm._base_layer.BaseLayerModel`, of the style models
:class:`~sklearn_crbm.FactoredCRBM` and :class:`~sklearn_crbm.LabelledCRBM`.
"""

import inspect
import os
import warnings
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

from ._gibbs import stacked_prediction
from ._likelihood import (
    LogLikelihood,
    frame_log_likelihood,
    stack_log_likelihood_bound,
)
from ._online import TOP_LAYER, History, run_online
from .exceptions import GenerationWarning
from .layers._base import sequence_frame_rbms, sequence_hidden_probabilities
from .metrics import motion_amplitude
from .utils._array_api import array_ops, array_random, is_numpy, to_numpy
from .utils._parallel import SAMPLE_BLOCK, map_sequence_blocks
from .utils._persistence import VersionedPickleMixin
from .utils._random import rng_from
from .utils._sequences import check_sequence_ids
from .utils._threads import frame_rows, limit_blas_threads, sequence_rows

__all__ = [
    "BaseCRBM",
    "check_context",
    "check_count",
    "generated_liveliness",
    "seed_frames",
]

# How many windows of training frames ``fit`` keeps to seed ``sample``.
MAX_SEED_WINDOWS = 500
# Gibbs iterations per generated frame of a model without an ``n_gibbs``.
DEFAULT_N_GIBBS = 30
# What sample does for a model without the parameters n_mean_field and
# hidden_drift (a layer model defined outside the package).
DEFAULT_N_MEAN_FIELD = 10
DEFAULT_HIDDEN_DRIFT = 0.0
# Mean-field iterations of the one-step-ahead prediction (``predict_next``).
SCORE_MEAN_FIELD_STEPS = 10
# Annealing of ``score`` for a model without ``ais_steps``/``ais_chains``.
AIS_STEPS, AIS_CHAINS = 50, 2
# Draws of the lower layers' hidden units per frame in a stack's bound.
BOUND_SAMPLES = 10
# Standard deviation of the jitter added to the previous frame to start the
# Gibbs chain of a new frame (the original code's gen.m).
START_JITTER = 0.01
# ``sample`` judges the last frames of every generated sequence (more than a
# cycle of walking or waving at 30 frames per second) against the same
# number of last frames of every training sequence: moving less than
# DEAD_FRACTION as much, it died out; beyond BLOWN_DEVIATIONS standard
# deviations of the widest channel from the training mean and BLOWN_REACH
# times as far as the channel's training frames went, it blew up (the toes
# of real walks reach 13.5 such deviations).
LIVELINESS_FRAMES = 100
DEAD_FRACTION = 0.5
BLOWN_DEVIATIONS = 10.0
BLOWN_REACH = 2.0


class BaseCRBM(
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
    :attr:`history_length`, ``_layers`` (every fitted layer) and, where they
    differ from the defaults, ``_ais_settings`` and ``_chain_rng``.

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

    # Noise on the previous frame where a new frame's Gibbs chain starts.
    _start_jitter = START_JITTER

    # With sklearn.set_config(enable_metadata_routing=True) a Pipeline or a
    # search passes ``sequence_ids`` and ``context`` to these methods without
    # being asked.
    __metadata_request__fit = {"sequence_ids": True, "context": True}
    __metadata_request__partial_fit = {"sequence_ids": True, "context": True}
    __metadata_request__transform = {"sequence_ids": True, "context": True}
    __metadata_request__score = {"sequence_ids": True, "context": True}

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
    def _layers(self):
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
        layers = self._layers() if _is_fitted(self) else self._planned_layers(1)
        return sum(layer.n_lags for layer in layers)

    def _matrix_product_size(self, n_features=None):
        """Multiply-adds per frame of the largest matrix product of the layers.

        Those fitted, or (``n_features`` given, before the first fit) those
        ``fit`` would make; the package sizes its BLAS threads by it
        (:mod:`sklearn_crbm.utils._threads`).
        """
        fitted = _is_fitted(self)
        layers = self._layers() if fitted else self._planned_layers(n_features)
        return max(layer.product_size() for layer in layers)

    def _ais_settings(self):
        """Intermediate distributions and chains per frame of the annealing."""
        return AIS_STEPS, AIS_CHAINS

    def _labels_context(self, y, X, reset):
        """Every frame's context from the labels ``y`` (None: ``y`` is ignored)."""
        return None

    def _style_context(self, style, n_frames, like):
        """Every frame's context from ``style`` (a model of styles only)."""
        raise ValueError(
            f"{type(self).__name__} has no styles: give context= instead of "
            "style=, or use a style model such as FactoredCRBM or LabelledCRBM."
        )

    def _inference_context(self, X, sequences, context):
        """The context of the frames of ``X``: the one given, which a model
        fitted with a context needs (a style model infers it instead)."""
        if context is None and self.n_context_:
            raise self._missing_context_error()
        return context

    def _frame_log_likelihoods(self, X, sequences, context):
        """Every frame's log-likelihood given its context (checked)."""
        context = self._inference_context(X, sequences, context)
        return self._log_likelihood(X, sequences, context=context).log_likelihood

    def _online_context(self, X, context):
        """What on-line fill-in conditions on: ``(frame_context, hypotheses)``.

        Every frame's context (None for a model without one); a style model
        given none gives hypotheses for particles to weigh instead.
        """
        if context is None and self.n_context_:
            raise self._missing_context_error()
        return context, None

    def _chain_rng(self, rng):
        """The generator of ``sample``'s chains, given the one that picked seeds."""
        return rng

    @property
    def n_context_(self):
        """Columns of the per-frame ``context`` the model was fitted with (0: none)."""
        check_is_fitted(self)
        return self._layers()[0].n_context

    # ------------------------------------------------------------- context

    def _fit_context(self, X, y, context, reset):
        """Every frame's context in ``fit`` and ``score``: from ``y`` or ``context``."""
        labels = self._labels_context(y, X, reset)
        if reset:
            self._forget_context_scaling()
        if labels is None:
            if reset:
                context = check_context(context, X.shape[0], None, X)
                self._learn_context_scaling(context)
                return self._standardized(context)
            if context is None and self.n_context_:
                raise self._missing_context_error()
            context = check_context(context, X.shape[0], self.n_context_, X)
            return self._standardized(context)
        if context is not None:
            raise self._both_error("y")
        return labels

    def _score_context(self, X, y, context):
        """Every frame's context in ``score``, whose ``y`` only style models read."""
        context = check_context(context, X.shape[0], self.n_context_, X)
        return self._standardized(context)

    # A real-valued context is standardised, as X is by the default
    # preprocessing: the learning rate and the initial weights assume inputs
    # of unit scale, and a control in the data's units (a speed in
    # centimetres per second) would swamp the past's input to the hidden units.
    def _learn_context_scaling(self, context):
        if context is None or not getattr(self, "_scales_context", True):
            return
        ops = array_ops(context)
        self.context_mean_ = ops.mean(context, axis=0)
        scale = ops.std(context, axis=0)
        self.context_scale_ = ops.where(scale > 0, scale, ops.ones_like(scale))

    def _forget_context_scaling(self):
        vars(self).pop("context_mean_", None)
        vars(self).pop("context_scale_", None)

    def _standardized(self, context):
        """A user's real-valued context as the layers see it (labels: unchanged)."""
        if context is None or "context_mean_" not in vars(self):
            return context
        ops = array_ops(context)
        mean = ops.astype(self.context_mean_, context.dtype, copy=False)
        scale = ops.astype(self.context_scale_, context.dtype, copy=False)
        return (context - mean) / scale

    def _both_error(self, labels):
        return ValueError(
            f"{type(self).__name__} got both {labels} and context=: give the "
            "labels (a style model turns them into its context) or a context, "
            "not both."
        )

    def _method_context(self, context, style, n_frames, like, *, one_row=False):
        """The context a method is given, as ``context`` or as ``style`` (checked).

        With ``one_row`` (``sample``) a single row stands for every frame.
        """
        if style is not None:
            if context is not None:
                raise self._both_error("style=")
            return self._style_context(style, n_frames, like)
        context = check_context(
            context, n_frames, self.n_context_, like, one_row=one_row
        )
        return self._standardized(context)

    def _missing_context_error(self):
        k = self.n_context_
        return ValueError(
            f"{type(self).__name__} was fitted with a context of {k} column"
            f"{'s' * (k != 1)} per frame, and computes nothing without one: pass "
            f"context= of shape (n_frames, {k}) (for sample: (n_samples, {k}) "
            f"or (1, {k})){self._context_hint}."
        )

    # how else a model can be told its context
    _context_hint = ""

    # ------------------------------------------------------------------ fit

    def fit_transform(self, X, y=None, *, sequence_ids=None, context=None):
        """Fit, then return the top layer's hidden probabilities of ``X``.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,) or (n_frames, n_classes), default=None
            The style of every frame, for the style models (see :meth:`fit`);
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
        context = self._fit_context(X, y, context, reset=False)
        return self._representations(X, sequences, self._layers(), context)[-1]

    def _keep_seeds(self, X, sequences, merge=False, context=None):
        """Keep windows of ``X`` to seed :meth:`sample`, and what it judges by.

        Sets ``seed_windows_`` and ``generation_statistics_`` (per style too
        for a model fitted on labels, whose ``context`` holds them); with
        ``merge`` (``partial_fit``), joined to those of the earlier calls.
        """
        windows = self._pick_seed_windows(X, sequences)
        labels = self._liveliness_labels(context)
        statistics = generation_statistics(X, sequences, labels)
        if merge and hasattr(self, "seed_windows_"):
            windows = self._merge_seed_windows(windows)
        if merge and hasattr(self, "generation_statistics_"):
            statistics = merge_statistics(self.generation_statistics_, statistics)
        self.seed_windows_ = windows
        self.generation_statistics_ = statistics

    def _pick_seed_windows(self, X, sequences):
        """Up to ``MAX_SEED_WINDOWS`` evenly spaced windows of real frames.

        Deterministic (no random draws), so that seeding ``sample`` does not
        disturb the training random stream.
        """
        width = max(self.history_length, 1)
        ends = evenly_spaced(sequences.valid_frames(width - 1) + 1, MAX_SEED_WINDOWS)
        rows = ends[:, None] - np.arange(width, 0, -1)
        ops = array_ops(X)
        windows = ops.take(X, rows.ravel(), axis=0)
        windows = ops.reshape(windows, (*rows.shape, X.shape[1]))
        return ops.astype(windows, self._layers()[0].dtype, copy=True)

    def _merge_seed_windows(self, new):
        """Seed windows of a ``partial_fit`` call joined to the earlier ones."""
        ops = array_ops(new)
        windows = ops.concatenate((self.seed_windows_, new))
        picks = evenly_spaced(np.arange(windows.shape[0]), MAX_SEED_WINDOWS)
        return ops.take(windows, picks, axis=0)

    # ------------------------------------------------------------ inference

    @property
    def _packed_parameters(self):
        """The bottom layer's parameter buffer: the fitted namespace and device."""
        return self._layers()[0].flat

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
        X = ops.astype(X, self._layers()[0].dtype, copy=False)
        return X, check_sequence_ids(sequence_ids, X.shape[0])

    def _given_context(self, X, sequences, context, style):
        """Every frame's context, from ``context`` or ``style``, else inferred."""
        context = self._method_context(context, style, X.shape[0], X)
        return self._inference_context(X, sequences, context)

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
        layers = self._layers()
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
            label weights per frame) in place of ``context``.

        Returns
        -------
        H : ndarray of shape (n_frames, n_components_out)
            Hidden probabilities of the top layer, in the dtype of the model.
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        context = self._given_context(X, sequences, context, style)
        return self._representations(X, sequences, self._layers(), context)[-1]

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
        self, X, sequences, method="auto", reverse=False, rng=None, context=None
    ):
        """:class:`~sklearn_crbm._likelihood.LogLikelihood` of every frame."""
        layers = self._layers()
        n_steps, n_chains = self._ais_settings()
        rng = rng_from(self.random_state) if rng is None else rng
        rng = array_random(rng, X)  # numpy's own stream for numpy input
        if len(layers) == 1:
            return frame_log_likelihood(
                X,
                sequence_frame_rbms(layers[0], X, sequences, context=context),
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
        y : array-like of shape (n_frames,) or (n_frames, n_classes), default=None
            A style model's labels of every frame (None: unknown, see
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
        frames = sequences.valid_frames(self.history_length)
        if len(frames) == 0:
            raise ValueError(
                f"score needs frames with {self.history_length} past frames in "
                "their own sequence; every sequence given is shorter. Pass longer "
                "sequences."
            )
        ops = array_ops(X)
        context = self._score_context(X, y, context)
        # every frame, as score_samples draws them: the same random numbers
        log_likelihood = self._frame_log_likelihoods(X, sequences, context)
        log_likelihood = ops.take(log_likelihood, frames, axis=0)
        if sample_weight is None:
            return float(ops.mean(log_likelihood))
        weights = ops.take(_check_sample_weight(sample_weight, X), frames, axis=0)
        return float(ops.sum(log_likelihood * weights) / ops.sum(weights))

    # ----------------------------------------------------------- generation

    @limit_blas_threads(sequence_rows)
    def sample(
        self,
        n_samples,
        *,
        history=None,
        context=None,
        style=None,
        n_sequences=1,
        n_gibbs=None,
        hidden_noise=0.0,
        sample_visibles=False,
        n_mean_field=None,
        hidden_drift=None,
        random_state=None,
        n_jobs=None,
    ):
        """Generate new frames by alternating Gibbs sampling (paper §4).

        Each new frame starts from the previous frame plus N(0, 0.01^2)
        jitter; ``n_gibbs`` alternating Gibbs iterations follow (hidden units
        sampled, visibles set to their mean), then ``n_mean_field``
        mean-field steps (hidden probabilities, visible means).  With
        ``hidden_drift``, every sequence's hidden biases carry a random
        offset that changes smoothly from frame to frame and holds through
        all of a frame's steps.  All sequences are generated together.  A
        stack does this in its top layer, whose visible units are the hidden
        probabilities of the layer below, and each layer below turns them
        into its visible means given its own generated past, down to the
        data (Taylor's ``gen2.m``).

        Parameters
        ----------
        n_samples : int
            Number of new frames per sequence.
        history : array-like, default=None
            Seed frames, oldest first; at least ``max(history_length, 1)``
            frames, of which the last that many are used (a stack passes
            them up its layers).  Shape ``(n_frames, n_features)`` seeds every
            sequence alike; shape ``(n_sequences, n_frames, n_features)``
            gives each sequence its own seed.  ``None`` draws windows of real
            training frames kept by :meth:`fit` (``seed_windows_``).
        context : array-like of shape (n_samples, n_context) or (1, n_context), \
default=None
            The context of every new frame (one row: the same for all),
            for every sequence; needed by a model fitted with a context.
            Changing it over the frames steers the motion (a transition).
        style : label or array-like of shape (n_samples, n_classes), default=None
            A style model's labels in place of ``context``: a label seen in
            :meth:`fit`, or non-negative label weights that sum to 1 in
            every frame (a blend; a transition when they change over the
            frames).
        n_sequences : int, default=1
            Number of sequences to generate; with a 3-D ``history`` it is
            taken from the history.
        n_gibbs : int, default=None
            Alternating Gibbs iterations per frame; None: the model's
            ``n_gibbs`` parameter if it has one, else 30.
        hidden_noise : float, default=0.0
            Standard deviation of Gaussian noise added to the (top layer's)
            hidden biases each time hidden states are chosen (paper §4.3:
            transitions between styles).
        sample_visibles : bool, default=False
            If True, the (top layer's) visibles are drawn from ``p(v | h,
            history)`` at every Gibbs step (Gaussian noise of unit variance,
            or binary states) and each new frame is the last draw: an exact
            Gibbs sampler whose frames follow ``p(x_t | history)`` when
            ``n_gibbs`` is large.  The default keeps the original code's
            scheme (visible means, then mean field), which gives smoother
            motion.
        n_mean_field : int, default=None
            Mean-field steps that end each frame (ignored with
            ``sample_visibles``); None: the model's ``n_mean_field``
            parameter.
        hidden_drift : float, default=None
            Standard deviation of the smooth random offset of the (top
            layer's) hidden biases that keeps sequences apart; None: the
            model's ``hidden_drift`` parameter.
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
        n_samples = check_count(n_samples, "n_samples", minimum=1)
        params = self.get_params()
        if n_gibbs is None:
            n_gibbs = params.get("n_gibbs", DEFAULT_N_GIBBS)
        n_gibbs = check_count(n_gibbs, "n_gibbs", minimum=0)
        n_sequences = check_count(n_sequences, "n_sequences", minimum=1)
        if n_mean_field is None:
            n_mean_field = params.get("n_mean_field", DEFAULT_N_MEAN_FIELD)
        n_mean_field = check_count(n_mean_field, "n_mean_field", minimum=1)
        if hidden_drift is None:
            hidden_drift = params.get("hidden_drift", DEFAULT_HIDDEN_DRIFT)
        if not isinstance(hidden_drift, Real) or not hidden_drift >= 0:
            raise ValueError(
                f"hidden_drift must be a non-negative number, got {hidden_drift!r}."
            )
        if not isinstance(hidden_noise, Real) or not hidden_noise >= 0:
            raise ValueError(
                f"hidden_noise must be a non-negative number, got {hidden_noise!r}."
            )
        like = self.seed_windows_
        context = self._method_context(context, style, n_samples, like, one_row=True)
        if context is None and self.n_context_:
            raise self._missing_context_error()
        labels = self._liveliness_labels(context)  # before it is broadcast
        rng = rng_from(self.random_state if random_state is None else random_state)
        seed = seed_frames(
            history,
            n_sequences,
            width=max(self.history_length, 1),
            n_features=self.n_features_in_,
            dtype=self._layers()[0].dtype,
            seed_windows=self.seed_windows_,
            rng=rng,
        )
        if context is not None:
            context = array_ops(seed).broadcast_to(
                context[None, ...], (seed.shape[0], *context.shape)
            )
        frames = self._generate(
            seed,
            n_samples,
            rng,
            context=context,
            n_gibbs=n_gibbs,
            hidden_noise=hidden_noise,
            sample_visibles=sample_visibles,
            n_mean_field=n_mean_field,
            hidden_drift=hidden_drift,
            n_jobs=n_jobs,
        )
        self._check_generated(frames, n_samples, labels)
        return frames

    def _liveliness_labels(self, context):
        """The label weights ``sample`` judges liveliness by (None: all
        training sequences alike); models fitted on labels return them."""
        return None

    def _check_generated(self, frames, n_frames, labels=None):
        """Warn with a :class:`GenerationWarning` about sequences that died out
        or blew up (a model fitted before ``generation_statistics_`` existed
        is not judged)."""
        statistics = getattr(self, "generation_statistics_", None)
        if statistics is None:
            return
        # binary visibles stay within [0, 1]: only non-finite values blew up
        scale = np.inf if self._layers()[0].binary else statistics.scale
        message = lifeless_message(
            to_numpy(frames),
            n_frames,
            statistics,
            scale,
            labels,
            getattr(self, "classes_", None),
        )
        if message:
            warnings.warn(message, GenerationWarning, stacklevel=_caller_level())

    def _generate(self, seed, n_samples, rng, *, context=None, n_jobs=None, **gibbs):
        """``n_samples`` frames after each seed, in long format (see :meth:`sample`).

        ``seed`` has shape ``(n_sequences, width, n_features)``; ``context``
        (shape ``(n_sequences, n_samples, n_context)``) gives each new frame's
        context to a layer that takes one.  ``gibbs`` holds ``n_gibbs``,
        ``hidden_noise``, ``sample_visibles``, ``n_mean_field`` and
        ``hidden_drift``.
        """
        layers = self._layers()
        ops = layers[0].ops
        seed_context = None if context is None else context[None, :, 0, ...]
        past = History.from_frames(layers, seed[None, ...], seed_context)

        def generate_block(block, block_rng):
            shape = (len(block), n_samples, seed.shape[2])
            frames = ops.empty(shape, seed.dtype)
            run = run_online(
                layers,
                array_random(block_rng, seed),
                history=past.select(block),
                n_steps=n_samples,
                context=None if context is None else ops.take(context, block, axis=0),
                scheme=TOP_LAYER,
                start_jitter=self._start_jitter,
                **gibbs,
            )
            for step, new in run:
                frames[:, step, ...] = new[0, ...]
            return frames

        blocks = map_sequence_blocks(
            generate_block,
            seed.shape[0],
            self._chain_rng(rng),
            n_jobs,
            # an accelerator runs every sequence in one pass
            block_size=SAMPLE_BLOCK if ops is np else seed.shape[0],
        )
        return ops.reshape(ops.concatenate(blocks), (-1, self.n_features_in_))

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
        return list(self._layers())

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
        return self._layers()[-1].n_components

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


def seed_frames(history, n_sequences, *, width, n_features, dtype, seed_windows, rng):
    """Check a ``sample`` history; seeds of shape (n_sequences, width, n_features).

    ``None`` draws windows of real training frames from ``seed_windows``; a
    2-D history seeds every sequence with its last ``width`` rows; a 3-D one
    gives one seed per sequence.  Oldest frame first.
    """
    ops = array_ops(seed_windows)
    if history is None:
        picks = rng.integers(seed_windows.shape[0], size=n_sequences)
        return ops.take(seed_windows, picks, axis=0)
    if hasattr(history, "toarray") or hasattr(history, "tocsr"):
        raise TypeError("history must be a dense array, got a sparse matrix.")
    try:
        history = ops.asarray(history, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"history must be an array of numbers, got {type(history).__name__}."
        ) from exc
    if history.ndim == 2:
        history = ops.broadcast_to(history, (n_sequences, *history.shape))
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
    if not ops.all(ops.isfinite(history)):
        raise ValueError("history contains NaN or infinity.")
    return ops.ascontiguousarray(history[:, -width:, ...])


def check_context(context, n_frames, n_context, like, *, one_row=False):
    """``context`` as an array of ``like``'s namespace, dtype and device.

    Parameters
    ----------
    context : array-like of shape (n_frames, n_context) or None
        None passes through.
    n_frames : int
    n_context : int or None
        The columns a fitted model takes (0: none); None in ``fit``, where
        any number of columns but 0 is one.
    like : ndarray
    one_row : bool, default=False
        Whether one row may stand for every frame (then broadcast).

    Returns
    -------
    context : ndarray of shape (n_frames, n_context) or None
    """
    if context is None:
        return None
    if n_context == 0:
        raise ValueError(
            "This model was fitted without context, so it takes none: fit it "
            "with context= of shape (n_frames, n_context) to condition on one."
        )
    if hasattr(context, "toarray") or hasattr(context, "tocsr"):
        raise TypeError("context must be a dense array, got a sparse matrix.")
    ops = array_ops(like)
    try:
        context = ops.asarray(context, dtype=like.dtype)
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"context must be an array of numbers, got {type(context).__name__}."
        ) from exc
    rows = (1, n_frames) if one_row else (n_frames,)
    wanted = "(n_frames, n_context)" if n_context is None else f"(n, {n_context})"
    if (
        context.ndim != 2
        or context.shape[0] not in rows
        or context.shape[1] == 0
        or n_context not in (None, context.shape[1])
    ):
        frames = " or ".join(str(n) for n in rows)
        raise ValueError(
            f"context must have shape {wanted} with n = {frames}: one row of "
            f"context per frame; got shape {tuple(context.shape)}. A single "
            "signal is one column: context.reshape(-1, 1)."
        )
    if not bool(ops.all(ops.isfinite(context))):
        raise ValueError("context contains NaN or infinity.")
    if context.shape[0] != n_frames:
        context = ops.broadcast_to(context, (n_frames, context.shape[1]))
    return context


def generation_statistics(X, sequences, labels=None):
    """What ``sample`` judges generated motion against, from the training data.

    A :class:`~sklearn.utils.Bunch`: ``mean`` (every channel's mean),
    ``scale`` (the largest channel standard deviation), ``amplitude`` (the
    :func:`~sklearn_crbm.metrics.motion_amplitude` of the last
    ``LIVELINESS_FRAMES`` frames of every sequence, their mean weighted by
    those frames), ``reach`` (every channel's largest distance from its
    mean) and ``n_frames``.  Given the frames' label weights
    ``labels`` (shape ``(n_frames, n_classes)``), also ``label_amplitude``:
    that mean for each style alone, each sequence weighted by its frames'
    weight for the style, and ``label_weight``: those weights' sums.
    """
    X = to_numpy(X).astype(np.float64, copy=False)
    amplitudes = motion_amplitude(
        X, sequence_ids=sequences.per_frame_ids(), last_frames=LIVELINESS_FRAMES
    )
    weights = np.minimum(sequences.lengths, LIVELINESS_FRAMES)
    mean = X.mean(axis=0)
    statistics = Bunch(
        mean=mean,
        scale=float(X.std(axis=0).max()),
        amplitude=float(np.average(amplitudes, weights=weights)),
        reach=np.abs(X - mean).max(axis=0),
        n_frames=X.shape[0],
    )
    if labels is not None:
        labels = to_numpy(labels).astype(np.float64, copy=False)
        # each sequence's label weights summed over its last frames
        sums = np.array(
            [
                labels[stop - n : stop].sum(axis=0)
                for stop, n in zip(sequences.stops, weights, strict=True)
            ]
        )
        label_weight = sums.sum(axis=0)
        weighted = amplitudes @ sums
        statistics.update(
            label_amplitude=_ratio(weighted, label_weight), label_weight=label_weight
        )
    return statistics


def _ratio(numerator, denominator):
    """``numerator / denominator``, NaN where the denominator is 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(denominator > 0, numerator / denominator, np.nan)


def merge_statistics(old, new):
    """The :func:`generation_statistics` of two calls of ``partial_fit``, joined."""
    total = old.n_frames + new.n_frames
    share = new.n_frames / total
    mean = old.mean + share * (new.mean - old.mean)
    merged = Bunch(
        mean=mean,
        scale=max(old.scale, new.scale),
        amplitude=old.amplitude + share * (new.amplitude - old.amplitude),
        n_frames=total,
    )
    if "reach" in old and "reach" in new:  # at most this far from the new mean
        merged.reach = np.maximum(
            old.reach + np.abs(old.mean - mean), new.reach + np.abs(new.mean - mean)
        )
    if "label_amplitude" in old and "label_amplitude" in new:
        weight = old.label_weight + new.label_weight
        weighted = [
            np.nan_to_num(part.label_amplitude) * part.label_weight
            for part in (old, new)
        ]
        merged.update(
            label_amplitude=_ratio(weighted[0] + weighted[1], weight),
            label_weight=weight,
        )
    return merged


def reference_amplitude(statistics, labels=None):
    """The training amplitude a generated sequence is compared with.

    Given the label weights of its last frames (``labels``, shape
    ``(n_frames, n_classes)``) and statistics of a model fitted on labels:
    the styles' amplitudes (``label_amplitude``) weighted by the mean label
    weights of the last ``LIVELINESS_FRAMES`` frames, so that a slow style is
    judged against its own training takes; otherwise ``amplitude``.
    """
    if labels is None or "label_amplitude" not in statistics:
        return statistics.amplitude
    weights = to_numpy(labels)[-LIVELINESS_FRAMES:].mean(axis=0)
    known = np.isfinite(statistics.label_amplitude)
    if not np.any(weights[known] > 0):
        return statistics.amplitude
    return float(np.average(statistics.label_amplitude[known], weights=weights[known]))


def generated_liveliness(frames, n_frames, statistics, labels=None):
    """How much every generated sequence moves at its end, against training.

    The amplitude (:func:`~sklearn_crbm.metrics.motion_amplitude`) of the
    last ``LIVELINESS_FRAMES`` frames of every sequence of ``frames`` (long
    format, ``n_frames`` each) over :func:`reference_amplitude` (the
    training sequences', or those of the styles ``labels`` ask for): 1 moves
    as much as they do; NaN where fewer frames were generated.
    """
    n_sequences = len(frames) // n_frames
    reference = reference_amplitude(statistics, labels)
    if n_frames < LIVELINESS_FRAMES or not reference > 0:
        return np.full(n_sequences, np.nan)
    amplitude = motion_amplitude(
        np.nan_to_num(frames),  # what blew up is judged as blown, not here
        sequence_ids=np.repeat(np.arange(n_sequences), n_frames),
        last_frames=LIVELINESS_FRAMES,
    )
    return amplitude / reference


def lifeless_message(
    frames, n_frames, statistics, scale=None, labels=None, label_names=None
):
    """What went wrong with generated ``frames`` (long format), or "" if nothing.

    A sequence blew up when a value is non-finite, or more than
    ``BLOWN_DEVIATIONS`` times ``scale`` (default ``statistics.scale``) from
    the training mean and ``BLOWN_REACH`` times as far as its channel's
    training values went (``statistics.reach``, where kept);
    it died out when its :func:`generated_liveliness` (against the styles
    the label weights ``labels`` ask for, if given) is below
    ``DEAD_FRACTION`` (judged only when ``LIVELINESS_FRAMES`` frames or more
    were generated).  ``label_names`` (the model's ``classes_``) names the
    styles asked for.
    """
    sequences = frames.reshape(-1, n_frames, frames.shape[1])
    with np.errstate(invalid="ignore", over="ignore"):
        scale = statistics.scale if scale is None else scale
        distance = np.abs(sequences - statistics.mean) / scale
        distance = np.where(np.isfinite(distance), distance, np.inf)
        limit = BLOWN_DEVIATIONS
        if "reach" in statistics:
            limit = np.maximum(limit, BLOWN_REACH * statistics.reach / scale)
        over = (distance > limit).any(axis=(1, 2))
    reach = distance.max(axis=(1, 2))
    blown = np.flatnonzero(over)
    liveliness = generated_liveliness(frames, n_frames, statistics, labels)
    dead = np.setdiff1d(np.flatnonzero(liveliness < DEAD_FRACTION), blown)
    compared = "the training sequences"
    if labels is not None and "label_amplitude" in statistics:
        compared += " of the style asked for" + _styles_asked(labels, label_names)
    parts = []
    if len(blown):
        parts.append(
            f"{_count(blown, len(sequences))} blew up (values up to "
            f"{reach[blown].max():.3g} training standard deviations from the "
            "training mean, beyond where the training frames went, or "
            "non-finite). Train longer (n_iter), lower "
            "learning_rate, or seed with real frames (history=)."
        )
    if len(dead):
        parts.append(
            f"{_count(dead, len(sequences))} died out: over the last "
            f"{LIVELINESS_FRAMES} frames, moving at most "
            f"{liveliness[dead].max():.2f} times as much as {compared} "
            f"(below {DEAD_FRACTION}: the motion came to rest). "
            "Train for more updates (raise n_iter) or on more frames, or seed "
            "with real frames of the motion wanted (history=); see the user "
            "guide's 'Training on your own corpus'."
        )
    return " ".join(parts)


def _styles_asked(labels, label_names):
    """``" ('fast')"``, or ``" ('fast' 0.5, 'slow' 0.5)"`` for a blend: the
    styles of the label weights of the frames judged, with their weights;
    "" without names."""
    if label_names is None:
        return ""
    weights = to_numpy(labels)[-LIVELINESS_FRAMES:].mean(axis=0)
    asked = np.flatnonzero(weights > 0)
    asked = asked[np.argsort(-weights[asked], kind="stable")]
    names = [np.asarray(label_names)[k] for k in asked]
    names = [repr(n.item() if isinstance(n, np.generic) else n) for n in names]
    if len(asked) == 1:
        return f" ({names[0]})"
    weighted = (f"{n} {weights[k]:.2f}" for n, k in zip(names, asked, strict=True))
    return " (" + ", ".join(weighted) + ")"


def _caller_level():
    """The ``stacklevel`` that points a warning at the first caller outside the
    package (through ``MotionPipeline.sample`` and the thread decorators)."""
    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = inspect.currentframe().f_back, 1
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    return level


def _count(indices, n_sequences):
    """``"Sequence 2 of 3"`` or ``"Sequences 0, 2 of 3"``."""
    noun = "Sequence" if len(indices) == 1 else "Sequences"
    listed = ", ".join(str(int(k)) for k in indices[:10])
    more = ", ..." if len(indices) > 10 else ""
    return f"{noun} {listed}{more} of {n_sequences}"


def evenly_spaced(values, at_most):
    """At most ``at_most`` entries of ``values``, evenly spaced, first and last kept."""
    if len(values) <= at_most:
        return values
    return values[np.linspace(0, len(values) - 1, at_most).round().astype(np.intp)]


def check_count(value, name, minimum):
    """``value`` as an int; a ValueError naming ``name`` unless it is one >= minimum."""
    if isinstance(value, bool) or not isinstance(value, Integral) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}.")
    return int(value)
