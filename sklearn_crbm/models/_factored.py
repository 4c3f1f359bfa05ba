"""Factored conditional RBM: one model of many styles (Taylor & Hinton, ICML 2009)."""

from numbers import Integral, Real

import numpy as np
from sklearn.utils._param_validation import Interval

from ..layers._factored import FactoredLayer
from ..utils._array_api import to_numpy
from ._base import FittedParameter
from ._label_factors import blocks
from ._style import BaseStyleModel

__all__ = ["FactoredCRBM"]


def balanced_frames(frames, label_weights, blocks=None):
    """``frames`` with each style's frames repeated to about the most frequent's count.

    A frame's style is its largest label weight (with several label factors,
    whose weights fill the ``blocks`` of the columns, its combination of
    each factor's largest); a style with ``n`` frames is repeated ``round(n_max
    / n)`` times (at least once), as the released code copies the takes of
    the less frequent styles.  Copies stay next to their frame, so the
    frames remain in time order.
    """
    weights = to_numpy(label_weights)[frames]
    if blocks is None:
        styles = np.argmax(weights, axis=1)
    else:
        codes = [np.argmax(weights[:, block], axis=1) for block in blocks]
        sizes = [block.stop - block.start for block in blocks]
        styles = np.ravel_multi_index(codes, sizes)
    counts = np.bincount(styles)
    copies = np.zeros(len(counts), dtype=np.intp)
    present = counts > 0
    copies[present] = np.maximum(np.rint(counts.max() / counts[present]), 1)
    return np.repeat(frames, copies[styles])


class FactoredCRBM(BaseStyleModel):
    """Factored conditional RBM whose interactions are gated by style labels.

    One model of motion in many styles (Taylor & Hinton, 2009).  Each
    frame's label weights ``y`` (one-hot for a labelled frame), or its
    real-valued ``context`` (control signals such as speed; Taylor, Hinton
    & Roweis, 2011), give style features ``z = y R``, and every
    interaction of a conditional RBM (past
    to visible, past to hidden, visible to hidden) goes through factors
    that the style features gate, so that one set of weights learns what
    the styles share and the gates what sets them apart.  Given its labels
    (or a blend of them, frame by frame), the model generates, scores and
    fills in motion of that style; given none, it names a sequence's style
    by Bayes' rule.

    Data are in long format as for :class:`ConditionalRBM`: ``X`` stacks
    all sequences, ``sequence_ids`` marks which frames belong together, and
    ``y`` gives every frame's style.  Standardise ``X`` first (the visible
    units are Gaussian with unit variance).

    Several label factors, such as the content of the motion and its style,
    are the columns of a 2-D ``y``, as scikit-learn's multi-output
    classifiers take them: each factor's label is a one-hot block of the
    labels the style features come from, so that the factors' gates add,
    and a combination never seen in training (an elderly run, from elderly
    walks and other styles' runs) can be asked for.  A blend of a factor's
    labels is a mapping ``{label: weight}`` in place of the label.

    Parameters
    ----------
    n_components : int, default=600
        Number of binary hidden units.
    n_factors : int, default=200
        Number of factors of each kind (autoregressive, past-to-hidden,
        undirected).
    n_style_features : int, default=100
        Number of real-valued style features ``z`` the labels map to.
    order : int, default=6
        Number of past frames feeding the visible and hidden units.
    shared_style_weights : bool, default=True
        One style-feature-to-factor matrix for the three kinds of factor
        (the released code's default); False learns one per kind.
    learning_rate : float, default=1e-2
        Step size of every weight and bias but the autoregressive factors
        (past to visible) and the label-to-feature weights ``R``, which take
        a tenth of it (as the released code).
    momentum : float, default=0.9
        Momentum used after the first ``momentum_delay`` epochs.
    momentum_delay : int, default=5
        Number of epochs trained without momentum.
    momentum_ramp : int, default=0
        Number of epochs after ``momentum_delay`` over which the momentum
        rises linearly to ``momentum`` (0: at once, as the released code).
    balance_styles : bool, default=True
        Train on every style about equally often: the frames of each style
        are repeated (each frame's style is its largest label weight) until
        it has about as many as the most frequent style, as the released
        code copies takes.  False: every frame once.
    max_step : float or None, default=0.25
        Largest norm of one minibatch's step of each weight matrix, as a
        fraction of the matrix's norm before the step (the velocity is
        scaled down to it); None: unbounded, as the released code.  It
        keeps the three-way weights from running away when momentum
        starts.
    weight_decay : float, default=2e-4
        L2 penalty on every weight (not on biases).
    cd_steps : int, default=10
        Reconstructions per update (CD-k).
    batch_size : int, default=100
        Frames per minibatch.
    batching : {"balanced", "shuffled"}, default="shuffled"
        ``"shuffled"``: all trainable frames shuffled each epoch;
        ``"balanced"``: one frame of each consecutive chunk per minibatch
        (see :class:`ConditionalRBM`).
    history_noise : float, default=1.0
        Standard deviation of Gaussian noise added to the past frames during
        training (in the units of ``X``).
    history_noise_fraction : float in (0, 1], default=1.0
        Probability with which each channel of a frame's past gets the
        noise.
    average_fraction : float in [0, 1), default=0.0
        :meth:`fit` keeps the mean of the parameters over the last
        ``ceil(average_fraction * n_iter)`` epochs (0: the last epoch's).
    n_iter : int, default=200
        Number of epochs.
    n_gibbs : int, default=100
        Alternating Gibbs iterations per generated frame in :meth:`sample`.
    priors : array-like of shape (n_classes,) or list of array-like, default=None
        Prior probabilities of the styles in :meth:`predict_proba`; with
        several label factors, a list of each factor's; None: equal.
    ais_steps : int, default=50
        Intermediate distributions of the annealed importance sampling of
        :meth:`score` and :meth:`score_samples`.
    ais_chains : int, default=2
        Annealing chains per frame.
    early_stopping : bool, default=False
        Hold out whole sequences (``validation_fraction``), score them
        every ``validation_interval`` epochs and keep the best parameters
        (see :class:`ConditionalRBM`).
    validation_fraction : float, default=0.1
    n_iter_no_change : int, default=50
    validation_interval : int, default=10
    tol : float, default=1e-3
    n_mean_field : int, default=1
        Mean-field steps (hidden probabilities, then visible means) that end
        every frame :meth:`sample` generates, after its Gibbs iterations.
        One (the original code's) leaves the frame where the last sampled
        hidden states put it, and the frames shake; more settle it at the
        mean-field fixed point of the mode the chain ended in: smooth, but
        deterministic given the past, so that without ``hidden_drift``
        sequences generated from one seed become copies of each other.
        The style models take one: ten settle a blend of two styles into
        one gait.
    hidden_drift : float, default=0.0
        Standard deviation of a random offset of the hidden biases of every
        sequence :meth:`sample` generates, which changes smoothly over a
        few frames and holds through all of a frame's steps: randomness that
        keeps sequences from one seed apart without shaking the frames, in
        the units of the hidden units' input (as ``hidden_noise``); ``0``:
        none.
    random_state : int, RandomState instance or None, default=None
        Controls initialisation, minibatches, sampling during training and,
        unless given their own, generation and scoring.
    verbose : int, default=0
        Every ``verbose`` epochs, print the one-step prediction error on
        training frames beside that of repeating the previous frame, the
        reconstruction error and the time.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,) or list of ndarray
        The styles, in the order of the columns of label weights (fitted on
        labels only); with several label factors, a list of each factor's
        labels, whose blocks of columns follow one another.
    n_outputs_ : int
        Number of label factors (columns of ``y``; fitted on labels only).
    n_context_ : int
        Columns of the context: the number of styles for a model fitted on
        labels (with several factors, of all their labels).
    context_mean_ : ndarray of shape (n_context,)
        Mean of each column of a real-valued context in ``fit``, which the
        model subtracts from every context it is given (absent when fitted
        without one or on labels).
    context_scale_ : ndarray of shape (n_context,)
        Standard deviation of each column (1 for a constant one), by which
        the model divides every context it is given.
    visible_factors_ : ndarray of shape (n_features, n_factors)
        ``W_v``: the visible units' weights to the undirected factors.
    hidden_factors_ : ndarray of shape (n_components, n_factors)
        ``W_h``: the hidden units' weights to the undirected factors.
    past_visible_factors_ : ndarray of shape (order * n_features, n_factors)
        ``P_A``: the past's weights to the autoregressive factors (lag-major
        rows: ``x[t-1]`` first).
    visible_from_factors_ : ndarray of shape (n_features, n_factors)
        ``A_v``: the autoregressive factors' weights to the visible units.
    past_hidden_factors_ : ndarray of shape (order * n_features, n_factors)
        ``P_B``.
    hidden_from_factors_ : ndarray of shape (n_components, n_factors)
        ``B_h``.
    label_features_ : ndarray of shape (n_context, n_style_features)
        ``R``: the style features of each label (each column of the context).
    style_factors_ : ndarray of shape (n_style_features, n_factors)
        ``Z``: the style features' weights to every kind of factor (with
        ``shared_style_weights``; otherwise ``style_undirected_``,
        ``style_hidden_`` and ``style_visible_``).
    intercept_hidden_ : ndarray of shape (n_components,)
    intercept_visible_ : ndarray of shape (n_features,)
    seed_windows_ : ndarray of shape (n_windows, order, n_features)
        Windows of training frames kept to seed :meth:`sample`.
    reconstruction_error_ : float
        Mean squared reconstruction error per frame of the last epoch.
    n_iter_ : int
        Epochs trained so far.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    ConditionalRBM : One style, or styles modelled implicitly.

    References
    ----------
    G. W. Taylor and G. E. Hinton. Factored Conditional Restricted Boltzmann
    Machines for Modeling Motion Style. ICML 2009.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm import FactoredCRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, ids = make_oscillations(n_sequences=4, n_frames=60, random_state=0)
    >>> styles = np.where(ids < 2, "slow", "fast")
    >>> model = FactoredCRBM(16, n_factors=8, n_style_features=4, order=2,
    ...                      cd_steps=1, n_iter=5, random_state=0)
    >>> model = model.fit(X, styles, sequence_ids=ids)
    >>> model.classes_
    array(['fast', 'slow'], dtype='<U4')
    >>> model.sample(20, style="slow", n_sequences=2, n_gibbs=5).shape
    (40, 6)
    >>> weights = np.linspace([1, 0], [0, 1], 20)  # from fast to slow
    >>> model.sample(20, style=weights, n_gibbs=5).shape
    (20, 6)

    Two label factors, content and style, one column each:

    >>> content = np.where(ids % 2 == 0, "walk", "run")
    >>> y = np.stack([content, styles], axis=1)
    >>> model = model.fit(X, y, sequence_ids=ids)
    >>> model.classes_
    [array(['run', 'walk'], dtype='<U4'), array(['fast', 'slow'], dtype='<U4')]
    >>> model.predict(X[:60]).shape
    (60, 2)
    >>> [proba.shape for proba in model.predict_proba(X[:60])]
    [(60, 2), (60, 2)]
    >>> model.sample(20, y=("run", {"fast": 0.5, "slow": 0.5}), n_gibbs=5).shape
    (20, 6)
    """

    _parameter_constraints: dict = {
        **BaseStyleModel._parameter_constraints,
        "order": [Interval(Integral, 0, None, closed="left")],
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "n_factors": [Interval(Integral, 1, None, closed="left")],
        "n_style_features": [Interval(Integral, 1, None, closed="left")],
        "shared_style_weights": ["boolean"],
        "momentum_ramp": [Interval(Integral, 0, None, closed="left")],
        "balance_styles": ["boolean"],
        "max_step": [Interval(Real, 0, None, closed="neither"), None],
        "n_gibbs": [Interval(Integral, 0, None, closed="left")],
        "learning_rate": [Interval(Real, 0, None, closed="neither")],
    }

    # A new frame's Gibbs chain starts at the previous frame plus this much
    # noise, as in the released code.
    _start_jitter = 0.05

    visible_factors_ = FittedParameter("visible_factors")
    hidden_factors_ = FittedParameter("hidden_factors")
    past_visible_factors_ = FittedParameter("past_visible_factors")
    visible_from_factors_ = FittedParameter("visible_from_factors")
    past_hidden_factors_ = FittedParameter("past_hidden_factors")
    hidden_from_factors_ = FittedParameter("hidden_from_factors")
    label_features_ = FittedParameter("label_features")
    style_factors_ = FittedParameter("style_factors")
    style_undirected_ = FittedParameter("style_undirected")
    style_hidden_ = FittedParameter("style_hidden")
    style_visible_ = FittedParameter("style_visible")
    intercept_hidden_ = FittedParameter("hidden_bias")
    intercept_visible_ = FittedParameter("visible_bias")

    def __init__(
        self,
        n_components=600,
        *,
        n_factors=200,
        n_style_features=100,
        order=6,
        shared_style_weights=True,
        learning_rate=1e-2,
        momentum=0.9,
        momentum_delay=5,
        momentum_ramp=0,
        balance_styles=True,
        max_step=0.25,
        weight_decay=2e-4,
        cd_steps=10,
        batch_size=100,
        batching="shuffled",
        history_noise=1.0,
        history_noise_fraction=1.0,
        average_fraction=0.0,
        n_iter=200,
        n_gibbs=100,
        priors=None,
        ais_steps=50,
        ais_chains=2,
        early_stopping=False,
        validation_fraction=0.1,
        n_iter_no_change=50,
        validation_interval=10,
        tol=1e-3,
        n_mean_field=1,
        hidden_drift=0.0,
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
        self.n_factors = n_factors
        self.n_style_features = n_style_features
        self.shared_style_weights = shared_style_weights
        self.momentum_ramp = momentum_ramp
        self.balance_styles = balance_styles
        self.max_step = max_step
        self.n_gibbs = n_gibbs
        self.priors = priors
        self.ais_steps = ais_steps
        self.ais_chains = ais_chains
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.validation_interval = validation_interval
        self.tol = tol

    def _train(self, X, frames, n_epochs, n_averaged=0, context=None):
        if self.balance_styles and self._labelled:
            frames = balanced_frames(frames, context, blocks(self._factor_classes))
        super()._train(X, frames, n_epochs, n_averaged, context)

    def _new_layer(self, n_features, n_context, dtype):
        return FactoredLayer(
            n_features,
            self.n_components,
            self.n_factors,
            self.n_style_features,
            n_context,
            self.order,
            dtype,
            shared_style_weights=self.shared_style_weights,
        )
