"""Euler angles, rotation matrices and exponential maps."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sklearn_crbm.utils._rotations import (
    axis_angle_to_matrix,
    euler_to_matrix,
    expmap_to_matrix,
    matrix_to_euler,
    matrix_to_expmap,
    unwrap_expmap,
)

ORDERS_3 = ["".join(p) for p in itertools.permutations("xyz")]
ORDERS_2 = ["".join(p) for p in itertools.permutations("xyz", 2)]
ORDERS_1 = ["x", "y", "z"]
ALL_ORDERS = ORDERS_3 + ORDERS_2 + ORDERS_1
HALF_PI = np.pi / 2

# Angles anywhere on the circle, with extra weight on +-pi, 0 and +-pi/2 and
# on values a hair away from them.
special = st.sampled_from([0.0, np.pi, -np.pi, HALF_PI, -HALF_PI])
nudge = st.sampled_from([0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-8, -1e-8, 1e-4, -1e-4])
angle = st.one_of(
    st.floats(-np.pi, np.pi, allow_nan=False),
    st.builds(lambda a, e: a + e, special, nudge),
)


def _is_rotation(R, atol=1e-12):
    eye = np.broadcast_to(np.eye(3), R.shape)
    return np.allclose(R @ np.swapaxes(R, -1, -2), eye, atol=atol) and np.allclose(
        np.linalg.det(R), 1.0, atol=atol
    )


def _angle_diff(a, b):
    return np.abs((a - b + np.pi) % (2 * np.pi) - np.pi)


@pytest.mark.parametrize("axes", ALL_ORDERS)
def test_euler_to_matrix_matches_scipy_extrinsic(axes):
    # scipy's lower-case (extrinsic) sequences apply the first angle first too
    rng = np.random.default_rng(0)
    angles = rng.uniform(-np.pi, np.pi, size=(50, len(axes)))
    expected = Rotation.from_euler(axes, angles).as_matrix()
    assert np.allclose(euler_to_matrix(angles, axes), expected, atol=1e-14)


def test_euler_to_matrix_applies_first_axis_first():
    R = euler_to_matrix(np.deg2rad([90.0, 90.0]), "xz")
    # x by 90 takes y to z; z by 90 leaves z.  Then x -> x -> y.
    assert np.allclose(R @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
    assert np.allclose(R @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])


@pytest.mark.parametrize("axes", ORDERS_3)
@settings(max_examples=150, deadline=None)
@given(a=angle, b=angle, c=angle)
def test_three_axis_round_trip(axes, a, b, c):
    R = euler_to_matrix([a, b, c], axes)
    back = matrix_to_euler(R, axes)
    assert np.all(np.abs(back) <= np.pi)
    assert abs(back[1]) <= HALF_PI + 1e-15
    assert np.allclose(euler_to_matrix(back, axes), R, rtol=0, atol=4e-15)
    if abs(np.cos(b)) > 1e-6:  # away from gimbal lock the solution is unique
        if abs(b) > HALF_PI:  # ... up to the equivalent triple
            a, b, c = a + np.pi, np.pi - b, c + np.pi
        assert np.all(_angle_diff(back, [a, b, c]) < 1e-9)


@pytest.mark.parametrize("axes", ORDERS_2)
@settings(max_examples=150, deadline=None)
@given(a=angle, b=angle)
def test_two_axis_round_trip_keeps_absent_angle_zero(axes, a, b):
    R = euler_to_matrix([a, b], axes)
    back = matrix_to_euler(R, axes)
    assert np.allclose(euler_to_matrix(back, axes), R, rtol=0, atol=4e-15)
    # Unique over the whole circle, also for |b| > 90 degrees
    assert np.all(_angle_diff(back, [a, b]) < 1e-12)


@pytest.mark.parametrize("axes", ORDERS_1)
@settings(max_examples=100, deadline=None)
@given(a=angle)
def test_one_axis_round_trip(axes, a):
    back = matrix_to_euler(euler_to_matrix([a], axes), axes)
    assert _angle_diff(back[0], a) < 1e-14


@pytest.mark.parametrize("axes", ORDERS_3)
@pytest.mark.parametrize("middle", [HALF_PI, -HALF_PI])
def test_gimbal_lock_is_deterministic(axes, middle):
    rng = np.random.default_rng(1)
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, 20),
            np.full(20, middle),
            rng.uniform(-np.pi, np.pi, 20),
        ]
    )
    R = euler_to_matrix(angles, axes)
    back = matrix_to_euler(R, axes)
    assert np.allclose(back[:, 1], middle, atol=1e-7)
    assert np.all(back[:, 2] == 0.0)  # the last angle is set to zero
    assert np.allclose(euler_to_matrix(back, axes), R, atol=4e-15)
    assert np.array_equal(matrix_to_euler(R, axes), back)


def test_matrix_to_euler_is_vectorised_over_leading_dims():
    rng = np.random.default_rng(2)
    angles = rng.uniform(-np.pi, np.pi, size=(4, 5, 3))
    R = euler_to_matrix(angles, "zxy")
    assert R.shape == (4, 5, 3, 3)
    back = matrix_to_euler(R, "zxy")
    assert back.shape == (4, 5, 3)
    assert np.allclose(euler_to_matrix(back, "zxy"), R, atol=1e-14)


@pytest.mark.parametrize(
    "axes, message",
    [("xyw", "letters"), ("xx", "repeat"), ("", "letters"), ("xyzx", "letters")],
)
def test_bad_axes(axes, message):
    with pytest.raises(ValueError, match=message):
        matrix_to_euler(np.eye(3), axes)


def test_angle_count_must_match_axes():
    with pytest.raises(ValueError, match="columns"):
        euler_to_matrix(np.zeros(3), "xy")


unit_axis = st.tuples(
    st.floats(-1, 1, allow_nan=False),
    st.floats(-1, 1, allow_nan=False),
    st.floats(-1, 1, allow_nan=False),
).filter(lambda v: np.linalg.norm(v) > 1e-3)
rotation_angle = st.one_of(
    st.floats(0.0, np.pi, allow_nan=False),
    st.floats(1e-12, 1e-4),  # near 0
    st.builds(lambda e: np.pi - e, st.floats(1e-9, 1e-3)),  # near pi
)


@settings(max_examples=300, deadline=None)
@given(axis=unit_axis, theta=rotation_angle)
def test_expmap_round_trip(axis, theta):
    n = np.asarray(axis) / np.linalg.norm(axis)
    r = theta * n
    R = expmap_to_matrix(r)
    assert _is_rotation(R)
    assert np.allclose(R, Rotation.from_rotvec(r).as_matrix(), atol=1e-15)
    back = matrix_to_expmap(R)
    if np.pi - theta > 1e-12:
        assert np.allclose(back, r, rtol=0, atol=1e-12)
    else:  # at pi, r and -r are the same rotation
        assert np.allclose(np.abs(back), np.abs(r), rtol=0, atol=1e-7)
    assert np.allclose(expmap_to_matrix(back), R, atol=4e-15)


def test_expmap_near_zero_is_accurate_relative_to_its_size():
    rng = np.random.default_rng(3)
    n = rng.normal(size=(200, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    theta = 10.0 ** rng.uniform(-14, -4, 200)
    r = n * theta[:, None]
    back = matrix_to_expmap(expmap_to_matrix(r))
    relative = np.linalg.norm(back - r, axis=1) / theta
    assert relative.max() < 1e-9
    assert np.array_equal(matrix_to_expmap(np.eye(3)), np.zeros(3))


def test_expmap_at_pi_gives_angle_pi_and_a_deterministic_sign():
    for axis in np.eye(3):
        R = expmap_to_matrix(np.pi * axis)
        r = matrix_to_expmap(R)
        assert np.isclose(np.linalg.norm(r), np.pi)
        assert np.allclose(r, np.pi * axis, atol=1e-7)  # largest component positive
        assert np.allclose(expmap_to_matrix(r), R, atol=1e-15)
        assert np.allclose(expmap_to_matrix(-r), R, atol=1e-15)


def test_expmap_to_matrix_accepts_any_angle():
    n = np.array([0.0, 0.6, 0.8])
    for theta in [0.5, 3.0, 4.0, 7.0, -2.0]:
        R = expmap_to_matrix(theta * n)
        assert np.allclose(R, axis_angle_to_matrix(n, theta))
        back = matrix_to_expmap(R)
        assert np.linalg.norm(back) <= np.pi + 1e-12
        assert np.allclose(expmap_to_matrix(back), R, atol=1e-14)


def test_unwrap_expmap_removes_the_jump_at_pi():
    # A rotation about a fixed axis whose angle passes through pi
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    theta = np.linspace(2.5, 4.0, 40)
    R = expmap_to_matrix(theta[:, None] * n)
    jumpy = matrix_to_expmap(R)
    assert np.max(np.linalg.norm(np.diff(jumpy, axis=0), axis=1)) > 5.0
    smooth = unwrap_expmap(jumpy)
    assert np.allclose(smooth, theta[:, None] * n, atol=1e-9)
    assert np.allclose(expmap_to_matrix(smooth), R, atol=1e-14)


def test_unwrap_expmap_vectorised_over_bones_and_keeps_identity():
    rng = np.random.default_rng(4)
    r = rng.normal(scale=0.3, size=(30, 5, 3))
    r[10, 2] = 0.0
    assert np.allclose(unwrap_expmap(r), r)
    with pytest.raises(ValueError, match="shape"):
        unwrap_expmap(np.zeros(3))


def test_mean_rotation_is_the_chordal_mean():
    from sklearn_crbm.utils._rotations import mean_rotation

    rotations = Rotation.random(50, random_state=0)
    spread = Rotation.from_rotvec(0.3 * rotations.as_rotvec() / np.pi)
    centre = Rotation.from_rotvec([0.2, 2.9, -0.4])  # near pi from the identity
    R = (centre * spread).as_matrix()
    M = mean_rotation(R)
    assert np.allclose(M @ M.T, np.eye(3)) and np.isclose(np.linalg.det(M), 1.0)
    # no rotation is closer to the matrices in the Frobenius sense
    cost = lambda Q: np.sum((R - Q) ** 2)  # noqa: E731
    for other in Rotation.random(200, random_state=1).as_matrix():
        assert cost(M) <= cost(other)
    nudged = Rotation.from_rotvec([1e-3, 0, 0]).as_matrix() @ M
    assert cost(M) < cost(nudged)
    # NaN frames are ignored; none finite gives the identity
    with_nan = np.concatenate([R, np.full((3, 3, 3), np.nan)])
    assert np.allclose(mean_rotation(with_nan), M)
    assert np.array_equal(mean_rotation(np.full((2, 3, 3), np.nan)), np.eye(3))
