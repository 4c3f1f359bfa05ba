"""What a layer model conditioned on a style per frame adds: labels in and out.

A style model fitted on labels takes every frame's label weights ``y``
(one-hot for a labelled frame, any non-negative weights that sum to 1 for a
blend) as its context.  :class:`BaseStyleModel` turns labels into those
weights (``y`` in ``fit`` and ``score``, ``style`` in the other methods of
:class:`~sklearn_crbm.models._base.BaseCRBM`), names the style of a sequence by
Bayes' rule (``classes_``, ``predict``, ``predict_proba``), infers the
context of frames given none from each sequence's posterior, and scores
them under the mixture of styles, each weighted by its posterior given the
frames before.  Fitted on a real-valued ``context`` instead, it is a model
of that context, without the classifier.
"""

import hashlib
import weakref
from numbers import Integral

import numpy as np
from scipy.special import logsumexp
from sklearn.base import clone
from sklearn.utils._array_api import _estimator_with_converted_arrays
from sklearn.utils.validation import check_is_fitted

from ..utils._array_api import array_ops, to_numpy
from ..utils._random import rng_from
from ..utils._threads import frame_rows, limit_blas_threads
from ._one_layer import BaseLayerModel

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
    label weights ``(n_frames, n_classes)``.  ``fit(X, context=...)``
    takes a real-valued context instead (no ``classes_``).
    """

    _parameter_constraints: dict = {
        **BaseLayerModel._parameter_constraints,
        "priors": ["array-like", None],
    }

    __metadata_request__transform = {
        "sequence_ids": True,
        "context": True,
        "style": True,
    }
    __metadata_request__predict = {"sequence_ids": True}
    __metadata_request__predict_proba = {"sequence_ids": True}

    _context_hint = ", or style= for a model fitted on labels"

    # -------------------------------------------------------------- labels

    @property
    def _labelled(self):
        """Whether the model was fitted on labels (its context: label weights)."""
        return hasattr(self, "classes_")

    def _context_for_fit(self, X, y, context, reset):
        if reset and y is None and context is None:
            raise ValueError(
                f"{type(self).__name__} requires y to be passed, but the target y "
                "is None: give the style label of every frame (an array of shape "
                "(n_frames,)) or label weights of shape (n_frames, n_classes), or a "
                "real-valued context= of shape (n_frames, n_context)."
            )
        return super()._context_for_fit(X, y, context, reset)

    def _labels_context(self, y, X, reset):
        if y is None:
            if reset:  # a model of a real-valued context names no classes
                vars(self).pop("classes_", None)
            return None
        if not (reset or self._labelled):
            raise self._unlabelled_error("y")
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

    def _score_context(self, X, y, context):
        if y is None:
            return super()._score_context(X, y, context)
        if context is not None:
            raise self._both_error("y")
        if not self._labelled:
            raise self._unlabelled_error("y")
        return self._as_context(self._style_weights(y, X.shape[0], "y"), X)

    def _unlabelled_error(self, name):
        return ValueError(
            f"{type(self).__name__} was fitted on a real-valued context, not on "
            f"labels: it has no styles to take {name} or to predict. Give "
            "context=, or fit it with labels y."
        )

    def _style_context(self, style, n_frames, like):
        if not self._labelled:
            raise self._unlabelled_error("style=")
        return self._as_context(self._style_weights(style, n_frames), like)

    def _inference_context(self, X, sequences, context):
        """The context given, or each sequence's posterior over the styles."""
        if context is None and self._labelled:
            return self._as_context(self._posterior(X, sequences), X)
        return super()._inference_context(X, sequences, context)

    def _frame_log_likelihoods(self, X, sequences, context):
        """Given a context, the frames' log-likelihood; with the style unknown,
        that of the mixture of the styles (:meth:`_mixture_log_likelihoods`)."""
        if context is None and self._labelled:
            return self._as_context(self._mixture_log_likelihoods(X, sequences), X)
        return super()._frame_log_likelihoods(X, sequences, context)

    def _online_context(self, X, context):
        """What on-line fill-in conditions on: every frame's context, or hypotheses.

        Returns ``(frame_context, hypotheses)``: the context given, or (a
        model fitted on labels, given none) one one-hot hypothesis per style
        for the chains of a particle filter to carry.
        """
        if context is None and self._labelled:
            return None, self._as_context(np.eye(len(self.classes_)), X)
        return super()._online_context(X, context)

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

    def _liveliness_labels(self, context):
        return to_numpy(context) if self._labelled and context is not None else None

    def _as_context(self, weights, like):
        ops = array_ops(like)
        return ops.asarray(weights, dtype=like.dtype)

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

    def _posterior_key(self, X, sequences):
        """A digest of everything :meth:`_posterior` depends on."""
        digest = hashlib.blake2b(digest_size=16)
        arrays = [X, sequences.starts, sequences.lengths]
        arrays += [layer.flat for layer in self._fitted_layers()]
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
        if not self._labelled:
            raise self._unlabelled_error(method)
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
