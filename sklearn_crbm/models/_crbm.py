"""Conditional Restricted Boltzmann Machine (Taylor, Hinton & Roweis, 2006)."""

from numbers import Integral

import numpy as np
from sklearn.externals import array_api_compat
from sklearn.utils._array_api import (
    _convert_to_numpy,
)
from sklearn.utils._param_validation import Interval, StrOptions

from ..layers._base import BINARY
from ..layers._crbm import (
    MIN_LOG_VARIANCE,
    ORDER_CONSTRAINTS,
    CRBMLayer,
    hidden_order_of,
)
from ..utils._array_api import array_ops
from ..utils._autoregression import ridge_autoregression
from ._base import FittedParameter
from ._one_layer import BaseLayerModel

# Ridge penalty of init="autoregressive": AutoregressiveImputer's default.
_AUTOREGRESSIVE_ALPHA = 1.0


class ConditionalRBM(BaseLayerModel):
    """Conditional Restricted Boltzmann Machine for sequences of frames.

    Models each frame with Gaussian or binary visible units and binary hidden
    units, given the previous frames of its sequence (Taylor, Hinton & Roweis,
    2006) and, if given, a real-valued per-frame ``context`` such as a speed.
    ``X`` stacks all sequences; ``sequence_ids`` marks the frames of each.

    Read more in the :ref:`User Guide <training>`.

    Parameters
    ----------
    n_components : int, default=200
        Number of binary hidden units.
    order : int, default=3
        Number of past frames feeding the visible units (0, 0: a plain RBM).
    hidden_order : int, default=None
        Number of past frames feeding the hidden units; ``None`` means ``order``.
    visible_type : {"gaussian", "binary"}, default="gaussian"
        Gaussian units for standardised data, binary units for data in [0, 1].
    visible_variance : {"unit", "learned", "residual"}, default="unit"
        Variance of the Gaussian visibles: 1 (the paper's), trained per channel,
        or the one-step residual of a ridge AR(``order``) per channel.
    init : {"random", "autoregressive"}, default="random"
        Small random weights, or the autoregressive part from that ridge AR.
    centering : bool, default=False
        Step as if the hidden units saw the frame's residual ``(v - c_hat) / s``.
    learning_rate : float, default=1e-3
        Step size for every parameter group.
    momentum, momentum_delay : float, int, default=0.9, 5
        Momentum, used after the first ``momentum_delay`` epochs.
    weight_decay : float, default=2e-4
        L2 penalty on the symmetric and directed weights (not on biases).
    cd_steps, batch_size : int, default=1, 100
        Gibbs steps per reconstruction (CD-k); frames per minibatch.
    batching : {"balanced", "shuffled"}, default="balanced"
        The paper's minibatches (a frame per chunk) or its code's (shuffled).
    history_noise : float, default=1.0
        Standard deviation of noise on the past frames in training (paper: 0).
    history_noise_fraction : float in (0, 1], default=0.5
        Probability that a channel of a frame's history gets that noise.
    average_fraction : float in [0, 1), default=0.25
        Fraction of the last epochs whose parameters :meth:`fit` averages.
    n_iter : int or "auto", default="auto"
        Number of epochs.  ``"auto"``: 1000, but at least 25,000 and at most
        100,000 minibatch updates (:ref:`training`).
    ais_steps, ais_chains : int, default=50, 2
        Annealing steps, and chains per frame, of :meth:`score`.
    early_stopping : bool, default=False
        Hold out whole sequences in :meth:`fit`; keep the best-scoring epoch.
    validation_fraction : float, default=0.1
        Fraction of the frames, in whole sequences, held out.
    n_iter_no_change, validation_interval : int, default=50, 10
        Epochs without an improvement of ``tol`` that stop training; epochs
        between two validation scores.
    tol : float, default=1e-3
        Improvement of the validation score, in nats per frame, that counts.
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
        Seeds training and, unless :meth:`sample` is given its own, generation.
    verbose : int, default=0
        Every ``verbose`` epochs, print the prediction and reconstruction
        errors, the time and the validation log-likelihood (if any).

    Attributes
    ----------
    components_ : ndarray of shape (n_components, n_features)
        Symmetric weights ``W`` between hidden and visible units.
    intercept_hidden_, intercept_visible_ : ndarray
        Static hidden biases (n_components,) and visible biases (n_features,).
    autoregressive_ : ndarray of shape (order, n_features, n_features)
        ``autoregressive_[q - 1] @ x[t - q]`` adds to frame ``t``'s visible mean.
    past_to_hidden_ : ndarray of shape (hidden_order, n_components, n_features)
        ``past_to_hidden_[q - 1] @ x[t - q]`` adds to frame ``t``'s hidden input.
    visible_variance_ : ndarray of shape (n_features,)
        Variance of each Gaussian visible unit (ones for ``"unit"``).
    context_to_visible_ : ndarray of shape (n_features, n_context)
        ``context_to_visible_ @ y_t`` adds to frame ``t``'s visible mean.
    context_to_hidden_ : ndarray of shape (n_components, n_context)
        ``context_to_hidden_ @ y_t`` adds to frame ``t``'s hidden input.
    n_context_ : int
        Columns of the context the model was fitted with (0: none).
    context_mean_, context_scale_ : ndarray of shape (n_context,)
        Each context column's mean and standard deviation in ``fit`` (1 if
        constant): ``y_t`` above is the context less the mean, over the scale.
    seed_windows_ : ndarray of shape (n_windows, width, n_features)
        Windows of consecutive training frames that seed :meth:`sample`.
    reconstruction_error_ : float
        Mean squared reconstruction error per frame in the last epoch.
    random_state_ : RandomState instance
        Random generator state carried across :meth:`partial_fit` calls.
    n_iter_ : int
        Number of epochs trained so far.
    validation_scores_, best_validation_score_ : list of float, float
        With ``early_stopping``: the held-out scores, and the best (kept).
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    StackedCRBM : Greedy layer-wise stack of conditional RBMs.

    References
    ----------
    G. W. Taylor, G. E. Hinton and S. Roweis. Modeling Human Motion Using
    Binary Latent Variables. NIPS 19, 2006.

    Examples
    --------
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, sequence_ids = make_oscillations(n_sequences=4, n_frames=50, random_state=0)
    >>> model = ConditionalRBM(n_components=16, order=2, n_iter=20, random_state=0)
    >>> model.fit(X, sequence_ids=sequence_ids)
    ConditionalRBM(n_components=16, n_iter=20, order=2, random_state=0)
    >>> model.sample(30, n_sequences=3, random_state=0).shape
    (90, 6)
    """

    _parameter_constraints: dict = {
        **BaseLayerModel._parameter_constraints,
        **ORDER_CONSTRAINTS,
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "visible_type": [StrOptions({"gaussian", "binary"})],
        "visible_variance": [StrOptions({"unit", "learned", "residual"})],
        "init": [StrOptions({"random", "autoregressive"})],
        "centering": ["boolean"],
    }

    components_ = FittedParameter("weights")
    intercept_hidden_ = FittedParameter("hidden_bias")
    intercept_visible_ = FittedParameter("visible_bias")
    autoregressive_ = FittedParameter("autoregressive")
    past_to_hidden_ = FittedParameter("past_to_hidden")
    visible_variance_ = FittedParameter("visible_variance")
    context_to_visible_ = FittedParameter("context_to_visible")
    context_to_hidden_ = FittedParameter("context_to_hidden")

    def __init__(
        self,
        n_components=200,
        *,
        order=3,
        hidden_order=None,
        visible_type="gaussian",
        visible_variance="unit",
        init="random",
        centering=False,
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
        n_iter="auto",
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
        self.visible_type = visible_type
        self.visible_variance = visible_variance
        self.init = init
        self.centering = centering
        self.ais_steps = ais_steps
        self.ais_chains = ais_chains
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.validation_interval = validation_interval
        self.tol = tol

    # The training of the paper and of its released code.
    _PAPER_SCHEDULE = dict(
        n_components=200,
        order=3,
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=100,
        batching="shuffled",
        history_noise=0.0,
        history_noise_fraction=1.0,
        average_fraction=0.0,
        visible_variance="unit",
        centering=False,
        n_iter=4000,
    )

    @classmethod
    def paper_schedule(cls, **params):
        """A model with the exact training schedule of the paper.

        Taylor, Hinton & Roweis (2006) and their released code: 200 hidden
        units, order 3, CD-1 with learning rate 1e-3 for every parameter
        group, momentum 0.9 after 5 epochs, weight decay 2e-4 on the
        weights, minibatches of 100 frames shuffled each epoch, clean
        histories (``history_noise=0``), 4000 epochs: the paper's experiments
        as they were run.  The defaults differ (``history_noise``,
        ``batching``; :ref:`what_we_tried` says why).

        Parameters
        ----------
        **params
            Parameters that replace those of the schedule, e.g.
            ``n_iter=1000`` or ``random_state=0``.

        Returns
        -------
        model : ConditionalRBM
            Unfitted.

        Examples
        --------
        >>> from sklearn_crbm import ConditionalRBM
        >>> model = ConditionalRBM.paper_schedule(n_iter=1000, random_state=0)
        >>> model.n_components, model.history_noise, model.batching
        (200, 0.0, 'shuffled')
        """
        return cls(**{**cls._PAPER_SCHEDULE, **params})

    # ------------------------------------------------------------ hooks

    def _new_layer(self, n_features, n_context, dtype):
        return CRBMLayer(
            n_features,
            self.n_components,
            self.order,
            hidden_order_of(self),
            self.visible_type,
            dtype,
            n_context=n_context,
            learned_variance=self.visible_variance == "learned",
            fixed_variance=self.visible_variance == "residual",
            centered=self.centering,
        )

    def _check_training_data(self, X):
        if self.visible_type == BINARY and self.visible_variance != "unit":
            raise ValueError(
                f"visible_variance={self.visible_variance!r} needs Gaussian "
                "visibles; binary visibles have no variance. Use "
                "visible_variance='unit'."
            )
        if self.centering and self.visible_type == BINARY:
            raise ValueError(
                "centering=True centres the hidden units' input on the Gaussian "
                "visible mean and needs Gaussian visibles. Use centering=False "
                "with binary visibles."
            )
        if self.centering and hidden_order_of(self) < self.order:
            raise ValueError(
                f"centering=True needs hidden_order >= order (got hidden_order="
                f"{hidden_order_of(self)}, order={self.order}): the centred hidden "
                "input is written back through the past-to-hidden weights of every "
                "autoregressive lag. Raise hidden_order or use centering=False."
            )
        if self.visible_type == BINARY and self.init == "autoregressive":
            raise ValueError(
                "init='autoregressive' starts from a linear-Gaussian model and "
                "needs Gaussian visibles. Use init='random' with binary visibles."
            )
        ops = array_ops(X)
        low, high = float(ops.min(X)), float(ops.max(X))
        if self.visible_type == BINARY and (low < 0 or high > 1):
            raise ValueError(
                "visible_type='binary' needs data in [0, 1] (binary values or "
                f"probabilities); got values in [{low:g}, {high:g}]. Use "
                "visible_type='gaussian' for standardised real-valued data."
            )

    def _start_parameters(self, X, frames, context=None):
        """Start from the ridge AR of ``frames`` where the parameters ask for it.

        ``init="autoregressive"`` sets the autoregressive weights, the
        visible biases and (learned variances) the visible variances; the
        other groups keep their random start.  ``visible_variance="residual"``
        sets the visible variances, whatever ``init``.
        """
        residual = self.visible_variance == "residual"
        if self.init != "autoregressive" and not residual:
            return
        if not isinstance(X, np.ndarray):  # array API input: fitted with numpy
            X = _convert_to_numpy(X, array_api_compat.array_namespace(X))
        fit = ridge_autoregression(
            X.astype(np.float64), frames, self.order, _AUTOREGRESSIVE_ALPHA
        )
        if self.init == "autoregressive":
            self.autoregressive_ = fit.coef.astype(X.dtype)
            self.intercept_visible_ = fit.intercept.astype(X.dtype)
        learned = self._layer.learned_variance
        if residual or (learned and self.init == "autoregressive"):
            variance = np.mean(np.square(fit.residual), axis=0)
            self.visible_variance_ = np.maximum(
                variance, np.exp(MIN_LOG_VARIANCE)
            ).astype(X.dtype)
