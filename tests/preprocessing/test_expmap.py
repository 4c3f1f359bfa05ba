"""ExpMapEncoder: Euler angles <-> exponential maps."""

import itertools
import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sklearn_crbm.datasets import Bone, Skeleton, load_cmu35, make_walker
from sklearn_crbm.preprocessing import ExpMapEncoder
from sklearn_crbm.preprocessing._layout import expmap_layout, find_euler_blocks
from sklearn_crbm.utils._rotations import euler_to_matrix, expmap_to_matrix


def _wrapped_deg(a, b):
    """Absolute angle difference in degrees, modulo 360."""
    return np.abs((np.asarray(a) - b + 180.0) % 360.0 - 180.0)


def _skeleton(*bones, **kwargs):
    return Skeleton(
        [
            Bone(name, None, np.zeros(3), 0.0, channels, order)
            for name, channels, order in bones
        ],
        **kwargs,
    )


@pytest.fixture(scope="module")
def cmu(data_home):
    return load_cmu35(data_home)


def test_cmu_round_trip_is_exact(cmu):
    encoder = ExpMapEncoder(cmu.skeleton)
    Z = encoder.fit_transform(cmu.data, sequence_ids=cmu.sequence_ids)
    assert Z.shape == (2813, 3 + 29 * 3)
    back = encoder.inverse_transform(Z)
    # positions pass through untouched
    assert np.array_equal(back[:, :3], cmu.data[:, :3])
    # every angle comes back, modulo 360, to 1e-9 degrees -- including the
    # 2-DOF joints with an angle beyond +-90 (35_19's rhand, the lthumb frame)
    err = _wrapped_deg(back, cmu.data)
    assert err.max() < 1e-9
    names = list(cmu.feature_names)
    beyond = np.abs(cmu.data[:, [names.index("rhand_rz"), names.index("lthumb_rz")]])
    assert (beyond > 90).sum() >= 2
    # angles outside (-180, 180] come back as their equivalent
    assert cmu.data.min() < -180 and back[:, 6:].min() >= -180


def test_cmu_one_dof_joints_use_one_axis(cmu):
    encoder = ExpMapEncoder(cmu.skeleton).fit(cmu.data)
    Z = encoder.transform(cmu.data)
    names = list(encoder.get_feature_names_out())
    for bone in ["ltibia", "rtibia", "lradius", "ltoes", "lfingers"]:
        assert np.all(Z[:, names.index(f"{bone}_ey")] == 0.0)
        assert np.all(Z[:, names.index(f"{bone}_ez")] == 0.0)
    assert np.all(np.abs(Z[:, names.index("ltibia_ex")]) > 0)
    wrist = [names.index(f"lwrist_{c}") for c in ("ex", "ez")]  # dof ry
    assert np.all(Z[:, wrist] == 0.0)


def test_exp_maps_equal_the_composed_rotation(cmu):
    encoder = ExpMapEncoder(cmu.skeleton).fit(cmu.data)
    Z = encoder.transform(cmu.data[:50])
    names_in = list(cmu.feature_names)
    names_out = list(encoder.get_feature_names_out())
    angles = np.deg2rad(cmu.data[:50, [names_in.index(f"lfemur_r{a}") for a in "xyz"]])
    R = euler_to_matrix(angles, "xyz")
    r = Z[:, [names_out.index(f"lfemur_e{a}") for a in "xyz"]]
    assert np.allclose(expmap_to_matrix(r), R, atol=1e-14)
    assert np.all(np.linalg.norm(r, axis=1) <= np.pi)


def test_feature_names_out_replace_each_block_in_place():
    skeleton = _skeleton(
        ("root", ("tx", "ty", "tz", "rx", "ry", "rz"), "xyz"),
        ("hip", (), ""),
        ("knee", ("rx",), "x"),
        ("foot", ("rz", "rx"), "zx"),
    )
    encoder = ExpMapEncoder(skeleton).fit(np.zeros((3, 9)))
    assert encoder.encoded_bones_ == ["root", "knee", "foot"]
    assert list(encoder.get_feature_names_out()) == [
        "root_tx", "root_ty", "root_tz", "root_ex", "root_ey", "root_ez",
        "knee_ex", "knee_ey", "knee_ez", "foot_ex", "foot_ey", "foot_ez",
    ]  # fmt: skip


@pytest.mark.parametrize("order", ["".join(p) for p in itertools.permutations("xyz")])
def test_rotation_order_of_the_skeleton_is_used(order):
    # channels always listed rx ry rz; the bone composes them in `order`
    skeleton = _skeleton(("b", ("rx", "ry", "rz"), order))
    rng = np.random.default_rng(0)
    X = rng.uniform(-80, 80, size=(20, 3))
    encoder = ExpMapEncoder(skeleton).fit(X)
    Z = encoder.transform(X)
    columns = ["xyz".index(a) for a in order]
    expected = euler_to_matrix(np.deg2rad(X[:, columns]), order)
    assert np.allclose(expmap_to_matrix(Z), expected, atol=1e-14)
    assert np.allclose(encoder.inverse_transform(Z), X, atol=1e-9)


axes_and_angles = st.sampled_from(
    ["".join(p) for k in (1, 2, 3) for p in itertools.permutations("xyz", k)]
).flatmap(
    lambda axes: st.tuples(
        st.just(axes),
        st.lists(
            st.one_of(
                st.floats(-179.999, 180.0),
                st.sampled_from([180.0, -179.9999999, 90.0, -90.0, 0.0, 179.9999999]),
            ),
            min_size=len(axes),
            max_size=len(axes),
        ),
    )
)


@settings(max_examples=200, deadline=None)
@given(case=axes_and_angles, unit=st.sampled_from(["deg", "rad"]))
def test_inverse_round_trip_property(case, unit):
    axes, angles = case
    skeleton = _skeleton(("b", tuple("r" + a for a in axes), axes))
    X = np.array([angles])
    if unit == "rad":
        X = np.deg2rad(X)
    encoder = ExpMapEncoder(skeleton, angle_unit=unit).fit(X)
    back = encoder.inverse_transform(encoder.transform(X))
    R = euler_to_matrix(X if unit == "rad" else np.deg2rad(X), axes)
    R_back = euler_to_matrix(back if unit == "rad" else np.deg2rad(back), axes)
    # A rotation within _PI_TIE_TOL (1e-12) of a half turn is encoded as the
    # half turn itself, which moves the matrix by up to a few times that.
    assert np.allclose(R_back, R, atol=1e-11)
    # Unique Euler angles come back themselves: always for one or two axes (the
    # absent angle is zero), for three when the middle one is inside (-90, 90).
    if len(axes) < 3 or abs(_wrapped_deg(angles[1], 0.0)) < 90.0 - 1e-6:
        scale = 1.0 if unit == "deg" else 180.0 / np.pi
        assert _wrapped_deg(back * scale, X * scale).max() < 1e-9


def test_continuous_removes_the_jump_per_sequence():
    skeleton = _skeleton(("b", ("rz",), "z"))
    angles = np.concatenate([np.linspace(150, 210, 13), np.linspace(170, 230, 13)])
    X = ((angles + 180) % 360 - 180)[:, None]  # raw data wraps at 180 too
    ids = np.repeat([0, 1], 13)
    plain = ExpMapEncoder(skeleton).fit_transform(X, sequence_ids=ids)
    assert np.abs(np.diff(plain[:13, 2])).max() > 5  # jumps near pi
    encoder = ExpMapEncoder(skeleton, continuous=True)
    smooth = encoder.fit_transform(X, sequence_ids=ids)
    assert np.allclose(smooth[:13, 2], np.deg2rad(angles[:13]))
    # the second sequence starts afresh at angle <= pi
    assert smooth[13, 2] == pytest.approx(np.deg2rad(170))
    assert np.allclose(smooth[13:, 2], np.deg2rad(angles[13:]))
    assert _wrapped_deg(encoder.inverse_transform(smooth), X).max() < 1e-9
    # without sequence_ids the whole array is one sequence
    assert np.allclose(encoder.transform(X)[:13], smooth[:13])


def test_plain_array_without_skeleton_passes_through():
    X = np.arange(12.0).reshape(3, 4)
    encoder = ExpMapEncoder().fit(X)
    assert encoder.encoded_bones_ == []
    assert np.array_equal(encoder.transform(X), X)
    assert np.array_equal(encoder.inverse_transform(X), X)
    assert list(encoder.get_feature_names_out()) == ["x0", "x1", "x2", "x3"]
    names = ["a", "b", "c", "d"]
    assert list(encoder.get_feature_names_out(names)) == names


def test_bones_inferred_from_feature_names_in_asf_order():
    names = ["root_tx", "root_rz", "root_ry", "knee_rx", "label", "foot_rx", "foot_rz"]
    blocks = find_euler_blocks(names)
    assert [(b.bone, b.columns, b.axes) for b in blocks] == [
        ("root", (1, 2), "zy"),
        ("knee", (3,), "x"),
        ("foot", (5, 6), "xz"),
    ]
    out, passthrough, starts = expmap_layout(names, blocks)
    assert list(out) == [
        "root_tx", "root_ex", "root_ey", "root_ez", "knee_ex", "knee_ey", "knee_ez",
        "label", "foot_ex", "foot_ey", "foot_ez",
    ]  # fmt: skip
    assert passthrough.tolist() == [[0, 0], [7, 4]]
    assert starts.tolist() == [1, 4, 8]


def test_walker_round_trip_and_feature_names():
    walker = make_walker(n_sequences=2, n_frames=30, random_state=0)
    encoder = ExpMapEncoder(walker.skeleton).fit(walker.data)
    Z = encoder.transform(walker.data)
    assert np.allclose(encoder.inverse_transform(Z), walker.data, atol=1e-9)
    with pytest.raises(ValueError, match="do not match"):
        encoder.get_feature_names_out(["x"] * walker.data.shape[1])


def test_unknown_channel_names_raise():
    skeleton = _skeleton(("knee", ("rx",), "x"))
    with pytest.raises(ValueError, match=r"Unknown channels 'hip_rx'"):
        find_euler_blocks(["knee_rx", "hip_rx"], skeleton)
    with pytest.raises(ValueError, match=r"Unknown channels 'knee_ry'"):
        find_euler_blocks(["knee_ry"], skeleton)


def test_incomplete_bone_raises():
    skeleton = _skeleton(("hip", ("rx", "ry", "rz"), "xyz"))
    with pytest.raises(ValueError, match=r"lacks \['hip_rz'\]"):
        find_euler_blocks(["hip_rx", "hip_ry"], skeleton)
    with pytest.raises(ValueError, match="more than once"):
        find_euler_blocks(["hip_rx", "hip_rx"])


def test_wrong_column_count_raises(cmu):
    encoder = ExpMapEncoder(cmu.skeleton)
    with pytest.raises(ValueError, match="skeleton has 62 channels"):
        encoder.fit(cmu.data[:, :60])
    encoder.fit(cmu.data)
    with pytest.raises(ValueError, match="X has 61 features"):
        encoder.transform(cmu.data[:, :61])
    with pytest.raises(ValueError, match="expects 90 features"):
        encoder.inverse_transform(cmu.data)


def test_bad_sequence_ids_raise(cmu):
    encoder = ExpMapEncoder(cmu.skeleton, continuous=True).fit(cmu.data)
    with pytest.raises(ValueError, match="one sequence id per row"):
        encoder.transform(cmu.data, sequence_ids=cmu.sequence_ids[:-1])


def test_nan_propagates_to_its_bone_only():
    walker = make_walker(n_sequences=1, n_frames=5, random_state=0)
    X = walker.data.copy()
    names = list(walker.feature_names)
    X[2, names.index("ltibia_rx")] = np.nan
    encoder = ExpMapEncoder(walker.skeleton).fit(walker.data)
    Z = encoder.transform(X)
    out = list(encoder.get_feature_names_out())
    nan_columns = set(np.flatnonzero(np.isnan(Z).any(axis=0)))
    assert nan_columns == {out.index(f"ltibia_{c}") for c in ("ex", "ey", "ez")}
    assert np.isnan(Z).sum() == 3


def test_mean_reference_measures_bones_from_their_mean_but_not_the_root():
    walker = make_walker(n_sequences=2, n_frames=40, random_state=0)
    X = walker.data.copy()
    femur = [list(walker.feature_names).index(f"lfemur_r{a}") for a in "xyz"]
    X[:, femur[0]] += 175.0  # the thigh sits near pi from its rest pose
    rest = ExpMapEncoder(walker.skeleton).fit(X)
    mean = ExpMapEncoder(walker.skeleton, reference="mean").fit(X)
    names = list(mean.get_feature_names_out())
    assert names == list(rest.get_feature_names_out())
    R = euler_to_matrix(np.deg2rad(X[:, femur]), "xyz")
    M = mean.reference_rotations_[mean.encoded_bones_.index("lfemur")]
    # the chordal mean: the rotation nearest to the mean matrix
    assert np.allclose(M.T @ M, np.eye(3)) and np.linalg.det(M) > 0
    U, _, Vt = np.linalg.svd(R.mean(axis=0))
    assert np.allclose(M, U @ Vt)
    cols = [names.index(f"lfemur_e{a}") for a in "xyz"]
    Z_rest, Z_mean = rest.transform(X), mean.transform(X)
    assert np.allclose(expmap_to_matrix(Z_mean[:, cols]), M.T @ R)
    assert np.linalg.norm(Z_rest[:, cols], axis=1).max() > 2.5
    assert np.linalg.norm(Z_mean[:, cols], axis=1).max() < 0.6
    # the root keeps its global orientation, for RootRelativeEncoder
    assert np.array_equal(mean.reference_rotations_[0], np.eye(3))
    root = [names.index(f"root_e{a}") for a in "xyz"]
    assert np.array_equal(Z_mean[:, root], Z_rest[:, root])
    back = mean.inverse_transform(Z_mean)
    # every bone's rotation comes back (the thigh as an equivalent triple)
    rotations = walker.skeleton.local_rotations(X)
    assert np.abs(walker.skeleton.local_rotations(back) - rotations).max() < 1e-13


def test_chunks_give_the_maps_of_one_pass(monkeypatch):
    # a bone turning through pi in sequences that cross the chunk boundaries
    skeleton = _skeleton(("a", ("rx", "ry", "rz"), "zxy"), ("b", ("rz",), "z"))
    rng = np.random.default_rng(0)
    turn = np.concatenate([np.linspace(150, 400, 23), np.linspace(100, -250, 17)])
    X = np.column_stack([rng.uniform(-179, 179, size=(40, 3)), turn])
    X[:, 3] = (X[:, 3] + 180) % 360 - 180
    ids = np.repeat([0, 1], [23, 17])
    for continuous, dtype in itertools.product([False, True], [np.float64, np.float32]):
        encoder = ExpMapEncoder(skeleton, continuous=continuous, reference="mean")
        whole = encoder.fit_transform(X.astype(dtype), sequence_ids=ids)
        monkeypatch.setattr("sklearn_crbm.preprocessing._layout.CHUNK_FRAMES", 7)
        chunked = encoder.transform(X.astype(dtype), sequence_ids=ids)
        monkeypatch.undo()
        assert chunked.dtype == dtype
        np.testing.assert_array_equal(chunked, whole)
    assert np.abs(np.diff(whole[:23, 5])).max() < 0.2  # unwrapped through pi


def test_transform_adds_little_beyond_its_output():
    # the rotation matrices of all frames at once took twenty times the output
    walker = make_walker(n_sequences=8, n_frames=5000, random_state=0)
    X = walker.data.astype(np.float32)
    encoder = ExpMapEncoder(walker.skeleton).fit(X)
    tracemalloc.start()
    try:
        base, _ = tracemalloc.get_traced_memory()
        Z = encoder.transform(X)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert Z.dtype == np.float32
    assert peak - base < Z.nbytes + 20e6  # a chunk's matrices: about 14 MB
