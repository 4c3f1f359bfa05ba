"""Rotations: Euler angles, rotation matrices and exponential maps.

Everything here is vectorised over leading dimensions, uses the column-vector
convention (a rotation matrix ``R`` maps a vector ``v`` to ``R @ v``) and
works in radians.

Euler angles are given together with a string of axes, one of ``"x"``,
``"y"``, ``"z"`` per angle.  The rotation of the *first* angle is applied to
a vector first::

    R = R_{axes[-1]}(angles[..., -1]) @ ... @ R_{axes[0]}(angles[..., 0])

so the ASF ``dof rx ry rz`` of a CMU bone is ``axes="xyz"`` and a BVH
``Zrotation Xrotation Yrotation`` channel list is ``axes="yxz"``.

The exponential map of a rotation by the angle ``theta`` about the unit axis
``n`` is the 3-vector ``theta * n`` (Grassia 1998).
"""

import numpy as np

__all__ = [
    "axis_angle_to_matrix",
    "euler_to_matrix",
    "expmap_to_matrix",
    "matrix_to_euler",
    "matrix_to_expmap",
    "mean_rotation",
    "unwrap_expmap",
]

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}

# Below this value of cos(middle angle) a three-axis decomposition is taken to
# be in gimbal lock and its last angle is set to zero.
_GIMBAL_TOL = 4 * np.finfo(np.float64).eps
# Below this value of sin(theta) * (n . axis) a rotation by theta ~ pi is
# taken to be exactly pi, where n and -n are the same rotation.
_PI_TIE_TOL = 1e-12
# Components of a unit rotation axis smaller than this are rounding noise.
_AXIS_ZERO_TOL = 1e-9


def _check_axes(axes, k=None):
    if not isinstance(axes, str):
        raise TypeError(f"axes must be a string such as 'xyz', got {axes!r}.")
    axes = axes.lower()
    if not 1 <= len(axes) <= 3 or any(a not in _AXIS_INDEX for a in axes):
        raise ValueError(
            f"axes must be 1 to 3 letters from 'x', 'y', 'z', got {axes!r}."
        )
    if len(set(axes)) != len(axes):
        raise ValueError(
            f"axes must not repeat an axis, got {axes!r}; only Tait-Bryan orders "
            "(as used by ASF and BVH files) are supported."
        )
    if k is not None and k != len(axes):
        raise ValueError(
            f"angles have {k} columns but axes {axes!r} name {len(axes)} axes."
        )
    return [_AXIS_INDEX[a] for a in axes]


def _single_axis_matrix(angle, axis):
    """Rotation matrices about one coordinate axis, shape ``angle.shape + (3, 3)``."""
    c = np.cos(angle)
    s = np.sin(angle)
    R = np.zeros(np.shape(angle) + (3, 3), dtype=np.result_type(angle, np.float64))
    u = (axis + 1) % 3
    w = (axis + 2) % 3
    R[..., axis, axis] = 1.0
    R[..., u, u] = c
    R[..., w, w] = c
    R[..., w, u] = s
    R[..., u, w] = -s
    return R


def _angle_about(R, axis):
    """Angle of the rotation about ``axis`` closest to ``R`` (least squares)."""
    u = (axis + 1) % 3
    w = (axis + 2) % 3
    return np.arctan2(R[..., w, u] - R[..., u, w], R[..., u, u] + R[..., w, w])


def euler_to_matrix(angles, axes):
    """Rotation matrices from Euler angles.

    Parameters
    ----------
    angles : array-like of shape (..., k)
        Angles in radians, one column per letter of ``axes``.
    axes : str
        ``k`` distinct letters from ``"x"``, ``"y"``, ``"z"`` (``k`` = 1, 2
        or 3): the axis of each column.  The rotation of the first column is
        applied to a vector first.

    Returns
    -------
    R : ndarray of shape (..., 3, 3)
        ``R_{axes[-1]}(angles[..., -1]) @ ... @ R_{axes[0]}(angles[..., 0])``.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._rotations import euler_to_matrix
    >>> R = euler_to_matrix([np.pi / 2, 0.0, 0.0], "xyz")
    >>> np.round(R @ [0.0, 1.0, 0.0], 12) + 0.0
    array([0., 0., 1.])
    """
    angles = np.asarray(angles, dtype=np.float64)
    idx = _check_axes(axes, angles.shape[-1] if angles.ndim else None)
    if angles.ndim == 0:
        raise ValueError("angles must have at least one dimension (..., k).")
    R = _single_axis_matrix(angles[..., 0], idx[0])
    for j in range(1, len(idx)):
        R = _single_axis_matrix(angles[..., j], idx[j]) @ R
    return R


def matrix_to_euler(R, axes):
    """Euler angles of rotation matrices; the inverse of :func:`euler_to_matrix`.

    Parameters
    ----------
    R : array-like of shape (..., 3, 3)
        Rotation matrices.
    axes : str
        One to three distinct letters from ``"x"``, ``"y"``, ``"z"``, with the
        meaning of :func:`euler_to_matrix`.

    Returns
    -------
    angles : ndarray of shape (..., k)
        Angles in radians in ``(-pi, pi]``.

    Notes
    -----
    Three axes: the middle angle lies in ``[-pi/2, pi/2]``; in gimbal lock
    (middle angle ``+-pi/2``) the last angle is set to 0 and the first takes
    the whole remaining rotation.  The first angle is always computed from
    what the last two leave, so ``euler_to_matrix(matrix_to_euler(R))``
    reproduces ``R`` to rounding error everywhere, near gimbal lock included.

    Two axes ``"ab"``: this is the three-axis decomposition whose absent angle
    (about the third axis) is *zero*, so the second angle covers the full
    circle ``(-pi, pi]``.  (A three-axis decomposition would move such a
    rotation to the equivalent triple with the absent angle at pi once the
    second angle passes +-pi/2.)  For a matrix that is not exactly of the
    form ``R_b(beta) R_a(alpha)`` the result is a projection.

    One axis: the angle of the rotation about that axis closest to ``R``.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._rotations import euler_to_matrix, matrix_to_euler
    >>> angles = np.deg2rad([30.0, 120.0])
    >>> np.rad2deg(matrix_to_euler(euler_to_matrix(angles, "xz"), "xz"))
    array([ 30., 120.])
    """
    R = np.asarray(R, dtype=np.float64)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"R must have shape (..., 3, 3), got {R.shape}.")
    idx = _check_axes(axes)
    if len(idx) == 1:
        return _angle_about(R, idx[0])[..., None]
    if len(idx) == 2:
        a, b = idx
        c = 3 - a - b
        # R e_a = R_b(beta) e_a = cos(beta) e_a + sin(beta) (e_b x e_a)
        sign = np.cross(np.eye(3)[b], np.eye(3)[a])[c]
        beta = np.arctan2(sign * R[..., c, a], R[..., a, a])
        M = np.swapaxes(_single_axis_matrix(beta, b), -1, -2) @ R
        alpha = _angle_about(M, a)
        return np.stack([alpha, beta], axis=-1)
    a, b, c = idx
    eye = np.eye(3)
    sigma = np.cross(eye[b], eye[a])[c]  # e_b x e_a = sigma e_c
    tau = np.cross(eye[c], eye[a])[b]  # e_c x e_a = tau e_b
    # R e_a = cos(beta) R_c(gamma) e_a + sin(beta) sigma e_c
    cos_beta = np.hypot(R[..., a, a], R[..., b, a])
    beta = np.arctan2(sigma * R[..., c, a], cos_beta)
    gamma = np.where(
        cos_beta > _GIMBAL_TOL, np.arctan2(tau * R[..., b, a], R[..., a, a]), 0.0
    )
    Rt = lambda angle, axis: np.swapaxes(_single_axis_matrix(angle, axis), -1, -2)  # noqa: E731
    M = Rt(beta, b) @ (Rt(gamma, c) @ R)
    alpha = _angle_about(M, a)
    return np.stack([alpha, beta, gamma], axis=-1)


def _skew(r):
    K = np.zeros(r.shape[:-1] + (3, 3), dtype=r.dtype)
    K[..., 0, 1] = -r[..., 2]
    K[..., 0, 2] = r[..., 1]
    K[..., 1, 0] = r[..., 2]
    K[..., 1, 2] = -r[..., 0]
    K[..., 2, 0] = -r[..., 1]
    K[..., 2, 1] = r[..., 0]
    return K


def expmap_to_matrix(r):
    """Rotation matrices from exponential maps (Rodrigues' formula).

    Parameters
    ----------
    r : array-like of shape (..., 3)
        Exponential maps ``theta * n`` (any ``theta``, not only ``<= pi``).

    Returns
    -------
    R : ndarray of shape (..., 3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._rotations import expmap_to_matrix
    >>> np.round(expmap_to_matrix([0.0, 0.0, np.pi / 2]), 12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    r = np.asarray(r, dtype=np.float64)
    if r.ndim == 0 or r.shape[-1] != 3:
        raise ValueError(f"r must have shape (..., 3), got {r.shape}.")
    theta2 = np.sum(r * r, axis=-1)
    theta = np.sqrt(theta2)
    small = theta < 1e-4
    safe = np.where(small, 1.0, theta)
    # sin(t)/t and (1 - cos(t))/t^2, by their Taylor series near 0
    A = np.where(small, 1.0 - theta2 / 6.0 + theta2**2 / 120.0, np.sin(safe) / safe)
    B = np.where(
        small,
        0.5 - theta2 / 24.0 + theta2**2 / 720.0,
        2.0 * np.sin(safe / 2.0) ** 2 / safe**2,
    )
    K = _skew(r)
    return np.eye(3) + A[..., None, None] * K + B[..., None, None] * (K @ K)


def axis_angle_to_matrix(axis, angle):
    """Rotation matrices about unit axes by the given angles (radians)."""
    axis = np.asarray(axis, dtype=np.float64)
    angle = np.asarray(angle, dtype=np.float64)
    return expmap_to_matrix(axis * angle[..., None])


def matrix_to_expmap(R):
    """Exponential maps of rotation matrices, with rotation angle in ``[0, pi]``.

    Parameters
    ----------
    R : array-like of shape (..., 3, 3)
        Rotation matrices.

    Returns
    -------
    r : ndarray of shape (..., 3)
        ``theta * n`` with ``0 <= theta <= pi``.  At exactly ``theta = pi``,
        where ``n`` and ``-n`` give the same rotation, the sign is chosen so
        that the first non-zero component of ``n`` is positive (so +180 and
        -180 degrees about an axis give the same map).

    Notes
    -----
    The angle comes from ``atan2(sin, cos)``, accurate at every angle.  The
    axis comes from the antisymmetric part of ``R`` for ``theta <= pi/2``
    (with the series of ``theta / sin(theta)`` near 0) and from the symmetric
    part for ``theta > pi/2``, so the result is accurate near 0 and near pi.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._rotations import expmap_to_matrix, matrix_to_expmap
    >>> r = np.array([0.1, -0.2, 0.3])
    >>> np.allclose(matrix_to_expmap(expmap_to_matrix(r)), r)
    True
    """
    R = np.asarray(R, dtype=np.float64)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"R must have shape (..., 3, 3), got {R.shape}.")
    w = 0.5 * np.stack(
        [
            R[..., 2, 1] - R[..., 1, 2],
            R[..., 0, 2] - R[..., 2, 0],
            R[..., 1, 0] - R[..., 0, 1],
        ],
        axis=-1,
    )
    sin_t = np.linalg.norm(w, axis=-1)
    cos_t = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    theta = np.arctan2(sin_t, cos_t)

    # theta <= pi/2: r = w * theta / sin(theta)
    small = sin_t < 1e-6
    theta2 = theta * theta
    factor = np.where(
        small,
        1.0 + theta2 / 6.0 + 7.0 * theta2**2 / 360.0,
        theta / np.where(small, 1.0, sin_t),
    )
    r_small = w * factor[..., None]

    # theta > pi/2: (R + R^T)/2 - cos(theta) I = (1 - cos(theta)) n n^T
    S = 0.5 * (R + np.swapaxes(R, -1, -2)) - cos_t[..., None, None] * np.eye(3)
    diag = np.diagonal(S, axis1=-2, axis2=-1)
    pivot = np.argmax(diag, axis=-1)
    column = np.take_along_axis(S, pivot[..., None, None], axis=-1)[..., 0]
    pivot_value = np.take_along_axis(diag, pivot[..., None], axis=-1)[..., 0]
    n = column / np.sqrt(np.maximum(pivot_value, np.finfo(np.float64).tiny))[..., None]
    norm = np.linalg.norm(n, axis=-1, keepdims=True)
    n = n / np.where(norm > 0, norm, 1.0)
    along = np.sum(n * w, axis=-1)
    # At theta = pi, w is rounding noise whose sign follows that of the input
    # (sin(+-pi) = +-1.2e-16), and so is the pivot when two components of n
    # are equally large: use the tie-break of the docstring there, so that
    # +180 and -180 degrees give the same map.
    first = np.argmax(np.abs(n) > _AXIS_ZERO_TOL, axis=-1)
    negative_first = np.take_along_axis(n, first[..., None], axis=-1)[..., 0] < 0
    flip = np.where(np.abs(along) > _PI_TIE_TOL, along < 0, negative_first)
    n = np.where(flip[..., None], -n, n)
    r_large = n * theta[..., None]

    return np.where((cos_t < 0)[..., None], r_large, r_small)


def unwrap_expmap(r):
    """Make a sequence of exponential maps continuous in time.

    The exponential map with angle in ``[0, pi]`` jumps where a rotation
    passes through pi: the angle falls back from near pi and the axis flips.
    The same rotation is also ``r + 2 pi k n`` for every integer ``k``
    (``n = r / |r|``).  Frame by frame, this picks the ``k`` that brings each
    map closest to the one chosen for the frame before.

    Parameters
    ----------
    r : array-like of shape (n_frames, ..., 3)
        Exponential maps of one sequence, time along the first axis.

    Returns
    -------
    r_unwrapped : ndarray of the same shape
        Maps of the same rotations; the first frame is left as it is.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._rotations import unwrap_expmap
    >>> r = np.array([[0.0, 0.0, 3.1], [0.0, 0.0, -3.1]])  # 3.1 rad, then 2*pi - 3.1
    >>> unwrap_expmap(r).round(4) + 0.0
    array([[0.    , 0.    , 3.1   ],
           [0.    , 0.    , 3.1832]])
    """
    r = np.array(r, dtype=np.float64)
    if r.ndim < 2 or r.shape[-1] != 3:
        raise ValueError(f"r must have shape (n_frames, ..., 3), got {r.shape}.")
    two_pi = 2.0 * np.pi
    theta = np.linalg.norm(r, axis=-1)
    n = r / np.where(theta > 0, theta, 1.0)[..., None]
    for t in range(1, r.shape[0]):
        moving = theta[t] > 0
        along = np.sum(r[t - 1] * n[t], axis=-1)
        k = np.round((along - theta[t]) / two_pi)
        k = np.where(moving, k, 0.0)
        r[t] = (theta[t] + two_pi * k)[..., None] * n[t]
    return r


def mean_rotation(R):
    """The rotation closest to the mean of rotation matrices (chordal L2 mean).

    Parameters
    ----------
    R : array-like of shape (n, 3, 3)
        Rotation matrices; those with a NaN are ignored.

    Returns
    -------
    mean : ndarray of shape (3, 3)
        The rotation ``Q`` that minimises ``sum ||Q - R_i||_F^2``: the
        arithmetic mean of the matrices projected onto the rotations by an
        SVD.  The identity when no matrix is finite.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils._rotations import euler_to_matrix, mean_rotation
    >>> R = euler_to_matrix(np.deg2rad([[170.0], [-170.0]]), "x")
    >>> mean_rotation(R).round(12) + 0.0  # 180 degrees about x
    array([[ 1.,  0.,  0.],
           [ 0., -1.,  0.],
           [ 0.,  0., -1.]])
    """
    R = np.asarray(R, dtype=np.float64)
    if R.ndim != 3 or R.shape[1:] != (3, 3):
        raise ValueError(f"R must have shape (n, 3, 3), got {R.shape}.")
    R = R[np.all(np.isfinite(R), axis=(1, 2))]
    if len(R) == 0:
        return np.eye(3)
    U, _, Vt = np.linalg.svd(R.mean(axis=0))
    D = np.diag([1.0, 1.0, np.linalg.det(U @ Vt)])
    return U @ D @ Vt
