"""The array API path: the math on any namespace, numpy's own calls on numpy.

The math modules are written once, against an *ops* object with numpy's
names and numpy's ``out=`` convention (the result is written into ``out``
and returned).  For numpy arrays :func:`array_ops` returns the numpy module
itself, so the numpy path runs exactly the calls it always ran (the same
results, the same random streams, no overhead).  For any other namespace
(PyTorch, CuPy, array-api-strict; with
``sklearn.set_config(array_api_dispatch=True)``) it returns :class:`ArrayOps`,
which computes with the namespace's array API functions on the arrays'
device and honours ``out`` by assigning into it (so views of a packed
buffer are updated in place).  Callers always use the returned value.

Random numbers follow the same split: the math draws from a
:class:`numpy.random.Generator` on the numpy path, and from an
:class:`ArrayRandom` (a ``torch.Generator`` on the tensors' device for
PyTorch; numpy draws moved to the device for other namespaces) otherwise.
"""

import functools
from numbers import Real

import numpy as np
from sklearn.externals import array_api_compat
from sklearn.utils._array_api import _convert_to_numpy

__all__ = [
    "ArrayOps",
    "ArrayRandom",
    "array_ops",
    "array_random",
    "copy_array",
    "is_numpy",
    "same_memory",
    "to_device_batches",
    "to_numpy",
]


def is_numpy(array):
    return isinstance(array, np.ndarray)


def array_ops(array):
    """numpy itself for a numpy array, else the :class:`ArrayOps` of its namespace."""
    if isinstance(array, (np.ndarray, np.generic)):
        return np
    xp = array_api_compat.array_namespace(array)
    return _ops(xp, array_api_compat.device(array))


@functools.lru_cache(maxsize=16)
def _ops(xp, device):
    return ArrayOps(xp, device)


class ArrayOps:
    """numpy's names and ``out=`` convention over an array API namespace and device.

    Only what the package's math uses.  ``out`` is filled by assignment
    (``out[...] = result``), cast to its dtype; the result is ``out``.
    """

    def __init__(self, xp, device):
        self.xp = xp
        self.device = device
        for name in (
            "float32",
            "float64",
            "bool",
            "int64",
            "isfinite",
            "all",
            "any",
            "argmin",
            "min",
            "max",
            "reshape",
            "permute_dims",
            "sqrt",
        ):
            setattr(self, name, getattr(xp, name))
        for name in ("exp", "log", "log1p", "tanh", "abs", "square"):
            setattr(self, name, self._unary(getattr(xp, name)))

    def __reduce__(self):  # rebuilt from the namespace's name and the device
        return (_ops_named, (self.xp.__name__, self.device))

    @staticmethod
    def _into(out, value):
        if out is None:
            return value
        out[...] = value
        return out

    def _unary(self, function):
        def apply(x, out=None):
            return self._into(out, function(x))

        return apply

    # creation
    def asarray(self, x, dtype=None):
        if isinstance(x, np.ndarray) and x.dtype == np.intp:
            x = x.astype(np.int64)
        return self.xp.asarray(x, dtype=dtype, device=self.device)

    def empty(self, shape, dtype=None):
        return self.xp.empty(shape, dtype=dtype, device=self.device)

    def zeros(self, shape, dtype=None):
        return self.xp.zeros(shape, dtype=dtype, device=self.device)

    def ones(self, shape, dtype=None):
        return self.xp.ones(shape, dtype=dtype, device=self.device)

    def eye(self, n, dtype=None):
        return self.xp.eye(n, dtype=dtype, device=self.device)

    def full(self, shape, value, dtype=None):
        return self.xp.full(shape, value, dtype=dtype, device=self.device)

    def arange(self, *args, dtype=None):
        return self.xp.arange(*args, dtype=dtype, device=self.device)

    def empty_like(self, x, dtype=None):
        return self.xp.empty_like(x, dtype=dtype)

    def zeros_like(self, x, dtype=None):
        return self.xp.zeros_like(x, dtype=dtype)

    def ones_like(self, x, dtype=None):
        return self.xp.ones_like(x, dtype=dtype)

    def astype(self, x, dtype, copy=True):
        return self.xp.astype(x, dtype, copy=copy)

    def ascontiguousarray(self, x, dtype=None):
        return x if dtype is None else self.xp.astype(x, dtype, copy=False)

    def concatenate(self, arrays, axis=0):
        return self.xp.concat(tuple(arrays), axis=axis)

    def stack(self, arrays, axis=0):
        return self.xp.stack(tuple(arrays), axis=axis)

    def repeat(self, x, repeats, axis=None):
        return self.xp.repeat(x, repeats, axis=axis)

    def broadcast_to(self, x, shape):
        return self.xp.broadcast_to(x, shape)

    # indexing
    def take(self, x, indices, axis=0, out=None, mode=None):
        if not array_api_compat.is_array_api_obj(indices) or is_numpy(indices):
            indices = self.asarray(np.asarray(indices, dtype=np.int64))
        return self._into(out, self.xp.take(x, indices, axis=axis))

    def copyto(self, dst, src, where=None):
        dst[...] = src if where is None else self.xp.where(where, src, dst)

    def where(self, condition, x, y):
        return self.xp.where(condition, x, y)

    # arithmetic: operators, so that Python scalars mix with arrays
    def add(self, a, b, out=None):
        return self._into(out, a + b)

    def subtract(self, a, b, out=None):
        return self._into(out, a - b)

    def multiply(self, a, b, out=None, dtype=None):
        result = a * b
        if dtype is not None:
            result = self.xp.astype(result, dtype, copy=False)
        return self._into(out, result)

    def divide(self, a, b, out=None):
        return self._into(out, a / b)

    def negative(self, x, out=None):
        return self._into(out, -x)

    def less(self, a, b, out=None):
        result = a < b
        if out is not None:
            result = self.xp.astype(result, out.dtype)
        return self._into(out, result)

    def maximum(self, a, b, out=None):
        if isinstance(b, Real):
            return self._into(out, self.xp.clip(a, min=b))
        return self._into(out, self.xp.maximum(a, b))

    def minimum(self, a, b, out=None):
        if isinstance(b, Real):
            return self._into(out, self.xp.clip(a, max=b))
        return self._into(out, self.xp.minimum(a, b))

    def clip(self, x, low, high):
        return self.xp.clip(x, min=low, max=high)

    def logaddexp(self, a, b, out=None):
        if isinstance(a, Real):
            a = self.xp.full_like(b, a)
        return self._into(out, self.xp.logaddexp(a, b))

    def matmul(self, a, b, out=None):
        return self._into(out, self.xp.matmul(a, b))

    dot = matmul

    # reductions
    def sum(self, x, axis=None, dtype=None):
        return self.xp.sum(x, axis=axis, dtype=dtype)

    def cumsum(self, x, axis=None):
        return self.xp.cumulative_sum(x, axis=axis)

    def mean(self, x, axis=None):
        return self.xp.mean(x, axis=axis)

    def std(self, x, axis=None, ddof=0):
        return self.xp.std(x, axis=axis, correction=ddof)

    # numpy.einsum for the contractions the math uses: "ij,ij->i" (row-wise
    # dot products) and "ij,ij->" (sum of products)
    _EINSUM_AXES = {"ij,ij->i": 1, "ij,ij->": None}

    def einsum(self, subscripts, a, b, dtype=None):
        """``numpy.einsum`` for ``"ij,ij->i"`` and ``"ij,ij->"``."""
        if subscripts not in self._EINSUM_AXES:
            raise ValueError(
                f"ArrayOps.einsum computes {sorted(self._EINSUM_AXES)} only, "
                f"not {subscripts!r}."
            )
        if dtype is not None:
            a, b = self.xp.astype(a, dtype), self.xp.astype(b, dtype)
        return self.xp.sum(a * b, axis=self._EINSUM_AXES[subscripts])

    def finfo(self, dtype):
        return self.xp.finfo(dtype)


def _ops_named(name, device):
    import importlib

    module = importlib.import_module(name)
    return _ops(array_api_compat.array_namespace(module.zeros(0)), device)


class ArrayRandom:
    """Random draws in an array API namespace, on a device.

    PyTorch: a ``torch.Generator`` on the tensors' device, so the draws never
    leave it.  Other namespaces have no generator in the standard: numpy
    draws, moved to the device.  Seeded from an int; numpy's
    :class:`~numpy.random.Generator` methods that the math calls.
    """

    def __init__(self, seed, ops):
        self.ops = ops
        self._torch = None
        if array_api_compat.is_torch_namespace(ops.xp):
            import torch

            self._torch = torch.Generator(device=ops.device)
            self._torch.manual_seed(int(seed))
        else:
            self._numpy = np.random.default_rng(seed)

    def _numpy_dtype(self, dtype):
        return np.float32 if dtype == self.ops.float32 else np.float64

    def random(self, shape, dtype=None, out=None):
        return self._draw("rand", "random", shape, dtype, out)

    def standard_normal(self, shape, dtype=None, out=None):
        return self._draw("randn", "standard_normal", shape, dtype, out)

    def _draw(self, torch_name, numpy_name, shape, dtype, out):
        dtype = self.ops.float64 if dtype is None else dtype
        if self._torch is not None:
            import torch

            draws = getattr(torch, torch_name)(
                shape, generator=self._torch, dtype=dtype, device=self.ops.device
            )
        else:
            numpy_draw = getattr(self._numpy, numpy_name)
            draws = self.ops.asarray(numpy_draw(shape, dtype=self._numpy_dtype(dtype)))
        return self.ops._into(out, draws)


def array_random(rng, like):
    """The generator the math draws from for arrays like ``like``.

    ``rng`` itself (a numpy Generator) for numpy arrays, so the numpy path's
    random stream is unchanged; otherwise an :class:`ArrayRandom` seeded by
    one draw from ``rng``.
    """
    if is_numpy(like) or isinstance(rng, ArrayRandom):
        return rng
    return ArrayRandom(int(rng.integers(2**63 - 1)), array_ops(like))


def to_numpy(array):
    """``array`` as a numpy array (itself for numpy, a copy off the host)."""
    if isinstance(array, np.ndarray):
        return array
    return np.asarray(_convert_to_numpy(array, array_api_compat.array_namespace(array)))


def copy_array(x):
    """A C-ordered copy of ``x``, in its namespace and on its device."""
    if isinstance(x, np.ndarray):
        return x.copy()
    return array_ops(x).xp.asarray(x, copy=True)


def same_memory(a, b):
    """Whether arrays ``a`` and ``b`` start at the same address (False if unknown)."""
    if isinstance(a, np.ndarray) and isinstance(b, np.ndarray):
        return a.__array_interface__["data"][0] == b.__array_interface__["data"][0]
    if hasattr(a, "data_ptr") and hasattr(b, "data_ptr"):
        return a.data_ptr() == b.data_ptr()
    return False


def to_device_batches(batches, ops):
    """Index arrays ``batches`` on the device of ``ops``, moved in one copy."""
    lengths = [len(batch) for batch in batches]
    flat = ops.asarray(np.concatenate(batches).astype(np.int64, copy=False))
    stops = np.cumsum(lengths)
    return [
        flat[stop - length : stop] for stop, length in zip(stops, lengths, strict=True)
    ]
