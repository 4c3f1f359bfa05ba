"""Log-likelihood of frames under a conditional RBM: exact or annealed.

Given its history, frame ``t`` of a CRBM is an RBM with dynamic biases
``c_hat`` (visible) and ``b_hat`` (hidden).  With Gaussian visibles of
standard deviation ``s`` (one per channel, the square root of
``visible_variance_``) its energy is (Hinton's practical guide)::

    E(v, h) = sum_i (v_i - c_hat_i)^2 / (2 s_i^2) - b_hat . h - (v / s) . (W.T h)

and with binary visibles ``E(v, h) = -c_hat . v - b_hat . h - v . (W.T h)``.
Summing out the hiddens gives the free energy ``F(v)`` and

    log p(v | history) = -F(v) - log Z(history).

``log Z`` is a sum over the ``2 ** n_components`` hidden configurations
(the visibles integrate in closed form for a given ``h``)::

    Gaussian: log Z = logsumexp_h [b_hat . h + (c_hat / s) . u + ||u||^2 / 2]
                      + sum_i log(sqrt(2 pi) s_i),          u = W.T h
    binary:   log Z = logsumexp_h [b_hat . h + sum_i softplus(c_hat_i + u_i)]

which :func:`log_partition_exact` enumerates when that is cheap.  Otherwise
annealed importance sampling (Salakhutdinov & Murray, 2008) estimates it,
for all frames at once, each with its own chains.  The annealing runs from a
factorial base distribution at the frame's mean-field fixed point (visible
mean ``m``, hidden probabilities ``q``; base logits ``a = logit(q)``) to the
frame's RBM along the intermediate RBMs

    log f_beta(v) = base(v) + beta g(v) + sum_j softplus(a_j + beta (x_j(v) - a_j))

with ``x(v) = b_hat + W (v / s)`` the hidden input, ``base(v)`` the log
density of the base visibles (Gaussian ``N(m, s^2)`` up to its normaliser,
or Bernoulli with logits ``logit(m)``) and ``g(v)`` the change of the
visible term from the base to the model.  ``beta = 0`` is the base (known
normaliser ``Z_0``), ``beta = 1`` the model.  Each intermediate RBM has
exact block-Gibbs conditionals, with visible field ``m + beta (c_hat - m) +
beta s (W.T h)`` (Gaussian mean, or binary logits with ``logit(m)`` for
``m``).

The forward estimate of ``log Z`` is low on average (Jensen), so the log
likelihood it gives is high on average.  The reverse estimate (RAISE; Burda,
Grosse & Salakhutdinov, 2015) starts at the data and anneals back to the
base; it is an unbiased estimate of the likelihood under the annealing
process, so its logarithm is low on average: the two bracket the truth when
the annealing is good, and their gap says how far to trust either.
"""

import math
from typing import NamedTuple

import numpy as np

from ..layers._base import clipped_logit, draw_bernoulli, logistic
from ..utils._array_api import array_ops, copy_array

# Hidden configurations summed per block by the exact enumeration.
_EXACT_BLOCK = 4096
# The exact path enumerates at most 2 ** this many hidden configurations.
MAX_EXACT_COMPONENTS = 24
# Rows (frames x chains) an annealing run keeps in memory at once.
_AIS_ROWS = 16384
# Mean-field iterations that find each frame's fixed point (the AIS base).
_MEAN_FIELD_STEPS = 20
# A model without history anneals its one partition function with this many
# times the per-frame distributions, from this many frames at most.
SHARED_STEPS = 5
SHARED_STARTS = 256


class LogLikelihood(NamedTuple):
    """Per-frame log-likelihood estimates, in nats.

    Attributes
    ----------
    log_likelihood : ndarray of shape (n_frames,)
        ``log p(x_t | history)``: exact, or from forward AIS.
    lower : ndarray of shape (n_frames,) or None
        The reverse-annealing (RAISE) estimate, low on average; equal to
        ``log_likelihood`` on the exact path; None when not asked for.
    standard_error : ndarray of shape (n_frames,)
        Standard error of the forward estimate across chains (zero when
        exact), by the delta method on the importance weights.
    method : str
        ``"exact"`` or ``"ais"``.
    """

    log_likelihood: np.ndarray
    lower: np.ndarray | None
    standard_error: np.ndarray
    method: str


# ------------------------------------------------------------------ exact


def hidden_configurations(n_components, start, stop, ops=np):
    """Rows ``start`` to ``stop`` of all binary vectors of length ``n_components``."""
    codes = ops.arange(start, stop, dtype=ops.int64)[:, None]
    bits = ops.arange(n_components, dtype=ops.int64)
    return ops.astype((codes >> bits) & 1, ops.float64)


def log_partition_exact(rbms):
    """``log Z`` of every frame's RBM by enumerating its hidden configurations.

    Parameters
    ----------
    rbms : FrameRBMs

    Returns
    -------
    log_z : ndarray of shape (n_frames,)
    """
    n_components = rbms.n_components
    if n_components > MAX_EXACT_COMPONENTS:
        raise ValueError(
            f"Exact enumeration of {n_components} hidden units means 2**"
            f"{n_components} configurations; it is limited to "
            f"{MAX_EXACT_COMPONENTS} hidden units. Use method='ais'."
        )
    total = 2**n_components
    block = rbms.units.exact_block(_EXACT_BLOCK, rbms)
    ops = rbms.ops
    weights = rbms.shared_weights
    log_z = ops.full(rbms.n_frames, -math.inf, dtype=ops.float64)
    for start in range(0, total, block):
        stop = min(start + block, total)
        hidden = hidden_configurations(n_components, start, stop, ops)
        if weights is not None:  # one u = W.T h per configuration for all frames
            terms = _configuration_terms(rbms, hidden, hidden @ weights)
        else:
            terms = ops.concatenate(
                [
                    _own_configuration_terms(rbms, row, hidden)
                    for row in range(rbms.n_frames)
                ]
            )
        log_z = ops.logaddexp(log_z, _logsumexp_rows(terms))
    return log_z + rbms.log_normaliser()


def _configuration_terms(rbms, hidden, u):
    """``log sum_v exp(-E(v, h))`` up to the normaliser, frames x configurations.

    ``u`` holds ``W.T h`` of every configuration (shape ``(configs,
    n_features)``), the same for every frame of ``rbms``.
    """
    terms = rbms.hidden_bias @ hidden.T
    return rbms.units.add_configuration_terms(rbms, u, terms)


def _own_configuration_terms(rbms, row, hidden):
    """:func:`_configuration_terms` of frame ``row``, whose ``W_t`` is its own."""
    repeated = rbms.take(np.full(hidden.shape[0], row))
    u = repeated.interaction_field(hidden) / rbms.scale
    return _configuration_terms(rbms.take(slice(row, row + 1)), hidden, u)


def _logsumexp_rows(values):
    ops = array_ops(values)
    top = ops.max(values, axis=1)
    return top + ops.log(ops.sum(ops.exp(values - top[:, None]), axis=1))


def exact_is_cheaper(n_components, n_features, n_steps, n_chains):
    """Whether enumerating the hiddens costs less than annealing one frame."""
    if n_components > MAX_EXACT_COMPONENTS:
        return False
    exact = 2.0**n_components * (n_components + 2 * n_features)
    annealed = n_steps * n_chains * (2 * n_components * n_features + 4 * n_components)
    return exact <= annealed


# -------------------------------------------------------------- annealing


def mean_field_base(rbms, start=None, n_steps=_MEAN_FIELD_STEPS):
    """The factorial base of every frame at its mean-field fixed point.

    The iteration starts from the visible bias ``c_hat``, or from ``start``
    (visible values, one row per frame) when given.

    Returns
    -------
    visible_base : ndarray of shape (n_frames, n_features)
        Gaussian: the base mean ``m``; binary: the base logits.
    hidden_logits : ndarray of shape (n_frames, n_components)
    """
    units = rbms.units
    field = copy_array(rbms.visible_bias)
    if start is not None:
        field = units.field_of(start)
    hidden = None
    for _ in range(n_steps):
        visible = units.mean_copy(field)
        hidden = logistic(rbms.hidden_input(visible))
        field = rbms.visible_bias + rbms.interaction_field(hidden)
    return units.base_field(field), clipped_logit(hidden)


class _Annealing:
    """The path from the factorial base to the RBM of every row (one per chain).

    The chains run in float32 (numpy's float32 ``exp`` and ``log1p`` are
    several times faster than float64's); each step's change of the log
    weight is a sum of small elementwise differences, accumulated in
    float64.  ``d = x(v) - a`` is the hidden input's distance from the base
    logits; the intermediate RBM at ``beta`` has hidden logits ``a + beta
    d`` and, from the base to the model, its visible term changes by
    ``beta g(v)`` with ``g`` linear in ``v`` for either visible type
    (Gaussian: ``(c_hat - m) . (v - (c_hat + m) / 2) / s^2``; binary:
    ``(c_hat - logit(m)) . v``).
    """

    def __init__(self, rbms, n_chains, start=None):
        self.ops = ops = rbms.ops
        self.dtype = ops.float32
        visible_base, hidden_logits = mean_field_base(rbms, start)
        rows = np.repeat(np.arange(rbms.n_frames), n_chains)
        self.units = units = rbms.units
        self.n_rows = len(rows)
        self.log_base_normaliser = ops.take(
            ops.sum(ops.logaddexp(0, hidden_logits), axis=1), rows
        )
        self.log_base_normaliser += units.base_log_normaliser(rbms, visible_base, rows)
        scale = rbms.scale
        shift = rbms.visible_bias - visible_base  # c_hat - m
        gradient = units.change_gradient(shift, scale)
        self.change_offset = units.change_offset(rbms, visible_base, gradient, rows)

        def rows_of(array):
            return ops.ascontiguousarray(ops.take(array, rows, axis=0), self.dtype)

        self.scale = ops.astype(scale, self.dtype)
        self.visible_base = rows_of(visible_base)
        self.shift = rows_of(shift)
        self.gradient = rows_of(gradient)
        self.hidden_logits = rows_of(hidden_logits)
        self.input_offset = rows_of(rbms.hidden_bias - hidden_logits)  # b_hat - a
        # every row's interaction (its frame's, one row per chain)
        self.rbms = rbms.take(rows).astype(self.dtype)
        n_hidden = rbms.n_components
        self.difference = ops.empty((self.n_rows, n_hidden), self.dtype)
        self.logits = ops.empty_like(self.difference)
        self.previous = ops.empty_like(self.difference)
        self.work = ops.empty_like(self.difference)

    def sample_base(self, rng):
        return self.units.sample_field(copy_array(self.visible_base), self.scale, rng)

    def step(self, visible, beta, previous_beta):
        """``log f_beta(v) - log f_previous(v)`` of every row (float64).

        Leaves the hidden logits at both temperatures in :attr:`logits`
        (``beta``) and :attr:`previous` (``previous_beta``).
        """
        ops = self.ops
        difference = self.rbms.interaction_input(visible, out=self.difference)
        difference += self.input_offset
        logits = ops.multiply(difference, beta, out=self.logits)
        logits += self.hidden_logits
        previous = ops.multiply(difference, previous_beta - beta, out=self.previous)
        previous += logits
        hidden = _softplus(logits, self.work)
        hidden -= _softplus(previous, self.difference)
        change = ops.einsum("ij,ij->i", visible, self.gradient, dtype=ops.float64)
        change -= self.change_offset
        change *= beta - previous_beta
        change += ops.sum(hidden, axis=1, dtype=ops.float64)
        return change

    def gibbs(self, beta, logits, rng):
        """A block-Gibbs step at ``beta`` from hidden logits ``a + beta d(v)``."""
        hidden = draw_bernoulli(logistic(logits, out=self.work), rng)
        field = self.rbms.interaction_field(hidden)
        field += self.shift
        field *= beta
        field += self.visible_base
        return self.units.sample_field(field, self.scale, rng)


def _softplus(x, out):
    """``log(1 + exp(x))`` elementwise into ``out`` (not ``x``)."""
    ops = array_ops(x)
    out = ops.abs(x, out=out)
    out = ops.negative(out, out=out)
    out = ops.exp(out, out=out)
    out = ops.log1p(out, out=out)
    out += ops.maximum(x, 0)
    return out


def annealing_schedule(n_steps):
    """``n_steps + 1`` inverse temperatures from 0 to 1, denser near 1.

    The RBM's hidden units switch on and off most sharply near ``beta =
    1``; half the steps go to ``[0, 0.75]`` (linear), half to ``[0.75, 1]``.
    """
    if n_steps < 2:
        return np.linspace(0.0, 1.0, n_steps + 1)
    first = n_steps // 2
    return np.concatenate(
        (
            np.linspace(0.0, 0.75, first + 1)[:-1],
            np.linspace(0.75, 1.0, n_steps - first + 1),
        )
    )


def _schedule(n_steps, ops):
    """:func:`annealing_schedule`: numpy scalars for numpy, Python floats elsewhere."""
    betas = annealing_schedule(n_steps)
    return betas if ops is np else betas.tolist()


def log_partition_ais(rbms, n_steps, n_chains, rng):
    """Forward AIS estimate of every frame's ``log Z``, with its standard error.

    Parameters
    ----------
    rbms : FrameRBMs
    n_steps : int
        Intermediate distributions (transitions) per chain.
    n_chains : int
        Independent chains per frame.
    rng : numpy.random.Generator

    Returns
    -------
    log_z : ndarray of shape (n_frames,)
        ``log`` of the mean importance weight times ``Z_0``.
    standard_error : ndarray of shape (n_frames,)
        Delta-method standard error of ``log_z`` across chains.
    """
    ops = rbms.ops
    log_z = ops.empty(rbms.n_frames, dtype=ops.float64)
    error = ops.empty(rbms.n_frames, dtype=ops.float64)
    for rows in _row_blocks(rbms.n_frames, n_chains):
        log_weights = _forward_log_weights(rbms.take(rows), n_steps, n_chains, rng)
        log_z[rows], error[rows] = _log_mean_exp(log_weights)
    return log_z, error


def shared_log_partition_ais(rbms, starts, n_steps, n_chains, rng):
    """AIS estimate of the one ``log Z`` of an RBM without history.

    Every frame of a model without history has the same RBM, often with
    several modes (walking and jogging, say).  Chains run from the
    mean-field fixed points reached from each of ``starts`` (frames), so
    that they begin in different modes; each chain's weight, times its own
    base's ``Z_0``, is an unbiased estimate of ``Z``, and all are pooled.

    Parameters
    ----------
    rbms : FrameRBMs
        One frame's RBM (the first row is used).
    starts : ndarray of shape (n_starts, n_features)
        Visible values the mean-field iterations start from.

    Returns
    -------
    log_z : float
    standard_error : float
    """
    ops = rbms.ops
    rbms = rbms.take(np.zeros(starts.shape[0], dtype=np.intp))
    log_weights = [
        _forward_log_weights(rbms.take(rows), n_steps, n_chains, rng, starts[rows, ...])
        for rows in _row_blocks(starts.shape[0], n_chains)
    ]
    log_z, error = _log_mean_exp(ops.reshape(ops.concatenate(log_weights), (1, -1)))
    return float(log_z[0]), float(error[0])


def _forward_log_weights(rbms, n_steps, n_chains, rng, start=None):
    path = _Annealing(rbms, n_chains, start)
    betas = _schedule(n_steps, rbms.ops)
    visible = path.sample_base(rng)
    log_weight = copy_array(path.log_base_normaliser)
    for k in range(1, len(betas)):
        log_weight += path.step(visible, betas[k], betas[k - 1])
        if k < len(betas) - 1:
            visible = path.gibbs(betas[k], path.logits, rng)
    return rbms.ops.reshape(log_weight, (rbms.n_frames, n_chains))


def log_likelihood_raise(rbms, visible, n_steps, n_chains, rng):
    """Reverse-annealing (RAISE) estimate of ``log p(v)``, low on average.

    Each chain starts at the frame ``v``, takes a Gibbs step at every
    inverse temperature from 1 down to the first above 0, and collects
    ``log f_{k-1} - log f_k`` at every state it reaches; with ``-F(v) -
    log Z_0`` this is the log of an unbiased estimate of the likelihood of
    ``v`` under the annealing process that the forward chains follow.

    Returns
    -------
    log_likelihood : ndarray of shape (n_frames,)
    """
    result = rbms.ops.empty(rbms.n_frames, dtype=rbms.ops.float64)
    for rows in _row_blocks(rbms.n_frames, n_chains):
        result[rows] = _reverse_log_likelihood(
            rbms.take(rows), visible[rows, ...], n_steps, n_chains, rng
        )
    return result


def _reverse_log_likelihood(rbms, visible, n_steps, n_chains, rng):
    ops = rbms.ops
    path = _Annealing(rbms, n_chains)
    betas = _schedule(n_steps, rbms.ops)
    start = ops.repeat(rbms.negative_free_energy(visible), n_chains)
    log_weight = start - path.log_base_normaliser
    state = ops.astype(ops.repeat(visible, n_chains, axis=0), path.dtype)
    path.step(state, betas[-1], betas[-2])  # the hidden logits at beta = 1
    logits = path.logits
    for k in range(len(betas) - 1, 0, -1):
        state = path.gibbs(betas[k], logits, rng)
        log_weight -= path.step(state, betas[k], betas[k - 1])
        logits = path.previous
    return _log_mean_exp(ops.reshape(log_weight, (rbms.n_frames, n_chains)))[0]


def _row_blocks(n_frames, n_chains):
    per_block = max(1, _AIS_ROWS // n_chains)
    for lo in range(0, n_frames, per_block):
        yield slice(lo, min(lo + per_block, n_frames))


def _log_mean_exp(log_weights):
    """``log mean exp`` over axis 1, and its delta-method standard error."""
    ops = array_ops(log_weights)
    top = ops.max(log_weights, axis=1, keepdims=True)
    weights = ops.exp(log_weights - top)
    mean = ops.mean(weights, axis=1)
    n = log_weights.shape[1]
    spread = ops.std(weights, axis=1, ddof=1) if n > 1 else ops.zeros_like(mean)
    return top[:, 0] + ops.log(mean), spread / (math.sqrt(n) * mean)


# ----------------------------------------------------------------- public


def log_partition(rbms, *, method, n_steps, n_chains, rng):
    """``log Z`` of every frame, its standard error and the method used.

    ``method="auto"`` enumerates the hiddens when that costs less than
    annealing with ``n_steps`` and ``n_chains`` (:func:`exact_is_cheaper`).
    """
    if method == "auto":
        cheaper = exact_is_cheaper(
            rbms.n_components, rbms.n_features, n_steps, n_chains
        )
        method = "exact" if cheaper else "ais"
    if method == "exact":
        log_z = log_partition_exact(rbms)
        return log_z, rbms.ops.zeros_like(log_z), "exact"
    return (*log_partition_ais(rbms, n_steps, n_chains, rng), "ais")


def _shared_log_partition(rbms, frames, method, n_steps, n_chains, rng):
    """``log Z``, its standard error and the method, for a model without history."""
    picks = np.unique(np.linspace(0, frames.shape[0] - 1, SHARED_STARTS).round())
    starts = rbms.ops.take(frames, picks.astype(np.intp), axis=0)
    n_steps *= SHARED_STEPS
    n_chains_total = n_chains * starts.shape[0]
    one = rbms.take(slice(0, 1))
    if method == "auto":
        cheaper = exact_is_cheaper(
            rbms.n_components, rbms.n_features, n_steps, n_chains_total
        )
        method = "exact" if cheaper else "ais"
    if method == "exact":
        return float(log_partition_exact(one)[0]), 0.0, "exact"
    return (*shared_log_partition_ais(one, starts, n_steps, n_chains, rng), "ais")


def frame_log_likelihood(
    visible,
    chunks,
    *,
    method="auto",
    n_steps=50,
    n_chains=2,
    reverse=False,
    rng=None,
):
    """``log p(v_t | history)`` of frames, chunk by chunk, exact or by AIS.

    Parameters
    ----------
    visible : ndarray of shape (n_frames, n_features)
        The frames, indexed by the rows of ``chunks``.
    chunks : iterable of (rows, FrameRBMs)
        The frames' RBMs, as :func:`~sklearn_crbm.layers.sequence_frame_rbms`
        yields them.  When every frame has the same RBM (``frame_invariant``:
        a layer without history or context), its one partition function is
        annealed once (:func:`shared_log_partition_ais`) with
        ``SHARED_STEPS * n_steps`` distributions and ``n_chains`` chains from
        each of up to ``SHARED_STARTS`` frames.
    method : {"auto", "exact", "ais"}, default="auto"
    n_steps, n_chains : int, default=50, 2
        AIS intermediate distributions and chains per frame.
    reverse : bool, default=False
        Also run reverse annealing (RAISE), a conservative estimate.
    rng : numpy.random.Generator

    Returns
    -------
    LogLikelihood
    """
    rng = np.random.default_rng() if rng is None else rng
    ops = array_ops(visible)
    with np.errstate(under="ignore"):  # exp of very negative numbers is 0
        parts = _chunk_log_likelihoods(
            visible, chunks, method, n_steps, n_chains, reverse, rng
        )
    return LogLikelihood(
        ops.concatenate([p[0] for p in parts]),
        ops.concatenate([p[1] for p in parts]) if reverse else None,
        ops.concatenate([p[2] for p in parts]),
        parts[0][3] if parts else "exact",
    )


def _chunk_log_likelihoods(visible, chunks, method, n_steps, n_chains, reverse, rng):
    shared_partition = None
    parts = []
    for rows, rbms in chunks:
        ops = rbms.ops
        rbms = rbms.astype(ops.float64)  # AIS sums many small log ratios
        if rbms.frame_invariant:
            if shared_partition is None:
                shared_partition = _shared_log_partition(
                    rbms,
                    ops.take(visible, rows, axis=0),
                    method,
                    n_steps,
                    n_chains,
                    rng,
                )
            log_z, error, used = shared_partition
        else:
            log_z, error, used = log_partition(
                rbms, method=method, n_steps=n_steps, n_chains=n_chains, rng=rng
            )
        frames = ops.astype(ops.take(visible, rows, axis=0), ops.float64)
        log_likelihood = rbms.negative_free_energy(frames) - log_z
        lower = None
        if reverse:
            lower = log_likelihood
            if used == "ais":
                lower = log_likelihood_raise(rbms, frames, n_steps, n_chains, rng)
        error = ops.broadcast_to(ops.asarray(error, dtype=ops.float64), (len(rows),))
        parts.append((log_likelihood, lower, error, used))
    return parts


# ------------------------------------------------------------------ stacks


def stack_log_likelihood_bound(stack, visible, *, n_samples, rng, **top):
    """A lower bound on ``log p(v_t | history)`` under a stack of layers.

    The stack generates a frame top-down: the top layer gives the units of
    the layer below it, each lower layer's conditional ``p_l(h_{l-1} |
    h_l)`` the layer below, down to the frame.  With every lower layer's
    posterior ``q_l(h_l | h_{l-1})`` (its hidden probabilities, as in
    training) as the proposal, ``n_samples`` draws ``h_1, ..., h_{L-1}``
    give the importance-weighted bound (Burda, Grosse & Salakhutdinov,
    2016; with one sample the variational bound of Hinton et al., 2006)::

        log mean_s exp(sum_l [log p_l(h_{l-1} | h_l) - log q_l(h_l | h_{l-1})]
                       + log p_top(h_{L-1} | history))

    low on average by Jensen's inequality, whose top term is the top layer's
    exact or annealed log-likelihood.

    Parameters
    ----------
    stack : list of FrameRBMs
        Bottom first: every layer's RBMs of these frames, given its own
        history.
    visible : ndarray of shape (n_frames, n_features)
    n_samples : int
    rng : numpy.random.Generator
    **top
        ``method``, ``n_steps`` and ``n_chains`` for the top layer's
        :func:`log_partition`.

    Returns
    -------
    bound : ndarray of shape (n_frames,)
    """
    n_frames = visible.shape[0]
    ops = array_ops(visible)
    rows = np.repeat(np.arange(n_frames), n_samples)
    state = ops.astype(ops.take(visible, rows, axis=0), ops.float64)
    log_weight = ops.zeros(len(rows), dtype=ops.float64)
    stack = [rbms.astype(ops.float64) for rbms in stack]
    with np.errstate(under="ignore"):
        for rbms in stack[:-1]:
            rbms = rbms.take(rows)
            logits = rbms.hidden_input(state)
            hidden = draw_bernoulli(logistic(copy_array(logits)), rng)
            log_weight -= ops.sum(hidden * logits - ops.logaddexp(0, logits), axis=1)
            log_weight += _log_visible_given_hidden(rbms, state, hidden)
            state = hidden
        top_rbms = stack[-1]
        log_z, _, _ = log_partition(top_rbms, rng=rng, **top)
        top_term = top_rbms.take(rows).negative_free_energy(state)
        log_weight += top_term - ops.take(log_z, rows)
    return _log_mean_exp(ops.reshape(log_weight, (n_frames, n_samples)))[0]


def _log_visible_given_hidden(rbms, visible, hidden):
    """``log p(v | h)`` per row: ``N(c_hat + s W.T h, s^2)`` or Bernoulli."""
    return rbms.units.log_density(rbms, visible, rbms.interaction_field(hidden))
