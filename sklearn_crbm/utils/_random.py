"""Random draws: generators from ``random_state``, and the fast draws of the math.

The estimators take ``random_state`` as scikit-learn does but draw from a
:class:`numpy.random.Generator` (:func:`rng_from`).  The draws of Gibbs
sampling and training (uniforms, normals, noise on histories, Bernoulli
states) are written here once; on another array API namespace the generator
is an :class:`~sklearn_crbm.utils._array_api.ArrayRandom` and each function
falls back to its plain ``random``/``standard_normal``.
"""

import math

import numpy as np
from sklearn.utils import check_random_state

from ._array_api import array_ops

__all__ = [
    "add_history_noise",
    "add_normal_noise",
    "rng_from",
    "sample_bernoulli",
    "standard_normal",
    "uniform",
]


def rng_from(random_state):
    """A numpy Generator seeded from a scikit-learn ``random_state``.

    The estimators take ``random_state`` as scikit-learn does (None, an int
    or a ``RandomState``) but draw from a :class:`numpy.random.Generator`
    (fast float32 draws): one int drawn from ``random_state`` seeds it, so a
    ``RandomState`` instance advances by one draw.

    Examples
    --------
    >>> from sklearn_crbm.utils._random import rng_from
    >>> float(rng_from(0).random()) == float(rng_from(0).random())
    True
    """
    seed = check_random_state(random_state).randint(np.iinfo(np.int32).max)
    return np.random.default_rng(seed)


# float32 exponents of 1.0 and 2.0: OR-ed onto 23 random mantissa bits they
# give floats uniform on [1, 2) and [2, 4) without integer-to-float conversion
_FLOAT32_ONE_BITS = np.uint32(0x3F800000)
_FLOAT32_TWO_BITS = np.uint32(0x40000000)
_MIN_BIT_DRAWS = 4096


def _mantissa_floats(rng, size, exponent_bits):
    """``size`` float32 values in [1, 2) (or [2, 4)) from 23 random bits each.

    Two per 64-bit output of ``rng``'s bit generator, as the mantissa under
    ``exponent_bits`` (:data:`_FLOAT32_ONE_BITS` or :data:`_FLOAT32_TWO_BITS`).
    """
    bits = rng.bit_generator.random_raw((size + 1) // 2).view(np.uint32)[:size]
    np.right_shift(bits, 9, out=bits)
    np.bitwise_or(bits, exponent_bits, out=bits)
    return bits.view(np.float32)


def uniform(rng, shape, dtype, out=None, *, symmetric=False):
    """Uniform draws on [0, 1), or on [-1, 1) if ``symmetric``, in ``dtype``.

    float64 draws come from ``rng.random`` (53 random bits).  float32 draws
    take 23 random bits each, two per 64-bit output of the bit generator,
    as the mantissa of a float in [1, 2) (or [2, 4) if ``symmetric``) from
    which 1 (or 3) is subtracted: no integer-to-float conversion, about
    two thirds of the time of ``rng.random(dtype=np.float32)``, which
    matters in Gibbs sampling where these draws are a large part of every
    step.  Fewer than ``_MIN_BIT_DRAWS`` float32 draws (one sequence, where
    the extra numpy calls cost more than they save) come from
    ``rng.random`` too.  All are reproducible from ``rng``'s state.  Another
    namespace's generator (:class:`~sklearn_crbm.utils._array_api.ArrayRandom`)
    draws with its own ``random``.
    """
    if not isinstance(rng, np.random.Generator):
        draws = rng.random(shape, dtype=dtype, out=out)
        if symmetric:
            draws *= 2
            draws -= 1
        return draws
    dtype = np.dtype(dtype)
    size = math.prod(shape)
    if dtype != np.float32 or size < _MIN_BIT_DRAWS:
        draws = rng.random(shape, dtype=dtype, out=out)
        if symmetric:
            draws *= 2
            draws -= 1
        return draws
    floats = _mantissa_floats(
        rng, size, _FLOAT32_TWO_BITS if symmetric else _FLOAT32_ONE_BITS
    ).reshape(shape)
    return np.subtract(floats, 3 if symmetric else 1, out=out)


def standard_normal(rng, shape, dtype, out=None):
    """Standard normal draws in ``dtype``.

    Fewer than ``_MIN_BIT_DRAWS`` draws (and any other namespace's) are
    ``rng.standard_normal``'s.  Larger arrays, float32 or float64, come
    from the Box-Muller transform, in float32, of 23-bit uniforms ``u, u'``
    (:func:`uniform`'s), ``sqrt(-2 log(1 - u)) * (cos, sin)(2 pi u')``: a
    pair of normals per 64 random bits in a few vectorised passes, about
    five times faster than numpy's ziggurat (which draws one at a time, in
    either dtype), and the history noise of every training minibatch is
    that many draws.  float64 draws are these float32 values, converted:
    plenty for noise.  The tails stop at ``sqrt(46 log 2) =
    5.65`` standard deviations (probability 2e-8 beyond).
    """
    size = math.prod(shape)
    if not isinstance(rng, np.random.Generator) or size < _MIN_BIT_DRAWS:
        return rng.standard_normal(shape, dtype=dtype, out=out)
    half = (size + 1) // 2
    radius, angle = _mantissa_floats(rng, 2 * half, _FLOAT32_ONE_BITS).reshape(2, half)
    np.subtract(2, radius, out=radius)  # 1 - u in (0, 1]: log(0) never taken
    np.log(radius, out=radius)
    radius *= -2
    np.sqrt(radius, out=radius)
    angle -= 1
    angle *= np.float32(2 * np.pi)
    draws = out
    if out is None or out.dtype != np.float32 or not out.flags.c_contiguous:
        draws = np.empty(shape, np.float32)
    # cosines, then sines, each times its radius
    flat = draws.reshape(-1)
    np.cos(angle, out=flat[:half])
    flat[:half] *= radius
    np.sin(angle[: size - half], out=flat[half:])
    flat[half:] *= radius[: size - half]
    if out is None:
        return draws.astype(dtype, copy=False)
    if draws is not out:
        out[...] = draws
    return out


def add_normal_noise(rng, array, scale, work=None):
    """``array += scale * N(0, 1)``, elementwise and in place; returns ``array``.

    The draws are :func:`standard_normal`'s, in float32 where that routine
    computes them in float32 anyway (at least ``_MIN_BIT_DRAWS`` of them
    from a numpy Generator), else in ``array``'s dtype.  ``work``, scratch
    of ``array``'s shape, receives them if it has that dtype.
    """
    noise = _noise_draws(rng, array, work)
    noise *= scale
    array += noise
    return array


def _noise_draws(rng, array, work):
    """Standard normals of ``array``'s shape, in the dtype add_normal_noise uses."""
    dtype = array.dtype
    if isinstance(rng, np.random.Generator) and math.prod(array.shape) >= (
        _MIN_BIT_DRAWS
    ):
        dtype = np.float32
    if work is not None and work.dtype != dtype:
        work = None
    return standard_normal(rng, array.shape, dtype, work)


def add_history_noise(rng, history, scale, n_features, fraction=1.0, work=None):
    """Noise on a random ``fraction`` of the channels of each frame's history.

    ``history`` (shape ``(n, n_lags * n_features)``, lag blocks of
    ``n_features`` channels) gets ``scale * N(0, 1)`` added in place where
    channel ``i`` of frame ``k`` is drawn to be noised, with probability
    ``fraction``, independently for every frame and channel, and then at
    every lag of that channel; the other channels' past stays clean.  The
    noised channels are drawn first (one uniform per frame and channel),
    then the noise as :func:`add_normal_noise` draws it; ``fraction=1``
    draws no uniforms and is :func:`add_normal_noise` itself.  Returns
    ``history``.
    """
    if fraction >= 1:
        return add_normal_noise(rng, history, scale, work)
    ops = array_ops(history)
    xp = np if ops is np else ops.xp
    n = history.shape[0]
    draws = uniform(rng, (n, n_features), history.dtype)
    noise = _noise_draws(rng, history, work)
    noised = ops.astype(ops.less(draws, fraction), noise.dtype)
    noised *= scale
    blocks = xp.reshape(noise, (n, -1, n_features))
    blocks *= xp.reshape(noised, (n, 1, n_features))
    history += xp.reshape(blocks, history.shape)
    return history


def sample_bernoulli(probabilities, rng, out=None):
    """Binary states with the given probabilities, in their dtype.

    One uniform draw per entry, ``state = uniform < probability``; ``out``
    (not ``probabilities`` itself) receives the uniforms, then the states.
    """
    draws = uniform(rng, probabilities.shape, probabilities.dtype, out=out)
    return array_ops(draws).less(draws, probabilities, out=draws)
