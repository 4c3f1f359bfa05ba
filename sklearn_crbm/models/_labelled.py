"""A conditional RBM whose dynamic biases also take the style labels (no gating)."""

from numbers import Integral, Real

from sklearn.utils._param_validation import Interval, StrOptions

from ..layers._crbm import ORDER_CONSTRAINTS, CRBMLayer, hidden_order_of
from ._base import FittedParameter
from ._style import BaseStyleModel

__all__ = ["LabelledCRBM"]


class LabelledCRBM(BaseStyleModel):
    """Conditional RBM whose dynamic biases also take each frame's style label.

    The simplest model of a labelled corpus: a :class:`ConditionalRBM`
    whose visible and hidden units get, besides their inputs from the
    past, an input from the frame's label weights ``y`` (one-hot for a
    labelled frame): ``c_hat = c + A x_past + L_v y`` and ``b_hat = b + B
    x_past + L_h y``.  The labels shift the biases but do not change how
    the units interact (no gating): the baseline Taylor & Hinton (2009)
    compare :class:`FactoredCRBM` with.  It generates, scores, fills in
    and names styles as :class:`FactoredCRBM` does, of one label factor or
    several (the columns of a 2-D ``y``, such as content and style: each a
    one-hot block of the labels, whose shifts of the biases add).

    Parameters
    ----------
    n_components : int, default=200
        Number of binary hidden units.
    order : int, default=3
        Number of past frames feeding the visible units.
    hidden_order : int, default=None
        Number of past frames feeding the hidden units; None means ``order``.
    learning_rate : float, default=1e-3
    momentum : float, default=0.9
    momentum_delay : int, default=5
    weight_decay : float, default=2e-4
    cd_steps : int, default=1
    batch_size : int, default=100
    batching : {"balanced", "shuffled"}, default="balanced"
    history_noise : float, default=1.0
    history_noise_fraction : float in (0, 1], default=0.5
    average_fraction : float in [0, 1), default=0.25
    n_iter : int, default=1000
    n_gibbs : int, default=30
        Alternating Gibbs iterations per generated frame in :meth:`sample`.
    priors : array-like of shape (n_classes,) or list of array-like, default=None
        Prior probabilities of the styles in :meth:`predict_proba`; with
        several label factors, a list of each factor's.
    ais_steps : int, default=50
    ais_chains : int, default=2
    early_stopping : bool, default=False
    validation_fraction : float, default=0.1
    n_iter_no_change : int, default=50
    validation_interval : int, default=10
    tol : float, default=1e-3
    n_mean_field : int, default=10
        Mean-field steps (hidden probabilities, then visible means) that end
        every frame :meth:`sample` generates, after its Gibbs iterations.
        One (the original code's) leaves the frame where the last sampled
        hidden states put it, and the frames shake; more settle it at the
        mean-field fixed point of the mode the chain ended in: smooth, but
        deterministic given the past, so that without ``hidden_drift``
        sequences generated from one seed become copies of each other.
    hidden_drift : float, default=0.3
        Standard deviation of a random offset of the hidden biases of every
        sequence :meth:`sample` generates, which changes smoothly over a
        few frames and holds through all of a frame's steps: randomness that
        keeps sequences from one seed apart without shaking the frames, in
        the units of the hidden units' input (as ``hidden_noise``); ``0``:
        none.
    random_state : int, RandomState instance or None, default=None
    verbose : int, default=0
        The parameters without a description are those of
        :class:`ConditionalRBM`, with its defaults.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,) or list of ndarray
        The styles, in the order of the columns of label weights; with
        several label factors, a list of each factor's labels.
    n_outputs_ : int
        Number of label factors (columns of ``y``).
    components_ : ndarray of shape (n_components, n_features)
    intercept_hidden_ : ndarray of shape (n_components,)
    intercept_visible_ : ndarray of shape (n_features,)
    autoregressive_ : ndarray of shape (order, n_features, n_features)
    past_to_hidden_ : ndarray of shape (hidden_order, n_components, n_features)
    label_to_visible_ : ndarray of shape (n_features, n_context)
        ``L_v``: what each style (each column of the context) adds to the
        visible biases.
    label_to_hidden_ : ndarray of shape (n_components, n_context)
        ``L_h``: what each style adds to the hidden biases.
    n_context_ : int
        Columns of the context: the number of styles for a model fitted on
        labels.
    context_mean_ : ndarray of shape (n_context,)
        Mean of each column of a real-valued context in ``fit``, which the
        model subtracts from every context it is given (absent when fitted
        without one or on labels).
    context_scale_ : ndarray of shape (n_context,)
        Standard deviation of each column (1 for a constant one), by which
        the model divides every context it is given.
    seed_windows_ : ndarray of shape (n_windows, width, n_features)
    reconstruction_error_ : float
    n_iter_ : int
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    FactoredCRBM : The labels gate every interaction.
    ConditionalRBM : No labels.

    References
    ----------
    G. W. Taylor and G. E. Hinton. Factored Conditional Restricted Boltzmann
    Machines for Modeling Motion Style. ICML 2009.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm import LabelledCRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, ids = make_oscillations(n_sequences=4, n_frames=60, random_state=0)
    >>> styles = np.where(ids < 2, "slow", "fast")
    >>> model = LabelledCRBM(16, order=2, n_iter=10, random_state=0)
    >>> model = model.fit(X, styles, sequence_ids=ids)
    >>> model.label_to_hidden_.shape
    (16, 2)
    >>> model.sample(20, style="fast", n_sequences=2).shape
    (40, 6)

    Content and style, switching the content on-line after 10 frames:

    >>> y = np.stack([np.where(ids % 2 == 0, "walk", "run"), styles], axis=1)
    >>> model = model.fit(X, y, sequence_ids=ids)
    >>> model.n_outputs_, model.label_to_hidden_.shape
    (2, (16, 4))
    >>> rows = [("walk", "fast")] * 10 + [("run", "fast")] * 10
    >>> model.sample(20, y=rows).shape
    (20, 6)
    """

    _parameter_constraints: dict = {
        **BaseStyleModel._parameter_constraints,
        **ORDER_CONSTRAINTS,
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "n_gibbs": [Interval(Integral, 0, None, closed="left")],
        "batching": [StrOptions({"balanced", "shuffled"})],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
    }

    components_ = FittedParameter("weights")
    intercept_hidden_ = FittedParameter("hidden_bias")
    intercept_visible_ = FittedParameter("visible_bias")
    autoregressive_ = FittedParameter("autoregressive")
    past_to_hidden_ = FittedParameter("past_to_hidden")
    label_to_visible_ = FittedParameter("context_to_visible")
    label_to_hidden_ = FittedParameter("context_to_hidden")

    def __init__(
        self,
        n_components=200,
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
        history_noise=1.0,
        history_noise_fraction=0.5,
        average_fraction=0.25,
        n_iter=1000,
        n_gibbs=30,
        priors=None,
        ais_steps=50,
        ais_chains=2,
        early_stopping=False,
        validation_fraction=0.1,
        n_iter_no_change=50,
        validation_interval=10,
        tol=1e-3,
        n_mean_field=10,
        hidden_drift=0.3,
        random_state=None,
        verbose=0,
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
        self.n_gibbs = n_gibbs
        self.priors = priors
        self.ais_steps = ais_steps
        self.ais_chains = ais_chains
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.validation_interval = validation_interval
        self.tol = tol

    def _new_layer(self, n_features, n_context, dtype):
        return CRBMLayer(
            n_features,
            self.n_components,
            self.order,
            hidden_order_of(self),
            "gaussian",
            dtype,
            n_context=n_context,
        )
