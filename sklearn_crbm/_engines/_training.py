"""Training any conditional layer by contrastive divergence, epoch by epoch.

:func:`train_epochs` runs the loop every estimator shares: minibatches
gathered by index arithmetic, noise on their histories, the layer's own
CD statistics (:meth:`~sklearn_crbm.layers.ConditionalLayer.cd_statistics`),
momentum and weight decay (:class:`~sklearn_crbm.layers._parameters.MomentumUpdate`),
parameter averaging, and a check for divergence after every epoch.
:class:`ProgressMonitor` reports what ``verbose`` asks for.
"""

import math
import time
from dataclasses import dataclass

import numpy as np

from ..exceptions import TrainingDivergedError
from ..layers._parameters import MomentumUpdate, ParameterAverage
from ..utils._array_api import array_ops, array_random, to_device_batches
from ..utils._random import add_history_noise, rng_from
from ..utils._sequences import balanced_batches, frame_history, shuffled_batches
from ._gibbs import mean_field_prediction

__all__ = ["ProgressMonitor", "Schedule", "UpdateBudget", "train_epochs"]

# Frames the progress report predicts one step ahead (evenly spaced).
MONITOR_FRAMES = 1000
# Mean-field iterations of those predictions.
MONITOR_MEAN_FIELD_STEPS = 10
ONE_STEP_EXPLANATION = (
    "one-step error: RMS error per channel of predicting each training frame "
    "from its past. A model that learns the motion predicts better than "
    "repeating the previous frame; one that stays worse has not learnt how "
    "the motion goes on, and its generated motion tends to die out: train "
    "for more updates (n_iter) or on more frames."
)


@dataclass(frozen=True)
class UpdateBudget:
    """What ``n_iter="auto"`` trains on a corpus, in minibatch updates.

    ``epochs`` epochs, but at least ``min_updates`` and at most
    ``max_updates`` minibatch updates, in whole epochs (at least one): a
    corpus of short takes gets as many updates as a larger one, and a large
    corpus the updates of a medium one, each frame seen fewer times.  When
    ``max_updates`` shortens training, the epochs that ``momentum_delay``
    and ``momentum_ramp`` count are ``max_updates / epochs`` updates long
    (:meth:`epoch_updates`), so that momentum starts at the same fraction
    of training whatever the corpus's size.
    """

    epochs: int
    min_updates: int = 0
    max_updates: int | None = None

    def n_epochs(self, n_frames, batch_size):
        """The epochs to train on ``n_frames`` trainable frames."""
        batches = math.ceil(n_frames / batch_size)
        epochs = max(self.epochs, math.ceil(self.min_updates / batches))
        if self.max_updates is not None and epochs * batches > self.max_updates:
            epochs = max(1, self.max_updates // batches)
        return epochs

    def epoch_updates(self, n_frames, batch_size):
        """The updates an epoch of the momentum schedule lasts (None: an epoch's)."""
        if self.n_epochs(n_frames, batch_size) >= self.epochs:
            return None
        return self.max_updates / self.epochs


@dataclass(frozen=True)
class Schedule:
    """How an estimator trains: its hyper-parameters of contrastive divergence."""

    learning_rate: float
    momentum: float
    momentum_delay: int
    weight_decay: float
    cd_steps: int
    batch_size: int
    batching: str
    history_noise: float
    history_noise_fraction: float
    momentum_ramp: int = 0
    max_step: float | None = None
    epoch_updates: float | None = None

    @classmethod
    def of(cls, estimator, **given):
        """The schedule an estimator's parameters of the same names give
        (those it does not have keep their defaults), and ``given``."""
        params = {**estimator.get_params(deep=False), **given}
        names = [name for name in cls.__dataclass_fields__ if name in params]
        return cls(**{name: params[name] for name in names})

    def momentum_of_update(self, updates_done, batches_per_epoch):
        """Momentum of the update after ``updates_done``, when ``epoch_updates``
        updates count as an epoch (None: ``batches_per_epoch``)."""
        if self.epoch_updates is None:
            return self.momentum_at(updates_done // batches_per_epoch)
        return self.momentum_at(int(updates_done // self.epoch_updates))

    def momentum_at(self, epochs_done):
        """Momentum of the epoch after ``epochs_done``: none for the first
        ``momentum_delay`` epochs, then rising linearly to ``momentum`` over
        ``momentum_ramp`` epochs."""
        ramped = epochs_done - self.momentum_delay + 1
        if ramped <= 0:
            return 0.0
        return self.momentum * min(1.0, ramped / (self.momentum_ramp + 1))


class ProgressMonitor:
    """What a training loop prints with ``verbose``: is the model learning?

    Every ``verbose`` epochs: the epoch, the one-step prediction error of
    the model on (up to ``MONITOR_FRAMES``) training frames, as the root mean
    squared error per channel of the mean-field prediction of each frame
    from its clean past, beside that of simply repeating the previous frame,
    the mean squared reconstruction error of the epoch, and the time.  A
    model that learns predicts better than the previous frame, and better
    as training goes on.

    Parameters
    ----------
    name : str
        The estimator's class name.
    verbose : int
        Report every ``verbose`` epochs (0: never).
    X : ndarray of shape (n_frames, n_features)
    frames : ndarray of int
        The trainable frames.
    context : ndarray of shape (n_frames, n_context) or None
    """

    def __init__(self, name, verbose, X, frames, context=None):
        self.name = name
        self.verbose = verbose
        self._start = time.perf_counter()
        if not verbose:
            return
        picks = frames
        if len(frames) > MONITOR_FRAMES:
            picks = frames[np.linspace(0, len(frames) - 1, MONITOR_FRAMES).astype(int)]
        ops = array_ops(X)
        self._rows = picks
        self._X = X
        self._targets = ops.take(X, picks, axis=0)
        self._context = None if context is None else ops.take(context, picks, axis=0)
        previous = ops.take(X, picks - 1, axis=0)
        self.previous_frame_error = _rms(self._targets - previous)

    def one_step_error(self, layer):
        """RMS error per channel of the layer's one-step predictions."""
        history = frame_history(self._X, self._rows, layer.n_lags)
        rbms = layer.frame_rbms(history, self._context)
        prediction = mean_field_prediction(rbms, MONITOR_MEAN_FIELD_STEPS)
        return _rms(self._targets - prediction)

    def is_due(self, epoch):
        """Whether ``epoch`` (counted from 1) is one to report."""
        return bool(self.verbose) and epoch % self.verbose == 0

    def report(self, epoch, layer, reconstruction_error):
        """Print the line of ``epoch`` for the layer as it is after it (the
        first line says what the one-step error means)."""
        if not hasattr(self, "_explained"):
            self._explained = True
            print(f"[{self.name}] {ONE_STEP_EXPLANATION}")
        error = self.one_step_error(layer)
        verdict = "better" if error < self.previous_frame_error else "WORSE"
        print(
            f"[{self.name}] epoch {epoch}: one-step error {error:.4f} "
            f"({verdict} than repeating the previous frame: "
            f"{self.previous_frame_error:.4f}), reconstruction "
            f"error {reconstruction_error:.4f}, time "
            f"{time.perf_counter() - self._start:.1f}s"
        )


class StepBound:
    """Each weight matrix's step per minibatch, at most ``max_step`` times its norm.

    Wraps a :class:`~sklearn_crbm.layers._parameters.MomentumUpdate`: after its
    step, the velocity of every decayed group (every weight matrix; not the
    biases) whose norm exceeds ``max_step`` times the matrix's norm before
    the step is scaled down to it, and the step with it.  The velocity
    carries the bound into the next steps.  Three-way weights feed back on
    themselves (their statistics are products of the others): once a step
    outgrows the weights, the next statistics grow with it and training
    overflows within a few minibatches; bounded, the step grows the
    weights by at most a fixed factor per minibatch and the chain catches up.
    """

    def __init__(self, update, max_step):
        self.update = update
        self.max_step = max_step
        params = update.params
        offsets = np.cumsum(
            [0] + [math.prod(g.shape(params)) for g in self._sorted(params)]
        )
        self._parts = [
            slice(int(start), int(stop))
            for group, start, stop in zip(
                self._sorted(params), offsets[:-1], offsets[1:], strict=True
            )
            if group.decayed
        ]

    @staticmethod
    def _sorted(params):
        return sorted(params.groups, key=lambda group: not group.decayed)

    @property
    def statistics(self):
        return self.update.statistics

    @property
    def velocity(self):
        return self.update.velocity

    def _norms(self, flat):
        ops = array_ops(flat)
        return [ops.sqrt(ops.matmul(flat[part], flat[part])) for part in self._parts]

    def apply(self, momentum, learning_rate, weight_decay):
        """The momentum step, then each weight matrix's step bounded."""
        parameters, velocity = self.update.params.flat, self.update.velocity.flat
        ops = array_ops(parameters)
        limits = self._norms(parameters)
        self.update.apply(momentum, learning_rate, weight_decay)
        for part, limit, norm in zip(
            self._parts, limits, self._norms(velocity), strict=True
        ):
            if ops is np and not norm > self.max_step * limit:
                continue  # the common case, without a pass over the matrix
            scale = ops.minimum(self.max_step * limit / norm, 1.0)
            step = velocity[part]
            parameters[part] -= (1.0 - scale) * step
            step *= scale


def _rms(difference):
    ops = array_ops(difference)
    return float(ops.sqrt(ops.mean(difference * difference)))


def _divergence_message(schedule, epoch):
    """What a diverged training says: where, and what to change."""
    bounded = (
        ""
        if schedule.max_step is None
        else f" or max_step (now {schedule.max_step}), or raise momentum_ramp"
    )
    return (
        f"Training diverged at epoch {epoch}: the weights became non-finite with "
        f"learning_rate={schedule.learning_rate} and momentum={schedule.momentum}. "
        f"Lower the learning rate{bounded}, and standardise the data, e.g. with "
        "sklearn_crbm.preprocessing.StandardScaler."
    )


# Diverging weights overflow in the products before the epoch's check
# raises TrainingDivergedError, which says what to do.
@np.errstate(over="ignore", invalid="ignore")
def train_epochs(
    layer,
    velocity,
    X,
    frames,
    schedule,
    random_state,
    n_epochs,
    *,
    epochs_done=0,
    context=None,
    n_averaged=0,
    monitor=None,
):
    """``n_epochs`` epochs of contrastive divergence on the frames of ``X``.

    Parameters
    ----------
    layer : ConditionalLayer
        The start; not changed.
    velocity : PackedParameters or None
        The momentum carried over from earlier epochs (None: zeros).
    X : ndarray of shape (n_frames, n_features)
    frames : ndarray of int
        The trainable frames (those with a full past in their sequence).
    schedule : Schedule
    random_state : RandomState
        Draws one seed per epoch (minibatches, then the math's draws).
    n_epochs : int
    epochs_done : int, default=0
        Epochs trained before (momentum starts after ``momentum_delay``).
    context : ndarray of shape (n_frames, n_context), default=None
        Every frame's context, for a layer that uses one.
    n_averaged : int, default=0
        The layer returned is the mean of the parameters at the ends of the
        last ``n_averaged`` epochs (0: the last epoch's).
    monitor : ProgressMonitor, default=None

    Returns
    -------
    layer : ConditionalLayer
        The trained parameters, in the fitted form (C order).
    velocity : PackedParameters
        The momentum, to carry over.
    reconstruction_error : float
        Mean squared reconstruction error per frame of the last epoch.

    Raises
    ------
    TrainingDivergedError
        When the parameters become non-finite.
    """
    params = layer.training_copy()
    update = MomentumUpdate(params, velocity)
    if schedule.max_step is not None:
        update = StepBound(update, schedule.max_step)
    # Minibatches gather rows: from a Fortran-ordered X (what many
    # transformers return) every row would be a strided read.
    ops = array_ops(X)
    X = ops.ascontiguousarray(X)
    plan_batches = (
        balanced_batches if schedule.batching == "balanced" else shuffled_batches
    )
    workspace = params.new_workspace(schedule.batch_size)
    noise_buffer = ops.empty_like(workspace.history) if schedule.history_noise else None
    average = ParameterAverage()
    reconstruction_error = math.nan
    for epoch in range(n_epochs):
        rng = rng_from(random_state)
        # minibatches are planned with numpy; the math draws on X's device
        math_rng = array_random(rng, X)
        done = epochs_done + epoch
        squared_error = 0.0
        batches = plan_batches(frames, schedule.batch_size, rng)
        n_batches = len(batches)
        if ops is not np:  # the epoch's plan reaches the device in one copy
            batches = to_device_batches(batches, ops)
        for i, batch in enumerate(batches):
            momentum = schedule.momentum_of_update(done * n_batches + i, n_batches)
            n = batch.shape[0]
            visible = ops.take(X, batch, axis=0, out=workspace.visible(n), mode="clip")
            history = frame_history(
                X, batch, params.n_lags, out=workspace.history[:n, ...]
            )
            if schedule.history_noise:
                add_history_noise(
                    math_rng,
                    history,
                    schedule.history_noise,
                    X.shape[1],
                    schedule.history_noise_fraction,
                    noise_buffer[:n, ...],
                )
            batch_context = (
                None if context is None else ops.take(context, batch, axis=0)
            )
            _, error = params.cd_statistics(
                visible,
                history,
                batch_context,
                schedule.cd_steps,
                math_rng,
                out=update.statistics,
                scale=schedule.learning_rate / n,
                workspace=workspace,
            )
            squared_error += error
            update.apply(momentum, schedule.learning_rate, schedule.weight_decay)
            params.after_update()
        squared_error = float(squared_error)  # one device sync per epoch
        reconstruction_error = squared_error / len(frames)
        if not params.is_finite() or not math.isfinite(squared_error):
            raise TrainingDivergedError(_divergence_message(schedule, done + 1))
        if monitor is not None and monitor.is_due(done + 1):
            monitor.report(done + 1, params.fitted_copy(), reconstruction_error)
        if epoch >= n_epochs - n_averaged:
            average.add(params.fitted_copy())
    fitted = average.mean if average.count else params.fitted_copy()
    return fitted, update.velocity, reconstruction_error
