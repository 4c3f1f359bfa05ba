"""What a layer model conditioned on a style per frame adds: labels in and out.

A style model's layer takes every frame's label weights ``y`` (one-hot for a
labelled frame, any non-negative weights that sum to 1 for a blend) as its
context.  :class:`BaseStyleModel` turns labels into those weights in
``fit``, ``transform``, ``score`` and ``sample``, names the style of a
sequence by Bayes' rule (``predict_proba``), and scores frames whose style
is not given under the mixture of styles, each weighted by its posterior
given the frames before.
"""

import hashlib
import weakref
from numbers import Integral, Real

import numpy as np
from scipy.special import logsumexp
from sklearn.base import clone
from sklearn.utils._array_api import _estimator_with_converted_arrays
from sklearn.utils.validation import check_is_fitted

from ._base import check_count, seed_frames
from ._base_layer import BaseLayerModel
from .utils._array_api import array_ops, to_numpy
from .utils._random import rng_from
from .utils._threads import frame_rows, limit_blas_threads, sequence_rows

__all__ = ["BaseStyleModel", "check_label_weights"]

# How far a row of label weights may sum from 1.
_WEIGHT_SUM_TOLERANCE = 1e-6
# Each estimator's last posterior and the digest of what it came from (see
# BaseStyleModel._posterior); weak keys: nothing is kept for a deleted model.
_RECENT_POSTERIORS = weakref.WeakKeyDictionary()


def check_label_weights(weights, n_classes, name="style"):
    """``weights`` as a float64 array of rows of non-negative weights summing to 1."""
    try:
        weights = np.asarray(weights, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} weights must be numbers, got {weights!r}.") from exc
    if weights.ndim != 2 or weights.shape[1] != n_classes:
        raise ValueError(
            f"{name} weights must have shape (n_frames, {n_classes}): one weight "
            f"per style and frame; got shape {weights.shape}."
        )
    if not np.all(np.isfinite(weights)):
        raise ValueError(f"{name} weights contain NaN or infinity.")
    if np.any(weights < 0):
        raise ValueError(f"{name} weights must be non-negative.")
    sums = weights.sum(axis=1)
    if np.any(np.abs(sums - 1) > _WEIGHT_SUM_TOLERANCE):
        worst = sums[np.argmax(np.abs(sums - 1))]
        raise ValueError(
            f"{name} weights must sum to 1 in every frame; a frame's sum to "
            f"{worst:g}. Divide each row by its sum."
        )
    return weights


def _labels_that_compare(name):
    """The error for labels that cannot be sorted together (str and int, None)."""
    return TypeError(
        f"{name} holds style labels that cannot be compared with each other or "
        "with the styles seen in fit (such as strings and numbers mixed, or None): "
        "give labels of one kind."
    )


def _as_written(labels):
    """Labels as plain Python values for messages: ``'sad'``, not ``np.str_('sad')``."""
    return np.asarray(labels).tolist()


def _on_host(labels):
    """Labels or label weights as a numpy array, from any array namespace."""
    if hasattr(labels, "__array_namespace__") and not isinstance(labels, np.ndarray):
        return to_numpy(labels)
    return np.asarray(labels)


class BaseStyleModel(BaseLayerModel):
    """Base class of layer models conditioned on a style label per frame.

    ``fit(X, y)`` takes one label per frame (``classes_`` as a classifier
    has them) or a 2-D array of label weights per frame.  Where a method
    takes ``style``, it is a label (every frame), one label per frame, or
    label weights ``(n_frames, n_classes)``.
    """

    _parameter_constraints: dict = {
        **BaseLayerModel._parameter_constraints,
        "priors": ["array-like", None],
    }

    __metadata_request__transform = {"sequence_ids": True, "style": True}
    __metadata_request__predict = {"sequence_ids": True}
    __metadata_request__predict_proba = {"sequence_ids": True}

    # -------------------------------------------------------------- labels

    def _labels_context(self, y, X, reset):
        if y is None:
            raise ValueError(
                f"{type(self).__name__} requires y to be passed, but the target y "
                "is None: give the style label of every frame (an array of shape "
                "(n_frames,)) or label weights of shape (n_frames, n_classes)."
            )
        n_frames = X.shape[0]
        labels = _on_host(y)
        if labels.ndim == 2 and labels.dtype.kind in "biuf":
            if reset:
                self.classes_ = np.arange(labels.shape[1])
            weights = check_label_weights(labels, len(self.classes_), "y")
            if len(weights) != n_frames:
                raise ValueError(
                    f"y has {len(weights)} rows but X has {n_frames} frames: give "
                    "one row of label weights per frame."
                )
        else:
            if labels.ndim != 1 or len(labels) != n_frames:
                raise ValueError(
                    f"y must hold one style label per frame of X ({n_frames}); got "
                    f"an array of shape {labels.shape}."
                )
            if labels.dtype.kind == "f" and np.any(np.isnan(labels)):
                raise ValueError("y contains NaN: every frame needs a style label.")
            if reset:
                try:
                    self.classes_ = np.unique(labels)
                except TypeError:
                    raise _labels_that_compare("y") from None
            weights = self._one_hot(labels, "y")
        if reset:
            self._check_several_classes()
        return self._as_context(weights, X)

    def _check_several_classes(self):
        if len(self.classes_) < 2:
            raise ValueError(
                f"{type(self).__name__} learns what sets styles apart, but y holds "
                f"one class ({_as_written(self.classes_[0])!r}): give frames of at "
                "least two styles, or model one style with ConditionalRBM."
            )

    def _one_hot(self, labels, name):
        """Weights that put each label's whole weight on its class."""
        classes = self.classes_
        try:
            index = np.searchsorted(classes, labels)
        except TypeError:
            raise _labels_that_compare(name) from None
        index = np.minimum(index, len(classes) - 1)
        unseen = classes[index] != labels
        if np.any(unseen):
            raise ValueError(
                f"{name} holds the style {_as_written(labels[np.argmax(unseen)])!r}, "
                f"not seen in fit; the styles are {_as_written(classes)}."
            )
        return np.eye(len(classes))[index]

    def _style_weights(self, style, n_frames, name="style"):
        """Label weights ``(n_frames, n_classes)`` of a label, labels or weights."""
        check_is_fitted(self)
        array = _on_host(style)
        if array.ndim == 0:
            return np.repeat(self._one_hot(array[None], name), n_frames, axis=0)
        if array.ndim == 2:
            weights = check_label_weights(array, len(self.classes_), name)
        elif array.ndim == 1:
            if array.dtype.kind == "f" and np.any(np.isnan(array)):
                raise ValueError(f"{name} contains NaN: give a style for every frame.")
            weights = self._one_hot(array, name)
        else:
            raise ValueError(
                f"{name} must be a style label, one label per frame or label "
                f"weights of shape (n_frames, n_classes); got shape {array.shape}."
            )
        if len(weights) != n_frames:
            raise ValueError(
                f"{name} gives {len(weights)} frames' styles but {n_frames} are "
                "needed: one per frame."
            )
        return weights

    def _as_context(self, weights, like):
        ops = array_ops(like)
        return ops.asarray(weights, dtype=like.dtype)

    def _style_context(self, X, sequences, style):
        """The context of every frame: the style given, or the sequence's posterior."""
        if style is None:
            return self._as_context(self._posterior(X, sequences), X)
        return self._as_context(self._style_weights(style, X.shape[0]), X)

    # ----------------------------------------------------------- inference

    def _log_priors(self):
        n_classes = len(self.classes_)
        if self.priors is None:
            return np.full(n_classes, -np.log(n_classes))
        priors = np.asarray(self.priors, dtype=np.float64)
        if priors.shape != (n_classes,) or np.any(priors < 0) or priors.sum() <= 0:
            raise ValueError(
                f"priors must hold one non-negative number per style ({n_classes}), "
                f"got {self.priors!r}."
            )
        with np.errstate(divide="ignore"):
            return np.log(priors / priors.sum())

    def _class_log_likelihoods(self, X, sequences):
        """``log p(x_t | past, style k)`` of every frame and style, (n_frames, K)."""
        seed = int(rng_from(self.random_state).integers(np.iinfo(np.int32).max))
        columns = []
        for k in range(len(self.classes_)):
            one_hot = np.zeros((X.shape[0], len(self.classes_)))
            one_hot[:, k] = 1
            # the same random numbers for every style: their differences count
            log_likelihood = self._log_likelihood(
                X,
                sequences,
                rng=np.random.default_rng(seed),
                context=self._as_context(one_hot, X),
            ).log_likelihood
            columns.append(to_numpy(log_likelihood).astype(np.float64))
        return np.stack(columns, axis=1)

    # the posterior of a style the evidence rules out underflows to 0: exact
    @np.errstate(under="ignore")
    def _posterior(self, X, sequences, log_likelihoods=None):
        """Each frame's sequence's posterior over the styles, (n_frames, K).

        The last posterior is kept, keyed on the frames, the sequences, the
        parameters and the priors: ``predict`` then ``predict_proba`` of the
        same frames (the usual pair) anneal once per style, not twice.
        """
        if log_likelihoods is None:
            key = self._posterior_key(X, sequences)
            kept = _RECENT_POSTERIORS.get(self)
            if kept is not None and kept[0] == key:
                return kept[1].copy()
            posterior = self._posterior(
                X, sequences, self._class_log_likelihoods(X, sequences)
            )
            _RECENT_POSTERIORS[self] = (key, posterior.copy())
            return posterior
        valid = np.zeros(X.shape[0], dtype=bool)
        valid[sequences.valid_frames(self.history_length)] = True
        posterior = np.empty_like(log_likelihoods)
        for start, stop in zip(sequences.starts, sequences.stops, strict=True):
            rows = slice(start, stop)
            evidence = log_likelihoods[rows][valid[rows]]
            if len(evidence) == 0:  # too short for a full past: every frame
                evidence = log_likelihoods[rows]
            log_post = self._log_priors() + evidence.sum(axis=0)
            posterior[rows] = np.exp(log_post - logsumexp(log_post))
        return posterior

    def _frame_log_likelihoods(self, X, sequences, y=None, name="y"):
        if y is not None:
            context = self._as_context(self._style_weights(y, X.shape[0], name), X)
            return self._log_likelihood(X, sequences, context=context).log_likelihood
        return self._as_context(self._mixture_log_likelihoods(X, sequences), X)

    def _posterior_key(self, X, sequences):
        """A digest of everything :meth:`_posterior` depends on."""
        digest = hashlib.blake2b(digest_size=16)
        arrays = [X, sequences.starts, sequences.lengths]
        arrays += [layer.flat for layer in self._layers()]
        for array in arrays:
            array = np.ascontiguousarray(to_numpy(array))
            digest.update(f"{array.dtype}{array.shape}".encode())
            digest.update(array.data)
        seed = self.random_state if isinstance(self.random_state, Integral) else None
        settings = (self.priors, self.ais_steps, self.ais_chains, seed)
        digest.update(repr(settings).encode())
        return digest.digest()

    @np.errstate(under="ignore")
    def _mixture_log_likelihoods(self, X, sequences):
        """``log p(x_t | x_<t)`` with the style unknown: a mixture over styles.

        Each style weighted by its posterior given the sequence's frames
        before ``t`` (those with a full past), starting from the priors.
        """
        log_likelihoods = self._class_log_likelihoods(X, sequences)
        valid = np.zeros(X.shape[0], dtype=bool)
        valid[sequences.valid_frames(self.history_length)] = True
        result = np.empty(X.shape[0])
        for start, stop in zip(sequences.starts, sequences.stops, strict=True):
            rows = slice(start, stop)
            evidence = np.where(valid[rows, None], log_likelihoods[rows], 0.0)
            before = np.cumsum(evidence, axis=0) - evidence + self._log_priors()
            before -= logsumexp(before, axis=1, keepdims=True)
            result[rows] = logsumexp(before + log_likelihoods[rows], axis=1)
        return result

    @limit_blas_threads(frame_rows)
    def predict_log_proba(self, X, *, sequence_ids=None):
        """Log posterior of each sequence's style, for every frame.

        By Bayes' rule from the conditional log-likelihoods ``log p(x_t |
        past, style)`` of the sequence's frames that have a full past (all
        its frames if it has none) and ``priors`` (equal unless given).
        Every frame of a sequence gets its sequence's posterior.  The last
        posterior is kept: :meth:`predict`, :meth:`predict_proba` and this
        method on the same frames (and the same parameters) compute it once.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        log_proba : ndarray of shape (n_frames, n_classes)
            Columns in the order of ``classes_``.
        """
        return self._log_posterior(X, sequence_ids, "predict_log_proba")

    def _log_posterior(self, X, sequence_ids, method):
        X, sequences = self._check_inference_input(X, sequence_ids, method)
        with np.errstate(divide="ignore"):
            return self._as_context(np.log(self._posterior(X, sequences)), X)

    def predict_proba(self, X, *, sequence_ids=None):
        """Posterior of each sequence's style, for every frame.

        See :meth:`predict_log_proba`.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        proba : ndarray of shape (n_frames, n_classes)
            Columns in the order of ``classes_``; each row sums to 1.
        """
        log_proba = self._log_posterior(X, sequence_ids, "predict_proba")
        return array_ops(log_proba).exp(log_proba)

    def predict(self, X, *, sequence_ids=None):
        """The most probable style of each sequence, for every frame.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        styles : ndarray of shape (n_frames,)
            Labels from ``classes_``.
        """
        log_proba = self._log_posterior(X, sequence_ids, "predict")
        styles = self.classes_[np.argmax(to_numpy(log_proba), axis=1)]
        if styles.dtype.kind in "biuf":  # numbers go back to X's namespace
            return array_ops(log_proba).asarray(styles)
        return styles

    @limit_blas_threads(frame_rows)
    def transform(self, X, style=None, *, sequence_ids=None):
        """Hidden probabilities of every frame, given its style.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        style : label, array-like of shape (n_frames,) or (n_frames, n_classes), \
default=None
            The style of every frame (see the class docstring); None: each
            sequence's posterior over the styles (:meth:`predict_proba`) as
            its label weights.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        H : ndarray of shape (n_frames, n_components)
            ``p(h = 1 | x_t, past, style)``; a sequence's first frames use
            its first frame as their missing past (edge padding).
        """
        X, sequences = self._check_inference_input(X, sequence_ids)
        context = self._style_context(X, sequences, style)
        return self._representations(X, sequences, self._layers(), context)[-1]

    @limit_blas_threads(frame_rows)
    def score_samples(self, X, style=None, *, sequence_ids=None):
        """``log p(x_t | past, style)`` of every frame, in nats.

        Exact for few hidden units, annealed otherwise (as
        :meth:`ConditionalRBM.score_samples`).  With the style unknown
        (``style=None``), the frame's log-likelihood under the mixture of
        the styles, each weighted by its posterior given the sequence's
        frames before it (from ``priors``): ``log sum_k p(k | x_<t) p(x_t |
        past, k)``.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        style : label, array-like of shape (n_frames,) or (n_frames, \
n_classes), default=None
            Every frame's style; None: unknown (see above).
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        log_likelihood : ndarray of shape (n_frames,)
        """
        X, sequences = self._check_inference_input(X, sequence_ids, "score_samples")
        log_likelihood = self._frame_log_likelihoods(X, sequences, style, "style")
        return array_ops(X).astype(log_likelihood, X.dtype)

    @limit_blas_threads(frame_rows)
    def estimate_log_likelihood(
        self,
        X,
        style,
        *,
        sequence_ids=None,
        method="auto",
        reverse=True,
        random_state=None,
    ):
        """``log p(x_t | past, style)`` of every frame, with how far to trust it.

        As :meth:`ConditionalRBM.estimate_log_likelihood`, given the style.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        style : label, array-like of shape (n_frames,) or (n_frames, n_classes)
            Every frame's style.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
        method : {"auto", "exact", "ais"}, default="auto"
        reverse : bool, default=True
            Also run reverse annealing (a conservative estimate).
        random_state : int, RandomState instance or None, default=None
            Seeds the annealing; None uses the estimator's ``random_state``.

        Returns
        -------
        result : :class:`~sklearn.utils.Bunch`
            ``log_likelihood``, ``lower``, ``standard_error`` and ``method``,
            as :meth:`ConditionalRBM.estimate_log_likelihood` gives them.
        """
        X, sequences = self._check_inference_input(
            X, sequence_ids, "estimate_log_likelihood"
        )
        context = self._as_context(self._style_weights(style, X.shape[0]), X)
        return self._estimate(X, sequences, context, method, reverse, random_state)

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit, then return the hidden probabilities of ``X`` given ``y``.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        y : array-like of shape (n_frames,) or (n_frames, n_classes)
            The style of every frame.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        H : ndarray of shape (n_frames, n_components)
        """
        return self.fit(X, y, sequence_ids=sequence_ids).transform(
            X, y, sequence_ids=sequence_ids
        )

    @limit_blas_threads(frame_rows)
    def predict_next(self, X, style=None, *, sequence_ids=None):
        """One-step-ahead prediction of every frame from its past and its style.

        Mean field from the frame's directed prediction, as
        :meth:`ConditionalRBM.predict_next`; ``style`` as in
        :meth:`transform`.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
        style : label, array-like, default=None
        sequence_ids : array-like of shape (n_frames,), default=None

        Returns
        -------
        X_pred : ndarray of shape (n_frames, n_features)
        """
        X, sequences = self._check_inference_input(X, sequence_ids, "predict_next")
        context = self._style_context(X, sequences, style)
        return self._predict_frames(X, sequences, context=context)

    def _online_context(self, X, style):
        """What on-line fill-in conditions on: every frame's context, or hypotheses.

        Returns ``(frame_context, hypotheses)``: the given style as every
        frame's label weights, or (style None) one one-hot hypothesis per
        style for the chains of a particle filter to carry.
        """
        if style is not None:
            return self._as_context(self._style_weights(style, X.shape[0]), X), None
        return None, self._as_context(np.eye(len(self.classes_)), X)

    # ----------------------------------------------------------- generation

    @limit_blas_threads(sequence_rows)
    def sample(
        self,
        n_frames,
        *,
        history=None,
        style,
        n_sequences=1,
        n_gibbs=None,
        hidden_noise=0.0,
        random_state=None,
        n_jobs=None,
    ):
        """Generate new frames in a given style, blend of styles or transition.

        Each new frame starts from the previous frame plus noise, ``n_gibbs``
        alternating Gibbs iterations follow (hidden units sampled, visibles
        set to their mean) and a final mean-field step, the layer
        conditioned on the frame's label weights.

        Parameters
        ----------
        n_frames : int
            Number of new frames per sequence.
        history : array-like, default=None
            Seed frames, oldest first, at least ``history_length`` of them:
            shape ``(n_frames_seed, n_features)`` for every sequence, or
            ``(n_sequences, n_frames_seed, n_features)``.  ``None`` draws
            windows of training frames kept by :meth:`fit`.
        style : label or array-like of shape (n_frames, n_classes)
            The style of every new frame: a label seen in :meth:`fit`, or
            non-negative label weights that sum to 1 in every frame (a
            blend; a transition when they change over the frames).
        n_sequences : int, default=1
            Number of sequences, generated together.
        n_gibbs : int, default=None
            Alternating Gibbs iterations per frame; None: the model's
            ``n_gibbs``.
        hidden_noise : float, default=0.0
            Standard deviation of noise added to the hidden biases each time
            hidden states are drawn.
        random_state : int, RandomState instance or None, default=None
            Seeds the generation; None uses the estimator's ``random_state``.
        n_jobs : int, default=None
            Jobs generating blocks of sequences in parallel; the frames do
            not depend on it.

        Returns
        -------
        X_new : ndarray of shape (n_sequences * n_frames, n_features)
            The generated frames, sequence after sequence.
        """
        check_is_fitted(self)
        n_frames = check_count(n_frames, "n_frames", minimum=1)
        n_sequences = check_count(n_sequences, "n_sequences", minimum=1)
        n_gibbs = self.n_gibbs if n_gibbs is None else n_gibbs
        n_gibbs = check_count(n_gibbs, "n_gibbs", minimum=0)
        if not isinstance(hidden_noise, Real) or not hidden_noise >= 0:
            raise ValueError(
                f"hidden_noise must be a non-negative number, got {hidden_noise!r}."
            )
        weights = self._style_weights(style, n_frames)
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
        ops = array_ops(seed)
        context = self._as_context(weights, seed)
        context = ops.broadcast_to(context[None, ...], (seed.shape[0], *weights.shape))
        frames = self._generate(
            seed,
            n_frames,
            rng,
            context=context,
            n_jobs=n_jobs,
            n_gibbs=n_gibbs,
            hidden_noise=hidden_noise,
            sample_visibles=False,
        )
        self._check_generated(frames, n_frames)
        return frames

    def __sklearn_array_api_convert__(self, converter):
        """A copy on another namespace or device whose labels stay on the host.

        :func:`sklearn.utils._array_api.move_estimator_to` would move
        ``classes_`` too, which may hold strings no other namespace holds.
        """
        moved = clone(self)
        for name, value in vars(self).items():
            if name != "classes_":
                value = _estimator_with_converted_arrays(value, converter)
            setattr(moved, name, value)
        return moved

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.required = True
        return tags
