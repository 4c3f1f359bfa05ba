"""Splitting work on many sequences into blocks that run in parallel."""

import numpy as np
from sklearn.utils.parallel import Parallel, delayed

__all__ = ["BLOCK_SEQUENCES", "map_sequence_blocks"]

# Sequences handled together, vectorised, by one job of on-line fill-in.
BLOCK_SEQUENCES = 32
# Sequences generated together in one vectorised pass by ``sample``: one
# frame of 100 sequences costs little more than one of 1, so blocks are large.
SAMPLE_BLOCK = 256


def map_sequence_blocks(
    work, n_sequences, rng, n_jobs=None, block_size=BLOCK_SEQUENCES
):
    """Run ``work(block, rng)`` on blocks of sequence indices, maybe in parallel.

    Up to ``block_size`` sequences form a single block, run with ``rng``
    itself.  More are split into near-equal blocks of consecutive sequences,
    each run with its own generator seeded from ``rng``.  The blocks and their
    seeds depend on ``n_sequences`` only, so ``n_jobs`` never changes results.

    Parameters
    ----------
    work : callable
        ``work(block, rng)`` with ``block`` an array of sequence indices.
    n_sequences : int
    rng : numpy.random.Generator
    n_jobs : int, default=None
        Passed to :class:`sklearn.utils.parallel.Parallel`.
    block_size : int, default=BLOCK_SEQUENCES
        Most sequences in one block.  Larger blocks vectorise better; smaller
        ones give more parallel jobs.

    Returns
    -------
    results : list
        ``work``'s results, block by block in order.
    """
    n_blocks = -(-n_sequences // block_size)
    if n_blocks <= 1:
        return [work(np.arange(n_sequences), rng)]
    seeds = rng.integers(np.iinfo(np.int64).max, size=n_blocks)
    blocks = np.array_split(np.arange(n_sequences), n_blocks)
    return Parallel(n_jobs=n_jobs)(
        delayed(work)(block, np.random.default_rng(seed))
        for block, seed in zip(blocks, seeds, strict=True)
    )
