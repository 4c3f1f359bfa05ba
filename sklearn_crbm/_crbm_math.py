"""The mathematics of the conditional RBM, in one place.

Every estimator (ConditionalRBM, StackedCRBM, CRBMImputer) calls these
functions; none re-derives an energy, a conditional or a gradient.

Notation (paper, Section 2): visible frame ``v`` (``n_features``), hidden
units ``h`` (``n_components``), symmetric weights ``W`` (``components_``),
hidden bias ``b``, visible bias ``c``, and the history ``x[t-1], ..., x[t-L]``
flattened lag-major into one row.  The directed connections are packed into
a single matrix ``dynamic`` of shape ``(n_features + n_components, L *
n_features)``: its first ``n_features`` rows are the autoregressive weights
``A`` (past -> visible), the remaining rows the weights ``B`` (past ->
hidden).  Both dynamic biases thus come out of one matrix product::

    [c_hat, b_hat] = history @ dynamic.T + [c, b]

When ``order != hidden_order`` the blocks of lags a group does not use are
kept at exactly zero.

With Gaussian visibles of unit variance the energy given the history is

    E(v, h) = ||v - c_hat||^2 / 2 - b_hat . h - v . (W.T h)

so that ``p(h_j = 1 | v) = sigmoid(b_hat_j + W_j . v)`` and ``p(v | h) =
N(c_hat + W.T h, I)``.  With binary visibles the quadratic term becomes
``-c_hat . v`` and ``p(v_i = 1 | h) = sigmoid(c_hat_i + (W.T h)_i)``.
"""

import numpy as np
from scipy.special import expit

GAUSSIAN = "gaussian"
BINARY = "binary"


class CRBMParameters:
    """Packed parameters of one CRBM, in the layout the math works on.

    Parameters
    ----------
    weights : ndarray of shape (n_components, n_features)
    hidden_bias : ndarray of shape (n_components,)
    visible_bias : ndarray of shape (n_features,)
    dynamic : ndarray of shape (n_features + n_components, n_lags * n_features)
    order, hidden_order : int
    visible_type : {"gaussian", "binary"}
    """

    def __init__(
        self,
        weights,
        hidden_bias,
        visible_bias,
        dynamic,
        order,
        hidden_order,
        visible_type,
    ):
        self.weights = weights
        self.hidden_bias = hidden_bias
        self.visible_bias = visible_bias
        self.dynamic = dynamic
        self.order = order
        self.hidden_order = hidden_order
        self.visible_type = visible_type

    @property
    def n_features(self):
        return self.weights.shape[1]

    @property
    def n_components(self):
        return self.weights.shape[0]

    @property
    def n_lags(self):
        return max(self.order, self.hidden_order)

    @property
    def dtype(self):
        return self.weights.dtype

    @classmethod
    def initialize(
        cls, n_features, n_components, order, hidden_order, visible_type, dtype, rng
    ):
        """The original code's initialisation (REFERENCE.md).

        ``W``, ``A``, ``B`` and the visible bias are N(0, 0.01^2); the hidden
        bias is -1 + N(0, 0.01^2) so that hidden units start mostly off.
        """
        n_lags = max(order, hidden_order)

        def normal(*shape):
            return (0.01 * rng.standard_normal(shape)).astype(dtype, copy=False)

        dynamic = normal(n_features + n_components, n_lags * n_features)
        params = cls(
            weights=normal(n_components, n_features),
            hidden_bias=(normal(n_components) - 1).astype(dtype, copy=False),
            visible_bias=normal(n_features),
            dynamic=dynamic,
            order=order,
            hidden_order=hidden_order,
            visible_type=visible_type,
        )
        params.dynamic *= params.dynamic_mask()
        return params

    @classmethod
    def from_arrays(
        cls,
        components,
        intercept_hidden,
        intercept_visible,
        autoregressive,
        past_to_hidden,
        visible_type,
        dtype=None,
    ):
        """Pack the public 3-D directed weights into one ``dynamic`` matrix."""
        dtype = components.dtype if dtype is None else dtype
        n_components, n_features = components.shape
        order, hidden_order = len(autoregressive), len(past_to_hidden)
        n_lags = max(order, hidden_order)
        dynamic = np.zeros(
            (n_features + n_components, n_lags * n_features), dtype=dtype
        )
        dynamic[:n_features, : order * n_features] = _lag_blocks_to_matrix(
            autoregressive
        )
        dynamic[n_features:, : hidden_order * n_features] = _lag_blocks_to_matrix(
            past_to_hidden
        )
        return cls(
            weights=np.asarray(components, dtype=dtype),
            hidden_bias=np.asarray(intercept_hidden, dtype=dtype),
            visible_bias=np.asarray(intercept_visible, dtype=dtype),
            dynamic=dynamic,
            order=order,
            hidden_order=hidden_order,
            visible_type=visible_type,
        )

    def autoregressive(self):
        """A as ``(order, n_features, n_features)``; block ``q-1`` acts on x[t-q]."""
        n = self.n_features
        return _matrix_to_lag_blocks(self.dynamic[:n, : self.order * n], self.order, n)

    def past_to_hidden(self):
        """``B`` as ``(hidden_order, n_components, n_features)``."""
        n = self.n_features
        block = self.dynamic[n:, : self.hidden_order * n]
        return _matrix_to_lag_blocks(block, self.hidden_order, n)

    def dynamic_mask(self):
        """1 where a directed weight exists, 0 on the lags a group does not use."""
        n = self.n_features
        mask = np.zeros(self.dynamic.shape, dtype=self.dtype)
        mask[:n, : self.order * n] = 1
        mask[n:, : self.hidden_order * n] = 1
        return mask

    def arrays(self):
        """The trainable arrays, in the order gradients are returned."""
        return (self.weights, self.hidden_bias, self.visible_bias, self.dynamic)

    def is_finite(self):
        return all(np.isfinite(a).all() for a in self.arrays())


def _lag_blocks_to_matrix(blocks):
    """(q, rows, n) -> (rows, q * n) with block ``q-1`` in columns ``(q-1)n : qn``."""
    q, rows, n = blocks.shape
    return np.transpose(blocks, (1, 0, 2)).reshape(rows, q * n)


def _matrix_to_lag_blocks(matrix, q, n):
    rows = matrix.shape[0]
    return np.ascontiguousarray(np.transpose(matrix.reshape(rows, q, n), (1, 0, 2)))


def dynamic_biases(params, history):
    """Visible and hidden biases of each frame given its flattened history.

    Parameters
    ----------
    params : CRBMParameters
    history : ndarray of shape (n_frames, n_lags * n_features)

    Returns
    -------
    visible_bias : ndarray of shape (n_frames, n_features)
    hidden_bias : ndarray of shape (n_frames, n_components)
    """
    n = params.n_features
    if params.n_lags == 0:
        shape = (history.shape[0], 1)
        return (
            np.broadcast_to(params.visible_bias, shape[:1] + (n,)).copy(),
            np.broadcast_to(
                params.hidden_bias, shape[:1] + (params.n_components,)
            ).copy(),
        )
    both = history @ params.dynamic.T
    both[:, :n] += params.visible_bias
    both[:, n:] += params.hidden_bias
    return both[:, :n], both[:, n:]


def hidden_probabilities(params, visible, hidden_bias):
    """p(h = 1 | v, history) (paper Eq. 2 with the dynamic hidden bias)."""
    activation = visible @ params.weights.T
    activation += hidden_bias
    return expit(activation, out=activation)


def visible_means(params, hidden, visible_bias):
    """E[v | h, history] (paper Eq. 3 with the dynamic visible bias)."""
    mean = hidden @ params.weights
    mean += visible_bias
    if params.visible_type == BINARY:
        expit(mean, out=mean)
    return mean


def sample_bernoulli(probabilities, rng):
    """Binary states with the given probabilities, in their dtype."""
    uniform = rng.random(probabilities.shape, dtype=probabilities.dtype)
    return (uniform < probabilities).astype(probabilities.dtype)


def sample_visible_states(params, means, rng):
    """Draws from p(v | h, history) given its means: N(mean, I) or Bernoulli(mean)."""
    if params.visible_type == BINARY:
        return sample_bernoulli(means, rng)
    return means + rng.standard_normal(means.shape, dtype=means.dtype)


def free_energy(params, visible, visible_bias, hidden_bias):
    """F(v | history), so that p(v | history) is proportional to exp(-F).

    Gaussian: ``||v - c_hat||^2 / 2 - sum_j softplus(b_hat_j + W_j . v)``;
    binary: ``-c_hat . v - sum_j softplus(...)``.
    """
    activation = visible @ params.weights.T
    activation += hidden_bias
    softplus = np.logaddexp(0, activation).sum(axis=1)
    if params.visible_type == GAUSSIAN:
        quadratic = 0.5 * np.square(visible - visible_bias).sum(axis=1)
    else:
        quadratic = -(visible * visible_bias).sum(axis=1)
    return quadratic - softplus


def cd_gradients(params, visible, history, cd_steps, rng):
    """Contrastive-divergence statistics of one minibatch (paper Eqs. 4-7, §2.2).

    Positive phase: hidden probabilities from the data, binary hidden states
    sampled and used in the positive statistics.  Each reconstruction sets the
    visibles to their mean given sampled hidden states; the negative
    statistics use the hidden *probabilities* of the last reconstruction.
    The visible bias and autoregressive gradients use the residual against
    the dynamic visible bias, which reduces to ``v - v_recon``.

    Returns
    -------
    gradients : tuple of ndarray
        Sums over the batch (not means) for ``weights``, ``hidden_bias``,
        ``visible_bias`` and ``dynamic``, in the order of
        ``CRBMParameters.arrays``; ascent directions.
    squared_error : float
        Sum over the batch of ``||v - v_recon||^2``.
    """
    visible_bias, hidden_bias = dynamic_biases(params, history)
    positive_probabilities = hidden_probabilities(params, visible, hidden_bias)
    positive_states = sample_bernoulli(positive_probabilities, rng)

    hidden = positive_states
    for step in range(cd_steps):
        reconstruction = visible_means(params, hidden, visible_bias)
        negative_probabilities = hidden_probabilities(
            params, reconstruction, hidden_bias
        )
        if step + 1 < cd_steps:
            hidden = sample_bernoulli(negative_probabilities, rng)

    visible_delta = visible - reconstruction
    hidden_delta = positive_states - negative_probabilities
    grad_weights = (
        positive_states.T @ visible - negative_probabilities.T @ reconstruction
    )
    grad_hidden_bias = hidden_delta.sum(axis=0)
    grad_visible_bias = visible_delta.sum(axis=0)
    if params.n_lags:
        grad_dynamic = np.concatenate((visible_delta, hidden_delta), axis=1).T @ history
        if params.order != params.hidden_order:
            grad_dynamic *= params.dynamic_mask()
    else:
        grad_dynamic = np.zeros_like(params.dynamic)
    squared_error = float(np.einsum("ij,ij->", visible_delta, visible_delta))
    return (
        grad_weights,
        grad_hidden_bias,
        grad_visible_bias,
        grad_dynamic,
    ), squared_error


def gibbs_frames(
    params,
    start,
    visible_bias,
    hidden_bias,
    n_gibbs,
    rng,
    *,
    hidden_noise=0.0,
    observed_mask=None,
    sample_visibles=False,
):
    """Alternating Gibbs sampling of new frames given their dynamic biases.

    The original generation scheme (REFERENCE.md, ``gen.m``): ``n_gibbs``
    iterations in which the hidden units are sampled and the visibles set to
    their mean, then one final mean-field step with hidden probabilities.
    ``hidden_noise`` adds N(0, hidden_noise^2) to the hidden biases each time
    hidden states are chosen (paper §4.3).  Where ``observed_mask`` is True
    the visibles stay clamped at their value in ``start`` (paper §4.4).
    With ``sample_visibles=True`` the visibles are drawn from ``p(v | h,
    history)`` at every step and the last draw is returned (no mean-field
    step): an exact Gibbs sampler of ``p(v_t | history)``.

    Parameters
    ----------
    start : ndarray of shape (n, n_features)
        Initial visible state of each chain.
    visible_bias, hidden_bias : ndarray
        Dynamic biases from :func:`dynamic_biases`.

    Returns
    -------
    frames : ndarray of shape (n, n_features)
    """
    visible = start.copy()
    clamped = None
    if observed_mask is not None:
        clamped = start[observed_mask]
    for _ in range(n_gibbs):
        bias = hidden_bias
        if hidden_noise:
            bias = hidden_bias + hidden_noise * rng.standard_normal(
                hidden_bias.shape, dtype=hidden_bias.dtype
            )
        hidden = sample_bernoulli(hidden_probabilities(params, visible, bias), rng)
        visible = visible_means(params, hidden, visible_bias)
        if sample_visibles:
            visible = sample_visible_states(params, visible, rng)
        if clamped is not None:
            visible[observed_mask] = clamped
    if sample_visibles:
        return visible
    visible = visible_means(
        params, hidden_probabilities(params, visible, hidden_bias), visible_bias
    )
    if clamped is not None:
        visible[observed_mask] = clamped
    return visible


def mean_field_prediction(params, visible_bias, hidden_bias, n_steps):
    """Deterministic estimate of E[v_t | history] by mean-field iteration.

    Starts from the autoregressive prediction ``c_hat`` (so it uses nothing
    but the model and the history) and alternates hidden probabilities and
    visible means ``n_steps`` times.
    """
    visible = visible_bias.copy()
    if params.visible_type == BINARY:
        expit(visible, out=visible)
    for _ in range(n_steps):
        visible = visible_means(
            params, hidden_probabilities(params, visible, hidden_bias), visible_bias
        )
    return visible
