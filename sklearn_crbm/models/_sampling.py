"""Generation: the seed windows kept at fit, ``sample``, and judging its output.

:class:`SamplingMixin` gives :class:`~sklearn_crbm.models._base.BaseCRBM`
:meth:`~SamplingMixin.sample`: seeds from the windows of training frames
that ``fit`` keeps (``seed_windows_``), the on-line loop
(:mod:`sklearn_crbm._engines._online`) run on the model's layers, and a
:class:`~sklearn_crbm.exceptions.GenerationWarning` for sequences that died
out or blew up (:mod:`sklearn_crbm.metrics._liveliness`).
"""

import inspect
import os
import warnings
from numbers import Real

import numpy as np
from sklearn.utils.validation import check_is_fitted

from .._engines._online import TOP_LAYER, History, run_online
from ..exceptions import GenerationWarning
from ..metrics._liveliness import (
    generation_statistics,
    lifeless_message,
    merge_statistics,
)
from ..utils._array_api import array_ops, array_random, to_numpy
from ..utils._parallel import SAMPLE_BLOCK, map_sequence_blocks
from ..utils._random import rng_from
from ..utils._threads import limit_blas_threads, sequence_rows
from ..utils._validation import check_count

__all__ = ["SamplingMixin", "seed_frames"]

# How many windows of training frames ``fit`` keeps to seed ``sample``.
MAX_SEED_WINDOWS = 500
# Gibbs iterations per generated frame of a model without an ``n_gibbs``.
DEFAULT_N_GIBBS = 30
# What sample does for a model without the parameters n_mean_field and
# hidden_drift (a layer model defined outside the package).
DEFAULT_N_MEAN_FIELD = 10
DEFAULT_HIDDEN_DRIFT = 0.0
# Standard deviation of the jitter added to the previous frame to start the
# Gibbs chain of a new frame (the original code's gen.m).
START_JITTER = 0.01


class SamplingMixin:
    """Generation for :class:`~sklearn_crbm.models._base.BaseCRBM`.

    Hooks, which a model overrides where it differs: ``_liveliness_labels``
    (the label weights generated motion is judged by), ``_chain_rng`` (in
    :class:`~sklearn_crbm.models._base.BaseCRBM`) and ``_start_jitter``.
    """

    # Noise on the previous frame where a new frame's Gibbs chain starts.
    _start_jitter = START_JITTER

    @limit_blas_threads(sequence_rows)
    def sample(
        self,
        n_samples,
        *,
        history=None,
        y=None,
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
        y : label, mapping or array-like, default=None
            A model fitted on labels: the labels of the new frames, as ``y``
            in :meth:`fit`.  One factor: a label for every frame or one per
            frame, shape ``(n_samples,)``.  Several factors: one row of
            labels, one per factor, for every frame (``("run",
            "elderly")``), or one row per frame, shape ``(n_samples,
            n_outputs)``: changing a factor's label between frames switches
            it on-line.  In place of a label, a factor's entry may be a blend
            of its labels, a mapping ``{label: weight}`` of weights that sum
            to 1 (``("walk", {"elderly": 0.5, "youthful": 0.5})``).
        context : array-like of shape (n_samples, n_context) or (1, n_context), \
default=None
            The context of every new frame (one row: the same for all),
            for every sequence; needed by a model fitted with a context.
            Changing it over the frames steers the motion (a transition).
        style : label or array-like of shape (n_samples, n_classes), default=None
            The labels of a model of one label factor, in place of ``y``: a
            label seen in :meth:`fit`, one per frame, or non-negative label
            weights that sum to 1 in every frame (a blend; a transition when
            they change over the frames).  For a model of several factors,
            as ``y``.
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
        context = self._method_context(
            context, style, n_samples, like, one_row=True, y=y
        )
        if context is None and self.n_context_:
            raise self._missing_context_error()
        labels = self._liveliness_labels(context)  # before it is broadcast
        rng = rng_from(self.random_state if random_state is None else random_state)
        seed = seed_frames(
            history,
            n_sequences,
            width=max(self.history_length, 1),
            n_features=self.n_features_in_,
            dtype=self._fitted_layers()[0].dtype,
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

    def _context_names(self):
        """What each column of the context is called in messages (None: nothing)."""
        return getattr(self, "classes_", None)

    def _check_generated(self, frames, n_frames, labels=None):
        """Warn with a :class:`GenerationWarning` about sequences that died out
        or blew up (a model fitted before ``generation_statistics_`` existed
        is not judged)."""
        statistics = getattr(self, "generation_statistics_", None)
        if statistics is None:
            return
        # binary visibles stay within [0, 1]: only non-finite values blew up
        scale = np.inf if self._fitted_layers()[0].binary else statistics.scale
        message = lifeless_message(
            to_numpy(frames),
            n_frames,
            statistics,
            scale,
            labels,
            self._context_names(),
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
        layers = self._fitted_layers()
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
        return ops.astype(windows, self._fitted_layers()[0].dtype, copy=True)

    def _merge_seed_windows(self, new):
        """Seed windows of a ``partial_fit`` call joined to the earlier ones."""
        ops = array_ops(new)
        windows = ops.concatenate((self.seed_windows_, new))
        picks = evenly_spaced(np.arange(windows.shape[0]), MAX_SEED_WINDOWS)
        return ops.take(windows, picks, axis=0)


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


def evenly_spaced(values, at_most):
    """At most ``at_most`` entries of ``values``, evenly spaced, first and last kept."""
    if len(values) <= at_most:
        return values
    return values[np.linspace(0, len(values) - 1, at_most).round().astype(np.intp)]


def _caller_level():
    """The ``stacklevel`` that points a warning at the first caller outside the
    package (through ``MotionPipeline.sample`` and the thread decorators)."""
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # models/..
    frame, level = inspect.currentframe().f_back, 1
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    return level
