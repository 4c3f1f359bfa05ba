"""Resampling the particles of on-line fill-in by how well they explain the data."""

from ._gibbs import observed_log_likelihood, stacked_prediction

__all__ = []

# Mean-field iterations of the one-step prediction that weights particles.
PREDICTION_STEPS = 10


def _ancestors(stack, frames, observed, n_particles, rng):
    """Resample each group of particles by how well they explain the observed data.

    A particle's weight is the likelihood of the frame's observed channels
    under its own one-step prediction from ``stack``, its frame RBMs
    (:func:`~sklearn_crbm._engines._gibbs.observed_log_likelihood`); each group is
    resampled (systematic resampling).  Returns the ancestors, of shape
    ``(n_chains, n_sequences)``, as :meth:`History.reorder` takes them.
    """
    ops = stack[0].ops
    n_sequences, n_features = frames.shape
    n_chains = stack[0].n_frames // n_sequences
    n_groups = n_chains // n_particles
    prediction = stacked_prediction(stack, PREDICTION_STEPS)
    log_weights = observed_log_likelihood(
        stack[0],
        prediction,
        ops.reshape(
            ops.broadcast_to(frames, (n_chains, *frames.shape)), (-1, n_features)
        ),
        ops.reshape(
            ops.broadcast_to(observed, (n_chains, *observed.shape)), (-1, n_features)
        ),
    )
    log_weights = ops.reshape(log_weights, (n_groups, n_particles, n_sequences))
    log_weights = log_weights - ops.max(log_weights, axis=1, keepdims=True)
    cumulative = ops.cumsum(ops.exp(log_weights), axis=1)
    cumulative = cumulative / cumulative[:, -1:, ...]
    positions = (
        rng.random((n_groups, 1, n_sequences))
        + ops.arange(n_particles, dtype=ops.float64)[:, None]
    ) / n_particles
    # ancestor of particle i: how many cumulative weights lie below position i
    below = cumulative[:, None, :, :] < positions[:, :, None, :]
    ancestors = ops.sum(ops.astype(below, ops.int64), axis=2)
    ancestors = ops.minimum(ancestors, n_particles - 1)
    chains = (
        ancestors + (ops.arange(n_groups, dtype=ops.int64) * n_particles)[:, None, None]
    )
    return ops.reshape(chains, (n_chains, n_sequences))


def _take_chains(ops, array, chains):
    """``array[chains[i, s], s]`` for every chain ``i`` and sequence ``s``."""
    n_chains, n_sequences = chains.shape
    flat = ops.reshape(array, (n_chains * n_sequences, -1))
    index = chains * n_sequences + ops.arange(n_sequences, dtype=ops.int64)
    return ops.reshape(ops.take(flat, ops.reshape(index, (-1,)), axis=0), array.shape)
