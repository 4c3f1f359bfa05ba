"""The per-frame context of a model: checked, standardised, or from labels.

Every method of a model that depends on time takes the same per-frame
``context`` (shape ``(n_frames, n_context)``, real-valued).  A real-valued
context is standardised by the mean and scale learnt in ``fit``; the style
models make their context from labels (``y``) or ``style`` instead, through
the hooks of :class:`ContextMixin`.
"""

from ..utils._array_api import array_ops
from ..utils._validation import check_context

__all__ = ["ContextMixin"]


class ContextMixin:
    """The context of :class:`~sklearn_crbm.models._base.BaseCRBM`'s methods.

    Hooks, which a model overrides where it differs:

    - ``_labels_context(y, X, reset)``: every frame's context from labels
      (None: ``y`` is ignored);
    - ``_style_context(style, n_frames, like)``: every frame's context from
      ``style`` (a model of styles only);
    - ``_labels_rows(y, n_frames, like)``: every generated frame's context
      from ``sample``'s ``y`` (a model of labels only);
    - ``_inference_context(X, sequences, context)``: the context of frames
      given none (a style model infers it);
    - ``_online_context(X, context)``: what on-line fill-in conditions on;
    - ``_context_hint``: how else the model can be told its context;
    - ``_scales_context``: whether ``fit`` learns the scaling of a
      real-valued context; :meth:`_take_context_as_given` turns it off (a
      :class:`~sklearn_crbm.StackedCRBM` scales the context once for all
      its layers).
    """

    # how else a model can be told its context (said when one is missing)
    _context_hint = ""

    # whether fit learns the scaling of a real-valued context
    _scales_context = True

    def _take_context_as_given(self):
        """Make ``fit`` take a real-valued context as it is, unscaled.

        For a model whose owner standardises the context for it (a
        :class:`~sklearn_crbm.StackedCRBM` does, once for all its layers).
        Returns ``self``.
        """
        self._scales_context = False
        return self

    def _labels_context(self, y, X, reset):
        """Every frame's context from the labels ``y`` (None: ``y`` is ignored)."""
        return None

    def _style_context(self, style, n_frames, like):
        """Every frame's context from ``style`` (a model of styles only)."""
        raise ValueError(
            f"{type(self).__name__} has no styles: give context= instead of "
            "style=, or use a style model such as FactoredCRBM or LabelledCRBM."
        )

    def _labels_rows(self, y, n_frames, like):
        """Every generated frame's context from ``sample``'s ``y`` (a model of
        labels only)."""
        raise ValueError(
            f"{type(self).__name__} has no labels: give context= instead of y=, "
            "or use a style model such as FactoredCRBM or LabelledCRBM."
        )

    def _inference_context(self, X, sequences, context):
        """The context of the frames of ``X``: the one given, which a model
        fitted with a context needs (a style model infers it instead)."""
        if context is None and self.n_context_:
            raise self._missing_context_error()
        return context

    def _online_context(self, X, context):
        """What on-line fill-in conditions on: ``(frame_context, hypotheses)``.

        Every frame's context (None for a model without one); a style model
        given none gives hypotheses for particles to weigh instead.
        """
        if context is None and self.n_context_:
            raise self._missing_context_error()
        return context, None

    def _context_for_fit(self, X, y, context, reset):
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
        if context is None or not self._scales_context:
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

    def _method_context(self, context, style, n_frames, like, *, one_row=False, y=None):
        """The context a method is given, as ``context``, ``style`` or (``sample``)
        ``y`` (checked).

        With ``one_row`` (``sample``) a single row stands for every frame.
        """
        if y is not None:
            if style is not None:
                raise ValueError(
                    f"{type(self).__name__} got both y= and style=: give the "
                    "labels once (y= takes a row of labels of every factor, "
                    "style= the label of a model of one)."
                )
            if context is not None:
                raise self._both_error("y=")
            return self._labels_rows(y, n_frames, like)
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

    def _given_context(self, X, sequences, context, style):
        """Every frame's context, from ``context`` or ``style``, else inferred."""
        context = self._method_context(context, style, X.shape[0], X)
        return self._inference_context(X, sequences, context)
