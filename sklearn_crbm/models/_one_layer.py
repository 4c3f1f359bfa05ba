"""What the one-layer models share: one conditional layer, trained by CD.

:class:`BaseLayerModel` is the base of :class:`~sklearn_crbm.ConditionalRBM`
and, through :class:`~sklearn_crbm.models._style.BaseStyleModel`, of
:class:`~sklearn_crbm.FactoredCRBM` and :class:`~sklearn_crbm.LabelledCRBM`.
"""

import math
from abc import abstractmethod
from functools import partial
from numbers import Integral, Real

import numpy as np
from sklearn.base import _fit_context
from sklearn.utils import check_random_state
from sklearn.utils._array_api import get_namespace_and_device, move_to
from sklearn.utils._param_validation import Interval
from sklearn.utils.validation import validate_data

from .._engines._training import ProgressMonitor, Schedule, train_epochs
from ..utils._array_api import array_ops
from ..utils._fitting import unfitted_on_error
from ..utils._random import rng_from
from ..utils._sequences import (
    check_sequence_ids,
    validation_split,
    warn_if_sequences_unmarked,
)
from ..utils._threads import batch_rows, limit_blas_threads
from ._base import BaseCRBM

__all__ = ["BaseLayerModel"]

# ``n_iter="auto"``: at least AUTO_EPOCHS epochs, and enough of them for
# AUTO_UPDATES minibatch updates (what 1000 epochs of 25 minibatches give:
# CMU subject 35, 26-28 minibatches an epoch, trains 1000 epochs).
AUTO_EPOCHS, AUTO_UPDATES = 1000, 25_000


class BaseLayerModel(BaseCRBM):
    """Base class of the models that are one conditional layer trained by CD.

    :meth:`fit` and :meth:`partial_fit` validate the data, draw the layer's
    start parameters and train them with
    :func:`~sklearn_crbm._engines._training.train_epochs` (with early stopping on
    held-out sequences if asked), keeping windows of real frames to seed
    :meth:`sample`.  Subclasses provide the hooks ``_new_layer`` (the layer,
    not yet initialised) and, where they need them, ``_check_training_data``
    (checks of the data against the parameters) and ``_start_parameters``
    (a start other than the random one).
    """

    _parameter_constraints: dict = {
        **BaseCRBM._parameter_constraints,
        "ais_steps": [Interval(Integral, 1, None, closed="left")],
        "ais_chains": [Interval(Integral, 1, None, closed="left")],
        "early_stopping": ["boolean"],
        "validation_fraction": [Interval(Real, 0, 1, closed="neither")],
        "n_iter_no_change": [Interval(Integral, 1, None, closed="left")],
        "validation_interval": [Interval(Integral, 1, None, closed="left")],
        "tol": [Interval(Real, 0, None, closed="left")],
        "history_noise_fraction": [Interval(Real, 0, 1, closed="right")],
        "average_fraction": [Interval(Real, 0, 1, closed="left")],
    }

    # Private state that a failed fit must forget with the fitted attributes:
    # the layer (which the public attributes view) and the velocities.
    _training_state = ("_layer", "_velocity")

    # ---------------------------------------------------------------- hooks

    @abstractmethod
    def _new_layer(self, n_features, n_context, dtype):
        """The model's layer for ``n_features`` visible units and ``n_context``
        columns of context, not initialised."""

    def _check_training_data(self, X):
        """Raise a ValueError if the parameters cannot model ``X``."""

    def _start_parameters(self, X, frames, context):
        """Change the random start of the layer where the parameters ask for it."""

    # ------------------------------------------------------------------ fit

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None, context=None):
        """Train the model on sequences of frames.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,) or (n_frames, n_outputs), default=None
            The labels of every frame, for the style models
            (:class:`~sklearn_crbm.FactoredCRBM`,
            :class:`~sklearn_crbm.LabelledCRBM`), which turn them into their
            context; ignored by :class:`~sklearn_crbm.ConditionalRBM`.  One
            label per frame (one label factor, such as a style), or one
            column per label factor (such as content and style), as
            scikit-learn's multi-output classifiers take them; each
            factor's label is a one-hot block of the context.  In place of
            a label, a factor's entry may be a blend of its labels, a
            mapping ``{label: weight}`` of weights that sum to 1.  A 2-D
            ``y`` of floats is refused: label weights are written as such
            mappings.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's real-valued context (control signals such as
            speed): :class:`~sklearn_crbm.ConditionalRBM` and
            :class:`~sklearn_crbm.LabelledCRBM` add it to their dynamic
            biases, :class:`~sklearn_crbm.FactoredCRBM` gates its factors
            with it.  The model standardises a real-valued context with the
            mean and standard deviation of this call's (``context_mean_``,
            ``context_scale_``), so it may be given in any unit.  A model
            fitted with a context needs one in every method that computes
            (``n_context_`` columns).  Not with ``y``.

        Returns
        -------
        self : object
            The fitted model.
        """
        warn_if_sequences_unmarked(X, sequence_ids, f"{type(self).__name__}.fit")
        with unfitted_on_error(self):
            xp, _ = get_namespace_and_device(X)[:2]
            X = validate_data(self, X, dtype=[xp.float64, xp.float32], reset=True)
            sequences, frames = self._check_sequences(X, sequence_ids)
            context = self._context_for_fit(X, y, context, reset=True)
            self.random_state_ = check_random_state(self.random_state)
            self._initialize(X, context)
            if self.early_stopping:
                self._train_with_early_stopping(X, sequences, context)
            else:
                self._start_parameters(X, frames, context)
                n_epochs = self._n_epochs(len(frames))
                n_averaged = math.ceil(self.average_fraction * n_epochs)
                self._train(X, frames, n_epochs, n_averaged, context)
            self._keep_seeds(X, sequences, context=context)
        return self

    @limit_blas_threads(batch_rows)
    @_fit_context(prefer_skip_nested_validation=True)
    def partial_fit(self, X, y=None, *, sequence_ids=None, context=None):
        """Train for one epoch on the given sequences, keeping the current state.

        The first call initialises the model; later calls continue from the
        current parameters, momentum and epoch count.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,) or (n_frames, n_outputs), default=None
            The labels of every frame, as in :meth:`fit`.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        context : array-like of shape (n_frames, n_context), default=None
            Every frame's context, as in :meth:`fit` (of the width of the
            first call's).

        Returns
        -------
        self : object
            The updated model.
        """
        first_call = not hasattr(self, "_layer")
        # bad input leaves a fitted model as it was; divergence unfits it
        with unfitted_on_error(self, Exception if first_call else ()):
            xp = get_namespace_and_device(X)[0]
            if not first_call:
                self._check_namespace(X, "partial_fit")
            X = validate_data(
                self,
                X,
                dtype=[xp.float64, xp.float32] if first_call else self._layer.dtype,
                reset=first_call,
            )
            sequences, frames = self._check_sequences(X, sequence_ids)
            context = self._context_for_fit(X, y, context, reset=first_call)
        with unfitted_on_error(self):
            if first_call:
                self.random_state_ = check_random_state(self.random_state)
                self._initialize(X, context)
                self._start_parameters(X, frames, context)
            self._train(X, frames, 1, context=context)
        self._keep_seeds(X, sequences, merge=True, context=context)
        return self

    def _fitted_layers(self):
        return [self._layer]

    def _planned_layers(self, n_features):
        return [self._new_layer(n_features, 0, np.float64)]

    def _n_epochs(self, n_frames):
        """The epochs ``fit`` trains on ``n_frames`` trainable frames.

        ``n_iter``, or for ``"auto"`` enough epochs for ``AUTO_UPDATES``
        minibatch updates, at least ``AUTO_EPOCHS``: a corpus of short takes
        gets as many parameter updates as a larger one.
        """
        if self.n_iter != "auto":
            return self.n_iter
        batches_per_epoch = math.ceil(n_frames / self.batch_size)
        return max(AUTO_EPOCHS, math.ceil(AUTO_UPDATES / batches_per_epoch))

    def _ais_settings(self):
        return self.ais_steps, self.ais_chains

    def _check_sequences(self, X, sequence_ids):
        """Validate ids and data; return the sequences and trainable frames."""
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        self._check_training_data(X)
        n_lags = self._planned_layers(X.shape[1])[0].n_lags
        frames = sequences.valid_frames(n_lags)
        if len(frames) == 0:
            longest = int(sequences.lengths.max()) if len(sequences.lengths) else 0
            noun = "sample" if longest == 1 else "samples"
            raise ValueError(
                f"No frame has {n_lags} past frames in its own sequence: the "
                f"longest sequence has {longest} {noun}, but a model of order "
                f"{n_lags} needs sequences of at least {n_lags + 1} "
                "frames. Pass longer sequences (check sequence_ids) or lower order."
            )
        return sequences, frames

    def _initialize(self, X, context):
        """Draw the start parameters, in the namespace and on the device of ``X``.

        They are drawn with numpy (the same numbers for every namespace) and
        moved to ``X``'s namespace and device.
        """
        ops = array_ops(X)
        dtype = np.float32 if X.dtype == ops.float32 else np.float64
        n_context = 0 if context is None else context.shape[1]
        layer = self._new_layer(X.shape[1], n_context, dtype)
        layer.initialize(rng_from(self.random_state_))
        if ops is not np:
            xp, _, device = get_namespace_and_device(X)
            layer = layer.__sklearn_array_api_convert__(
                partial(move_to, xp=xp, device=device)
            )
        self.n_iter_ = 0
        self._layer = layer
        self._velocity = None

    def _train(self, X, frames, n_epochs, n_averaged=0, context=None):
        """``n_epochs`` epochs of CD; the parameters kept are the mean of those
        at the ends of the last ``n_averaged`` epochs (0: the last epoch's)."""
        self._layer, self._velocity, self.reconstruction_error_ = train_epochs(
            self._layer,
            self._velocity,
            X,
            frames,
            Schedule.of(self),
            self.random_state_,
            n_epochs,
            epochs_done=self.n_iter_,
            context=context,
            n_averaged=n_averaged,
            monitor=ProgressMonitor(
                type(self).__name__, self.verbose, X, frames, context
            ),
        )
        self.n_iter_ += n_epochs

    def _train_with_early_stopping(self, X, sequences, context):
        """Train on some sequences, keep the parameters that score best on the rest."""
        rng = rng_from(self.random_state_)
        held = validation_split(sequences, self.validation_fraction, rng)
        ids = sequences.per_frame_ids()
        ops = array_ops(X)
        parts = []
        for mask in (~held, held):
            part = check_sequence_ids(ids[mask], int(mask.sum()))
            frames = part.valid_frames(self.history_length)
            if len(frames) == 0:
                raise ValueError(
                    f"early_stopping: no {'validation' if mask is held else 'training'}"
                    f" frame has {self.history_length} past frames in its sequence; "
                    "pass longer sequences or raise validation_fraction."
                )
            rows = np.flatnonzero(mask)
            part_context = None if context is None else ops.take(context, rows, axis=0)
            parts.append((ops.take(X, rows, axis=0), part, frames, part_context))
        (X_train, _, train_frames, train_context) = parts[0]
        (X_valid, valid, valid_frames, valid_context) = parts[1]
        self._start_parameters(X_train, train_frames, train_context)
        # the same random numbers at every check: changes are the model's
        seed = int(rng.integers(np.iinfo(np.int32).max))
        self.validation_scores_ = []
        best, best_iter, best_layer = -np.inf, 0, None
        n_epochs = self._n_epochs(len(train_frames))
        while self.n_iter_ < n_epochs:
            epochs = min(self.validation_interval, n_epochs - self.n_iter_)
            self._train(X_train, train_frames, epochs, context=train_context)
            log_likelihood = self._log_likelihood(
                X_valid, valid, rng=np.random.default_rng(seed), context=valid_context
            ).log_likelihood
            ops = array_ops(log_likelihood)
            score = float(ops.mean(ops.take(log_likelihood, valid_frames, axis=0)))
            self.validation_scores_.append(score)
            if self.verbose:
                print(
                    f"[{type(self).__name__}] epoch {self.n_iter_}: validation "
                    f"log-likelihood {score:.4f} per frame"
                )
            if score > best + self.tol or best_layer is None:
                best, best_iter = float(score), self.n_iter_
                best_layer = self._layer.copy()
            elif self.n_iter_ - best_iter >= self.n_iter_no_change:
                break
        self._layer = best_layer
        self.best_validation_score_ = best

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.array_api_support = True
        return tags
