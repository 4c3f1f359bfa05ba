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
import itertools
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
from ._label_factors import (
    as_entries,
    as_written,
    blocks,
    check_label_weights,
    combinations,
    fit_columns,
    fitted_classes,
    label_weights,
)
from ._one_layer import BaseLayerModel

__all__ = ["BaseStyleModel", "check_label_weights"]

# Each estimator's last posterior and the digest of what it came from (see
# BaseStyleModel._posterior); weak keys: nothing is kept for a deleted model.
_RECENT_POSTERIORS = weakref.WeakKeyDictionary()
# With several label factors, a combination of labels whose posterior given a
# sequence's frames so far falls this many nats below the best combination's
# (a ratio below 1e-13) is no longer scored on the sequence's later frames.
PRUNE_NATS = 30.0
# Frames with a full past scored between two such prunings.
PRUNE_FRAMES = 16


def _factor_log_priors(priors, n_classes, name):
    """Log priors of one factor's ``n_classes`` labels (None: equal)."""
    if priors is None:
        return np.full(n_classes, -np.log(n_classes))
    try:
        array = np.asarray(priors, dtype=np.float64)
    except (TypeError, ValueError):
        array = np.empty(0)
    if array.shape != (n_classes,) or np.any(array < 0) or array.sum() <= 0:
        raise ValueError(
            f"{name} must hold one non-negative number per style ({n_classes}), "
            f"got {priors!r}."
        )
    with np.errstate(divide="ignore"):
        return np.log(array / array.sum())


class BaseStyleModel(BaseLayerModel):
    """Base class of layer models conditioned on labels per frame.

    ``fit(X, y)`` takes one label per frame, ``y`` of shape ``(n_frames,)``
    (one label factor: ``classes_`` an array, as a classifier has it), or
    the labels of several factors, ``y`` of shape ``(n_frames, n_outputs)``
    (such as content and style: ``classes_`` a list of arrays, as
    scikit-learn's multi-output classifiers have it).  Each factor's label
    is a one-hot block of the context, the blocks side by side.  In place
    of a label, a factor's entry may be a blend of its labels, a mapping
    ``{label: weight}`` of weights that sum to 1.  Where a method takes
    ``style``, it is a label (every frame), one label per frame, or label
    weights ``(n_frames, n_classes)`` of a model of one factor; for a model
    of several, a row of labels (every frame) or one row per frame, as
    ``y``.  ``fit(X, context=...)`` takes a real-valued context instead (no
    ``classes_``).
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

    _context_hint = ", or style= (y= in sample) for a model fitted on labels"

    # -------------------------------------------------------------- labels

    @property
    def _labelled(self):
        """Whether the model was fitted on labels (its context: label weights)."""
        return hasattr(self, "classes_")

    @property
    def _factor_classes(self):
        """Each label factor's classes: a list of arrays (one for one factor)."""
        classes = self.classes_
        return classes if isinstance(classes, list) else [classes]

    @property
    def n_outputs_(self):
        """Number of label factors (columns of ``y``) the model was fitted on."""
        if not self._labelled:
            raise AttributeError(
                f"{type(self).__name__} has no n_outputs_: it was not fitted on labels."
            )
        return len(self._factor_classes)

    def _context_for_fit(self, X, y, context, reset):
        if reset and y is None and context is None:
            raise ValueError(
                f"{type(self).__name__} requires y to be passed, but the target y "
                "is None: give the style label of every frame (an array of shape "
                "(n_frames,)), the labels of several label factors (shape "
                "(n_frames, n_outputs), such as content and style), or a "
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
        if reset:
            classes = fitted_classes(y, n_frames, "y")
            self.classes_ = classes[0] if len(classes) == 1 else classes
            self._check_several_classes()
        else:
            fit_columns(y, n_frames, "y")
        weights = label_weights(y, self._factor_classes, n_frames, name="y")
        return self._as_context(weights, X)

    def _check_several_classes(self):
        several = len(self._factor_classes) > 1
        for j, classes in enumerate(self._factor_classes):
            if len(classes) < 2:
                factor = f"y[:, {j}]" if several else "y"
                raise ValueError(
                    f"{type(self).__name__} learns what sets styles apart, but "
                    f"{factor} holds one class ({as_written(classes[0])!r}): give "
                    "frames of at least two styles, or model one style with "
                    "ConditionalRBM."
                )

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

    def _labels_rows(self, y, n_frames, like):
        """``sample``'s ``y``: one row of labels for every frame, or one per frame."""
        if not self._labelled:
            raise self._unlabelled_error("y=")
        weights = label_weights(
            y, self._factor_classes, n_frames, name="y", every_frame=True
        )
        return self._as_context(weights, like)

    def _inference_context(self, X, sequences, context):
        """The context given, or each sequence's posterior over the labels
        (each factor's marginal posterior in its block)."""
        if context is None and self._labelled:
            marginals = self._marginals(self._posterior(X, sequences))
            return self._as_context(np.hstack(marginals), X)
        return super()._inference_context(X, sequences, context)

    def _frame_log_likelihoods(self, X, sequences, context):
        """Given a context, the frames' log-likelihood; with the labels unknown,
        that of the mixture of the labels (:meth:`_mixture_log_likelihoods`)."""
        if context is None and self._labelled:
            return self._as_context(self._mixture_log_likelihoods(X, sequences), X)
        return super()._frame_log_likelihoods(X, sequences, context)

    def _online_context(self, X, context):
        """What on-line fill-in conditions on: every frame's context, or hypotheses.

        Returns ``(frame_context, hypotheses)``: the context given, or (a
        model fitted on labels, given none) one one-hot hypothesis per style
        (per combination of one label of each factor) for the chains of a
        particle filter to carry.
        """
        if context is None and self._labelled:
            return None, self._as_context(combinations(self._factor_classes)[1], X)
        return super()._online_context(X, context)

    def _style_weights(self, style, n_frames, name="style"):
        """Label weights ``(n_frames, n_context)`` of ``style``: a label,
        labels, label weights (one factor) or rows of labels (several)."""
        check_is_fitted(self)
        array = as_entries(style)
        if self.n_outputs_ == 1 and array.ndim == 2:
            weights = check_label_weights(array, len(self.classes_), name)
            if len(weights) != n_frames:
                raise ValueError(
                    f"{name} gives {len(weights)} frames' styles but {n_frames} "
                    "are needed: one per frame."
                )
            return weights
        if self.n_outputs_ == 1 and array.ndim > 1:
            raise ValueError(
                f"{name} must be a style label, one label per frame or label "
                f"weights of shape (n_frames, n_classes); got shape {array.shape}."
            )
        return label_weights(
            style, self._factor_classes, n_frames, name=name, every_frame=True
        )

    def _context_names(self):
        """The label of every column of the context (each factor's, in turn)."""
        if not self._labelled:
            return None
        return np.concatenate(
            [np.asarray(c, dtype=object) for c in self._factor_classes]
        )

    def _liveliness_labels(self, context):
        return to_numpy(context) if self._labelled and context is not None else None

    def _as_context(self, weights, like):
        ops = array_ops(like)
        return ops.asarray(weights, dtype=like.dtype)

    # ----------------------------------------------------------- inference

    def _log_priors(self):
        """Log prior of every label (one factor) or combination of one label
        of each factor (several: the sum of the factors' log priors), in the
        order of :func:`~sklearn_crbm.models._label_factors.combinations`."""
        classes = self._factor_classes
        if len(classes) == 1:
            return _factor_log_priors(self.priors, len(classes[0]), "priors")
        priors = self.priors
        if priors is not None and (
            isinstance(priors, str) or len(priors) != len(classes)
        ):
            raise ValueError(
                f"priors of a model of {len(classes)} label factors must be a list "
                f"of {len(classes)} arrays, one per factor, each holding one "
                f"non-negative number per class ({[len(c) for c in classes]}); got "
                f"{priors!r}."
            )
        factor_priors = [None] * len(classes) if priors is None else priors
        codes = combinations(classes)[0]
        log_priors = np.zeros(len(codes))
        for j, (factor, prior) in enumerate(zip(classes, factor_priors, strict=True)):
            log_priors += _factor_log_priors(prior, len(factor), f"priors[{j}]")[
                codes[:, j]
            ]
        return log_priors

    def _class_log_likelihoods(self, X, sequences):
        """``log p(x_t | past, labels)`` of every frame and label, (n_frames, K).

        One column per label (one factor), or per combination of one label
        of each factor (several), with ``-inf`` where a combination was no
        longer scored (:meth:`_pruned_log_likelihoods`).
        """
        seed = int(rng_from(self.random_state).integers(np.iinfo(np.int32).max))
        if len(self._factor_classes) > 1:
            return self._pruned_log_likelihoods(X, sequences, seed)
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

    def _pruned_log_likelihoods(self, X, sequences, seed):
        """``log p(x_t | past, combination)``, scoring only what can matter.

        The factors' contributions add in the context but not in the
        likelihood, so every combination of one label of each factor is a
        model of its own.  Each sequence is scored in steps: all
        combinations on its first ``history_length + PRUNE_FRAMES`` frames,
        then ``PRUNE_FRAMES`` frames at a time only the combinations whose
        posterior given its frames so far (as :meth:`_posterior` weighs
        them) is within ``PRUNE_NATS`` of the best; the others' later
        frames are ``-inf`` (a posterior below ``exp(-PRUNE_NATS)`` of the
        best's becomes 0).  One step scores each combination on its
        sequences' frames together, with the same random numbers for every
        combination.
        """
        contexts = combinations(self._factor_classes)[1]
        n_frames, n_combinations = X.shape[0], len(contexts)
        ops = array_ops(X)
        result = np.full((n_frames, n_combinations), -np.inf)
        valid = np.zeros(n_frames, dtype=bool)
        valid[sequences.valid_frames(self.history_length)] = True
        starts, lengths = sequences.starts, sequences.lengths
        alive = np.ones((len(starts), n_combinations), dtype=bool)
        evidence = np.tile(self._log_priors(), (len(starts), 1))
        done = np.zeros_like(lengths)
        for step in itertools.count():
            reach = np.minimum(lengths, self.history_length + PRUNE_FRAMES * (step + 1))
            active = np.flatnonzero(reach > done)
            if len(active) == 0:
                break
            rows = {
                i: np.arange(starts[i] + done[i], starts[i] + reach[i]) for i in active
            }
            for k in np.flatnonzero(alive[active].any(axis=0)):
                frames = np.concatenate([rows[i] for i in active[alive[active, k]]])
                context = ops.broadcast_to(
                    self._as_context(contexts[k][None, :], X),
                    (n_frames, contexts.shape[1]),
                )
                log_likelihood = self._log_likelihood(
                    X,
                    sequences,
                    rng=np.random.default_rng([seed, step]),
                    context=context,
                    frames=frames,
                ).log_likelihood
                result[frames, k] = to_numpy(log_likelihood)
            for i in active:
                evidence[i] += result[rows[i][valid[rows[i]]]].sum(axis=0)
            alive &= evidence >= evidence.max(axis=1, keepdims=True) - PRUNE_NATS
            done = reach
        return result

    def _marginals(self, posterior):
        """Each factor's marginal posterior, a list of ``(n_frames, n_classes)``."""
        classes = self._factor_classes
        if len(classes) == 1:
            return [posterior]
        contexts = combinations(classes)[1]
        return [posterior @ contexts[:, block] for block in blocks(classes)]

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
        With several label factors, a mixture over the combinations of one
        label of each factor, those no longer scored weighted 0 (see
        :meth:`_pruned_log_likelihoods`).
        """
        log_likelihoods = self._class_log_likelihoods(X, sequences)
        valid = np.zeros(X.shape[0], dtype=bool)
        valid[sequences.valid_frames(self.history_length)] = True
        result = np.empty(X.shape[0])
        for start, stop in zip(sequences.starts, sequences.stops, strict=True):
            rows = slice(start, stop)
            evidence = np.where(valid[rows, None], log_likelihoods[rows], 0.0)
            with np.errstate(invalid="ignore"):  # -inf - -inf: pruned
                before = np.cumsum(evidence, axis=0) - evidence + self._log_priors()
            if self.n_outputs_ > 1:
                before[np.isnan(before)] = -np.inf
            before -= logsumexp(before, axis=1, keepdims=True)
            result[rows] = logsumexp(before + log_likelihoods[rows], axis=1)
        return result

    @limit_blas_threads(frame_rows)
    def predict_log_proba(self, X, *, sequence_ids=None):
        """Log posterior of each sequence's labels, for every frame.

        By Bayes' rule from the conditional log-likelihoods ``log p(x_t |
        past, labels)`` of the sequence's frames that have a full past (all
        its frames if it has none) and ``priors`` (equal unless given).
        Every frame of a sequence gets its sequence's posterior.  A model of
        several label factors weighs every combination of one label of each
        factor and gives each factor's marginal; a combination whose
        posterior falls below ``exp(-30)`` of the best one's over a
        sequence's first frames is not scored on its later frames (its
        posterior is 0).  The last posterior is kept: :meth:`predict`,
        :meth:`predict_proba` and this method on the same frames (and the
        same parameters) compute it once.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        log_proba : ndarray of shape (n_frames, n_classes) or list of ndarray
            Columns in the order of ``classes_``; for a model of several
            label factors, a list with one such array per factor (columns
            in the order of ``classes_[j]``).
        """
        return self._unpacked(self._log_posterior(X, sequence_ids, "predict_log_proba"))

    def _log_posterior(self, X, sequence_ids, method):
        """Each factor's log posterior, a list of ``(n_frames, n_classes)``."""
        X, sequences = self._check_inference_input(X, sequence_ids, method)
        if not self._labelled:
            raise self._unlabelled_error(method)
        marginals = self._marginals(self._posterior(X, sequences))
        with np.errstate(divide="ignore"):
            return [self._as_context(np.log(m), X) for m in marginals]

    def _unpacked(self, per_factor):
        """One factor's array alone, or the list of several factors'."""
        return per_factor[0] if len(per_factor) == 1 else per_factor

    def predict_proba(self, X, *, sequence_ids=None):
        """Posterior of each sequence's labels, for every frame.

        See :meth:`predict_log_proba`.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        proba : ndarray of shape (n_frames, n_classes) or list of ndarray
            Columns in the order of ``classes_``; each row sums to 1.  For
            a model of several label factors, a list with each factor's
            marginal posterior, one array per factor.
        """
        log_proba = self._log_posterior(X, sequence_ids, "predict_proba")
        return self._unpacked([array_ops(p).exp(p) for p in log_proba])

    def predict(self, X, *, sequence_ids=None):
        """The most probable labels of each sequence, for every frame.

        Each factor's label is the most probable under its marginal
        posterior (:meth:`predict_proba`).

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            All sequences stacked, each contiguous and in time order.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        labels : ndarray of shape (n_frames,) or (n_frames, n_outputs)
            Labels from ``classes_``; for a model of several label factors,
            one column per factor, from ``classes_[j]``.
        """
        log_proba = self._log_posterior(X, sequence_ids, "predict")
        labels = [
            classes[np.argmax(to_numpy(p), axis=1)]
            for classes, p in zip(self._factor_classes, log_proba, strict=True)
        ]
        if len(labels) == 1:
            labels = labels[0]
        elif len({column.dtype.kind for column in labels}) == 1:
            labels = np.stack(labels, axis=1)
        else:  # strings beside numbers: each as it is
            labels = np.stack([column.astype(object) for column in labels], axis=1)
        if labels.dtype.kind in "biuf":  # numbers go back to X's namespace
            return array_ops(log_proba[0]).asarray(labels)
        return labels

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
        tags.target_tags.multi_output = True  # several label factors
        return tags
