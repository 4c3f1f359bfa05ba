"""Storage of a layer's trainable arrays in one flat buffer, and their updates.

A conditional layer (:mod:`sklearn_crbm.layers`) lists its trainable arrays
as :class:`ParameterGroup` entries; :class:`PackedParameters` lays them out
in one flat buffer and gives each a view.  Weight decay is then one pass
over a prefix of the buffer, a momentum step (:class:`MomentumUpdate`) one
pass over all of it, and an average over epochs (:class:`ParameterAverage`)
one running mean; velocities, statistics and copies are buffers of the same
layout.  The estimators' fitted attributes are views of the same buffer.
"""

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..utils._array_api import array_ops, copy_array

__all__ = [
    "MomentumUpdate",
    "PackedParameters",
    "ParameterAverage",
    "ParameterGroup",
    "small_normal",
]


def small_normal(rng, shape, dtype):
    """``0.01 * N(0, 1)`` draws in ``dtype``: the usual start of RBM weights."""
    return (0.01 * rng.standard_normal(shape)).astype(dtype, copy=False)


@dataclass(frozen=True)
class ParameterGroup:
    """One trainable array of a layer: its shape, start value and penalty.

    Parameters
    ----------
    name : str
        Attribute of the layer that views it.
    shape : callable
        ``shape(layer)`` gives its shape from the layer's sizes.
    initial : callable
        ``initial(layer, rng)`` gives its start value (float64 or the
        layer's dtype); ``rng`` draws in the order of the layer's groups.
    decayed : bool
        Whether weight decay applies to it.
    rate : float, default=1.0
        Its learning rate relative to the estimator's ``learning_rate``.
    """

    name: str
    shape: Callable
    initial: Callable
    decayed: bool
    rate: float = 1.0


class PackedParameters:
    """Every trainable array of a layer, packed in one flat buffer.

    A subclass lists its arrays in ``groups`` (a tuple of
    :class:`ParameterGroup`, in the order their start values are drawn) and
    calls :meth:`_allocate` once its sizes are set.  Each group is then an
    attribute viewing its part of :attr:`flat`; the decayed groups come
    first.

    Attributes
    ----------
    flat : ndarray of shape (n_parameters,)
    layout : {"C", "F"}
        Memory order of the 2-D groups inside ``flat``.  Training works in
        "F", the orientation in which BLAS runs its products fastest;
        fitted models keep "C" (the same numbers, but a matrix-vector
        product rounds differently in the two orders).
    """

    groups: tuple = ()

    def _allocate(self, dtype, *, flat=None, layout="C", ops=np):
        shapes = self._shapes()
        size = sum(math.prod(shape) for shape in shapes)
        self.flat = ops.zeros(size, dtype) if flat is None else flat
        # Fortran order is numpy's alone (the array API reshapes in C order)
        self.layout = layout if isinstance(self.flat, np.ndarray) else "C"
        self._bind(shapes)

    def _shapes(self):
        return [group.shape(self) for group in self.groups]

    def _bind(self, shapes=None):
        for name, view in self.views(self.flat, shapes).items():
            setattr(self, name, view)

    def views(self, flat, shapes=None):
        """``{group name: view}`` of a buffer laid out like :attr:`flat`."""
        shapes = self._shapes() if shapes is None else shapes
        views, offset = {}, 0
        for group, shape in sorted(
            zip(self.groups, shapes, strict=True), key=lambda pair: not pair[0].decayed
        ):
            size = math.prod(shape)
            part = flat[offset : offset + size]
            if isinstance(part, np.ndarray):
                views[group.name] = part.reshape(shape, order=self.layout)
            else:
                views[group.name] = array_ops(part).xp.reshape(part, shape)
            offset += size
        return views

    def initialize(self, rng):
        """Draw every group's start value from ``rng``, in the order of ``groups``."""
        for group in self.groups:
            getattr(self, group.name)[...] = group.initial(self, rng)
        return self

    @property
    def dtype(self):
        return self.flat.dtype

    @property
    def ops(self):
        """The array functions of :attr:`flat`'s namespace (numpy for numpy)."""
        return array_ops(self.flat)

    @property
    def decayed(self):
        """The prefix of :attr:`flat` that weight decay applies to."""
        size = sum(
            math.prod(getattr(self, g.name).shape) for g in self.groups if g.decayed
        )
        return slice(0, size)

    def rates(self):
        """Each entry's relative learning rate (n_parameters,); None if all are 1."""
        if all(group.rate == 1 for group in self.groups):
            return None
        rates = self.zeros_like()
        for group in self.groups:
            getattr(rates, group.name)[...] = group.rate
        return rates.flat

    def copy(self, layout=None, dtype=None):
        """The same values in a new buffer (laid out ``layout``, in ``dtype``)."""
        new = self.zeros_like(layout, dtype)
        for name, view in new.views(new.flat).items():
            view[...] = getattr(self, name)
        return new

    def zeros_like(self, layout=None, dtype=None):
        """Parameters of the same shape, all zero: velocities, gradients."""
        new = copy.copy(self)
        new._allocate(
            self.dtype if dtype is None else dtype,
            layout=self.layout if layout is None else layout,
            ops=self.ops,
        )
        return new

    def astype(self, dtype):
        """These parameters in ``dtype`` (themselves if already so)."""
        return self if self.dtype == dtype else self.copy(layout="C", dtype=dtype)

    def __sklearn_array_api_convert__(self, converter):
        """The same parameters with :attr:`flat` converted (C order).

        What :func:`sklearn.utils._array_api.move_estimator_to` calls.  The
        buffer is a copy: a converter may share memory (DLPack on the CPU),
        and training updates it in place.
        """
        source = self if self.layout == "C" else self.copy(layout="C")
        new = copy.copy(source)
        new.flat = copy_array(converter(source.flat))
        new.layout = "C"
        new._bind()
        return new

    def is_finite(self):
        ops = self.ops
        return bool(ops.all(ops.isfinite(self.flat)))

    def __getstate__(self):
        # the views would be pickled as copies: keep the buffer, view it again
        state = dict(vars(self))
        for group in self.groups:
            state.pop(group.name, None)
        return state

    def __setstate__(self, state):
        vars(self).update(state)
        self._bind()


class MomentumUpdate:
    """Velocities and statistics of one layer, laid out like its parameters.

    After every minibatch training applies (the original code's update)::

        velocity = momentum * velocity + rate * statistic      (all groups)
        velocity -= rate * learning_rate * weight_decay * param (decayed groups)
        param += velocity

    where ``statistic`` is ``learning_rate / n`` times the CD gradient (the
    layer's ``cd_statistics`` writes it into :attr:`statistics`) and
    ``rate`` each group's relative learning rate (:meth:`PackedParameters.
    rates`; 1 for every group of the CRBM).  Each line is one or two passes
    over a whole buffer.

    Parameters
    ----------
    params : PackedParameters
        Updated in place.
    velocity : PackedParameters, default=None
        Laid out like ``params``; zeros if None.
    """

    def __init__(self, params, velocity=None):
        self.params = params
        self.velocity = params.zeros_like() if velocity is None else velocity
        if self.velocity.layout != params.layout:
            self.velocity = self.velocity.copy(params.layout)
        self.statistics = params.zeros_like()
        self._decayed = params.decayed
        self._rates = params.rates()

    def apply(self, momentum, learning_rate, weight_decay):
        """Fold :attr:`statistics` into the velocities and those into the parameters."""
        velocity, statistic = self.velocity.flat, self.statistics.flat
        parameters = self.params.flat
        ops = self.params.ops
        if self._rates is not None:
            statistic *= self._rates
        velocity *= momentum
        velocity += statistic
        if weight_decay:  # the statistics are spent: their buffer is scratch
            decay = ops.multiply(
                parameters[self._decayed],
                learning_rate * weight_decay,
                out=statistic[self._decayed],
            )
            if self._rates is not None:
                decay *= self._rates[self._decayed]
            velocity[self._decayed] -= decay
        parameters += velocity


class ParameterAverage:
    """Running mean of a layer's parameters, one sample per epoch.

    Polyak-Ruppert averaging: with a constant learning rate the CD iterates
    keep wandering around the region they have reached, and their mean is a
    steadier model than any one of them.

    Attributes
    ----------
    mean : PackedParameters or None
        The mean of the parameters added so far (None before the first).
    count : int
        How many were added.
    """

    def __init__(self):
        self.mean = None
        self.count = 0

    def add(self, params):
        """Fold ``params`` (laid out as the first one added) into the mean."""
        self.count += 1
        if self.mean is None:
            self.mean = params.copy()
        else:
            self.mean.flat += (params.flat - self.mean.flat) / self.count
