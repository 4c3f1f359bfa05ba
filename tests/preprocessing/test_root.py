"""RootRelativeEncoder: global root <-> body-centred root."""

import dataclasses
import pickle
import tracemalloc
import warnings

import numpy as np
import pytest
import scipy.io

from sklearn_crbm.datasets import load_cmu35, load_mit_walk, make_walker
from sklearn_crbm.preprocessing import ExpMapEncoder, RootRelativeEncoder
from sklearn_crbm.utils._rotations import (
    euler_to_matrix,
    expmap_to_matrix,
    matrix_to_expmap,
)

ROOT_OUT = [
    "root_pitch",
    "root_roll",
    "root_dheading",
    "root_dforward",
    "root_dsideways",
    "root_height",
]


@pytest.fixture(scope="module")
def mit(data_home):
    return load_mit_walk(data_home)


@pytest.fixture(scope="module")
def cmu_expmap(data_home):
    cmu = load_cmu35(data_home)
    encoder = ExpMapEncoder(cmu.skeleton).fit(cmu.data)
    return cmu, encoder.transform(cmu.data), encoder.get_feature_names_out()


def _align_and_compare(original, back, ids, position_cols, expmap_cols, up):
    """Max errors of orientation and trajectory once each sequence's start pose
    (heading and ground position) is aligned with the original's."""
    rot_err = pos_err = 0.0
    for s in np.unique(ids):
        o, b = original[ids == s], back[ids == s]
        Ro, Rb = (
            expmap_to_matrix(o[:, expmap_cols]),
            expmap_to_matrix(b[:, expmap_cols]),
        )
        Q = Ro[0] @ Rb[0].T  # a rotation about the vertical only
        assert np.allclose(Q[:, up], np.eye(3)[up], atol=1e-12)
        rot_err = max(rot_err, np.abs(Q @ Rb - Ro).max())
        po, pb = o[:, position_cols], b[:, position_cols]
        aligned = (pb - pb[0]) @ Q.T + po[0]
        pos_err = max(pos_err, np.abs(aligned - po).max())
    return rot_err, pos_err


def test_mit_equals_taylors_motion_mat(mit, data_home):
    """Taylor's motion.mat is preprocess1(data.mat Motion[::4]); columns 1-6 are
    tilt forward, tilt left, d heading, d forward, d sideways, height."""
    motion = scipy.io.loadmat(data_home / "taylor_theano_motion" / "motion.mat")
    expected = np.vstack([m for m in motion["Motion"].flat])
    encoder = RootRelativeEncoder(mit.skeleton, roll="taylor")
    Z = encoder.fit_transform(mit.data, sequence_ids=mit.sequence_ids)
    assert encoder.up_axis_ == "z"
    assert list(encoder.get_feature_names_out()[:6]) == ROOT_OUT
    assert Z.shape == expected.shape == (3826, 108)
    assert np.abs(Z - expected).max() < 1e-12
    assert np.array_equal(Z[:, 6:], mit.data[:, 6:])


def test_mit_round_trip(mit):
    encoder = RootRelativeEncoder(mit.skeleton).fit(mit.data)
    ids = mit.sequence_ids
    back = encoder.inverse_transform(
        encoder.transform(mit.data, sequence_ids=ids), sequence_ids=ids
    )
    assert np.array_equal(back[:, 6:], mit.data[:, 6:])
    assert np.abs(back[:, 5] - mit.data[:, 5]).max() < 1e-12  # height is absolute
    # the documented start pose: heading 0 and ground position (0, 0)
    starts = np.flatnonzero(np.diff(ids, prepend=-1))
    assert np.all(back[starts][:, 3:5] == 0.0)
    forward = expmap_to_matrix(back[starts, :3])[:, :, 0]
    assert np.allclose(forward[:, 1], 0.0, atol=1e-15) and np.all(forward[:, 0] > 0)
    rot_err, pos_err = _align_and_compare(
        mit.data, back, ids, [3, 4, 5], [0, 1, 2], up=2
    )
    assert rot_err < 1e-12
    assert pos_err < 1e-9  # mm, after up to 3128 integrated steps


def test_cmu_round_trip_y_up(cmu_expmap):
    cmu, Z, names = cmu_expmap
    names = list(names)
    encoder = RootRelativeEncoder(cmu.skeleton)
    ids = cmu.sequence_ids
    E = encoder.fit_transform(Z, sequence_ids=ids)
    assert encoder.up_axis_ == "y"
    assert list(encoder.get_feature_names_out()) == ROOT_OUT + names[6:]
    # upright, walking forward along the body's z axis
    assert np.all(np.abs(E[:, 0] - np.pi / 2) < 0.3)
    assert np.all(np.abs(E[:, 1] - np.pi / 2) < 0.3)
    assert np.median(E[:, 3]) > 0.3 and np.abs(np.median(E[:, 4])) < 0.1
    assert np.array_equal(E[:, 5], Z[:, 1])
    back = encoder.inverse_transform(E, sequence_ids=ids)
    rot_err, pos_err = _align_and_compare(Z, back, ids, [0, 1, 2], [3, 4, 5], up=1)
    assert rot_err < 1e-12
    assert pos_err < 1e-10


@pytest.mark.parametrize("up", ["x", "y"])
def test_up_axis_is_a_cyclic_relabelling(mit, up):
    """The same motion written with another vertical gives the same encoding."""
    u = "xyz".index(up)
    perm = np.array([(u + 1) % 3, (u + 2) % 3, u])  # new axis -> old z-up axis
    inv = np.argsort(perm)  # old axis i is stored in column inv[i]
    X = mit.data[:200].copy()
    moved = X.copy()
    moved[:, 3:6] = X[:, 3:6][:, inv]
    moved[:, 0:3] = X[:, 0:3][:, inv]  # a proper relabelling maps exp maps alike
    z_up = RootRelativeEncoder(up_axis="z", root="root")
    reference = z_up.fit(X[:, :6][:, [3, 4, 5, 0, 1, 2]]).transform(
        X[:, :6][:, [3, 4, 5, 0, 1, 2]]
    )
    other = RootRelativeEncoder(up_axis=up).fit(moved[:, :6][:, [3, 4, 5, 0, 1, 2]])
    assert np.allclose(
        other.transform(moved[:, :6][:, [3, 4, 5, 0, 1, 2]]), reference, atol=1e-12
    )


def test_sequences_are_encoded_independently(mit):
    encoder = RootRelativeEncoder(mit.skeleton).fit(mit.data)
    ids = mit.sequence_ids
    whole = encoder.transform(mit.data, sequence_ids=ids)
    for s in np.unique(ids):
        alone = encoder.transform(mit.data[ids == s])
        assert np.array_equal(whole[ids == s], alone)
    # The last frame of every sequence repeats the deltas of the frame before
    last = np.flatnonzero(np.diff(ids, append=-1))
    assert np.array_equal(whole[last, 2:5], whole[last - 1, 2:5])
    # ... which differs from running across the boundaries
    joined = encoder.transform(mit.data)
    assert not np.allclose(joined[last[:-1], 2:5], whole[last[:-1], 2:5])


def test_a_one_frame_sequence_has_zero_deltas():
    walker = make_walker(n_sequences=1, n_frames=10, random_state=0)
    X = ExpMapEncoder(walker.skeleton).fit_transform(walker.data)
    ids = np.array([0] * 9 + [1])
    encoder = RootRelativeEncoder(walker.skeleton).fit(X)
    E = encoder.transform(X, sequence_ids=ids)
    assert np.array_equal(E[9, 2:5], np.zeros(3))
    back = encoder.inverse_transform(E, sequence_ids=ids)
    assert np.array_equal(back[9, [0, 2]], [0.0, 0.0])


def test_step_of_a_simple_walk():
    # y up; the body turns 90 degrees to its left (about +y) at frame 2
    X = np.zeros((4, 6))
    X[:, 1] = 10.0
    X[:, 2] = [0.0, 1.0, 2.0, 2.0]  # tz: forward along +z ...
    X[3, 0] = 1.0  # ... then one step along +x, the body's left before turning
    X[2:, 4] = np.pi / 2  # root exp map about y: now facing +x
    E = RootRelativeEncoder(up_axis="y").fit_transform(X)
    assert np.allclose(E[:, 2], [0.0, np.pi / 2, 0.0, 0.0])  # d heading
    assert np.allclose(E[:, 3], [1.0, 1.0, 1.0, 1.0])  # d forward
    assert np.allclose(E[:, 4], 0.0)  # d sideways
    X2 = X.copy()
    X2[3, [0, 2]] = [2.0, 3.0]  # side step to the right after the turn
    E2 = RootRelativeEncoder(up_axis="y").fit_transform(X2)
    assert np.allclose(E2[2, 3:5], [2.0, 1.0])  # forward 2, 1 to the right


def test_unnamed_array_uses_the_first_six_columns():
    walker = make_walker(n_sequences=1, n_frames=20, random_state=1)
    X = ExpMapEncoder(walker.skeleton).fit_transform(walker.data)
    with_skeleton = RootRelativeEncoder(walker.skeleton).fit(X).transform(X)
    positional = RootRelativeEncoder(up_axis="y").fit(X)
    assert np.array_equal(positional.transform(X), with_skeleton)
    assert list(positional.get_feature_names_out()[:7]) == ROOT_OUT + ["x6"]
    assert positional.root_columns_.tolist() == [0, 1, 2, 3, 4, 5]


def test_estimator_basics_on_root_data():
    """The basics sklearn's common checks test on partial roots (their data has
    fewer than six columns), on a whole root located through a skeleton: fit
    returns self, idempotence, pickling, input containers."""
    walker = make_walker(n_sequences=2, n_frames=15, random_state=2)
    X = ExpMapEncoder(walker.skeleton).fit_transform(walker.data)
    encoder = RootRelativeEncoder(walker.skeleton)
    assert encoder.fit(X) is encoder
    first = encoder.transform(X)
    assert np.array_equal(encoder.fit(X).transform(X), first)
    clone = pickle.loads(pickle.dumps(encoder))
    assert np.array_equal(clone.transform(X), first)
    assert np.array_equal(encoder.transform(X.tolist()), first)
    assert np.array_equal(encoder.transform(np.asfortranarray(X)), first)
    assert encoder.transform(X.astype(np.float32)).dtype == np.float32
    readonly = X.copy()
    readonly.setflags(write=False)
    assert np.array_equal(encoder.transform(readonly), first)
    assert encoder.n_features_in_ == X.shape[1]
    assert encoder.get_params() == RootRelativeEncoder(walker.skeleton).get_params()


def test_missing_root_channels_raise(cmu_expmap):
    cmu, Z, _ = cmu_expmap
    with pytest.raises(ValueError, match=r"lacks the root channels \['pelvis_tx'"):
        RootRelativeEncoder(cmu.skeleton, root="pelvis").fit(Z)
    with pytest.raises(ValueError, match="3 feature"):
        RootRelativeEncoder().fit(Z[:, :3])


def test_raw_euler_layout_raises(cmu_expmap):
    cmu, _, _ = cmu_expmap
    with pytest.raises(ValueError, match="after ExpMapEncoder, are 90"):
        RootRelativeEncoder(cmu.skeleton).fit(cmu.data)


def test_wrong_column_count_at_transform_raises(cmu_expmap):
    cmu, Z, _ = cmu_expmap
    encoder = RootRelativeEncoder(cmu.skeleton).fit(Z)
    with pytest.raises(ValueError, match="X has 89 features"):
        encoder.transform(Z[:, :89])
    with pytest.raises(ValueError, match="expects 90 features"):
        encoder.inverse_transform(Z[:, :89])
    with pytest.raises(ValueError, match="more than one contiguous run"):
        encoder.transform(Z[:4], sequence_ids=[0, 1, 0, 1])


def test_bad_up_axis_raises():
    with pytest.raises(ValueError, match="up_axis"):
        RootRelativeEncoder(up_axis="w").fit(np.zeros((3, 6)))


def _random_root(n, seed, up):
    """Root channels (tx, ty, tz, ex, ey, ez) with uniformly random orientations,
    a few exactly at gimbal lock (forward axis straight up or down)."""
    from scipy.spatial.transform import Rotation

    u = "xyz".index(up)
    forward, left = (u + 1) % 3, (u + 2) % 3
    maps = Rotation.random(n, random_state=seed).as_rotvec()
    # heading about the vertical, then the forward axis turned onto it
    headings = Rotation.from_rotvec(np.outer([0.3, -2.0, 3.0, 1.0], np.eye(3)[u]))
    tilts = Rotation.from_rotvec(np.outer([1, -1, 1, -1], np.pi / 2 * np.eye(3)[left]))
    maps[:4] = (headings * tilts).as_rotvec()
    R = Rotation.from_rotvec(maps[:4]).as_matrix()
    assert np.allclose(np.abs(R[:, u, forward]), 1.0, atol=1e-15)
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.normal(size=(n, 3)) * 10.0, maps])


@pytest.mark.parametrize("up", ["x", "y", "z"])
def test_every_orientation_round_trips_upside_down_included(up):
    X = _random_root(400, seed=0, up=up)
    encoder = RootRelativeEncoder(up_axis=up).fit(X)
    E = encoder.transform(X)
    back = encoder.inverse_transform(E)
    u = "xyz".index(up)
    rot_err, pos_err = _align_and_compare(
        X, back, np.zeros(len(X)), [0, 1, 2], [3, 4, 5], up=u
    )
    assert rot_err < 1e-12 and pos_err < 1e-10
    assert np.all((E[:, 0] >= 0) & (E[:, 0] <= np.pi))  # pitch
    assert np.all((E[:, 1] > -np.pi / 2) & (E[:, 1] <= 1.5 * np.pi))  # roll


def test_taylors_roll_matches_the_exact_roll_when_upright_and_warns_otherwise():
    X = _random_root(400, seed=1, up="y")
    euler = RootRelativeEncoder(up_axis="y").fit(X)
    with pytest.warns(UserWarning, match=r"cannot encode frames \d+, \d+"):
        taylor = RootRelativeEncoder(up_axis="y", roll="taylor").fit_transform(X)
    E = euler.transform(X)
    # the same pitch, deltas and height (away from the four frames at gimbal
    # lock, where the heading is arbitrary)
    same = [0, 2, 3, 4, 5]
    assert np.allclose(E[4:, same], taylor[4:, same], atol=1e-9)
    # the two rolls agree for a body that leans sideways but does not pitch:
    # R = R_y(heading) R_z(lean), z being the forward axis when y is up
    lean = np.tile([0.3, -0.5, 0.0, 1.2], 100)
    heading = np.linspace(-3.0, 3.0, 400)
    X[:, 3:6] = matrix_to_expmap(
        euler_to_matrix(np.column_stack([lean, heading]), "zy")
    )
    E = euler.transform(X)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        taylor = RootRelativeEncoder(up_axis="y", roll="taylor").fit_transform(X)
    assert np.allclose(E[:, 0], np.pi / 2, atol=1e-12)
    assert np.allclose(E[:, 1], taylor[:, 1], atol=1e-12)
    assert np.allclose(E[:, 1], np.pi / 2 + lean, atol=1e-12)


def test_the_root_is_the_skeletons_first_bone():
    walker = make_walker(n_sequences=1, n_frames=10, random_state=0)
    bones = list(walker.skeleton.bones)
    renamed = [
        type(b)(
            "Hips" if b.name == "root" else b.name,
            "Hips" if b.parent == "root" else b.parent,
            b.direction,
            b.length,
            b.channels,
            b.rotation_order,
        )
        for b in bones
    ]
    skeleton = type(walker.skeleton)(renamed)
    X = ExpMapEncoder(skeleton).fit_transform(walker.data)
    encoder = RootRelativeEncoder(skeleton).fit(X)
    assert encoder.root_ == "Hips"
    assert list(encoder.get_feature_names_out()[:2]) == ["Hips_pitch", "Hips_roll"]
    assert np.array_equal(
        encoder.transform(X), RootRelativeEncoder(walker.skeleton).fit(X).transform(X)
    )
    with pytest.raises(ValueError, match=r"root='pelvis'.*pass root="):
        RootRelativeEncoder(skeleton, root="pelvis").fit(X)


# ------------------------------------------------------- roots with some channels
ROOT_IN = ["tx", "ty", "tz", "ex", "ey", "ez"]
# what a root holds, in words; _channels names the channels for an up axis
ROLES = [
    ("ground",),
    ("ground", "height"),
    ("ground", "yaw"),
    ("ground", "height", "yaw"),
    ("yaw",),
    ("rotation",),
    ("height", "rotation"),
]


def _channels(roles, up):
    u = "xyz".index(up)
    ground = ["xyz"[(u + 1) % 3], "xyz"[(u + 2) % 3]]
    names = {
        "ground": [f"t{a}" for a in ground],
        "height": [f"t{up}"],
        "yaw": [f"e{up}"],
        "rotation": ["ex", "ey", "ez"],
    }
    return [c for role in roles for c in names[role]]


def _wrap(angle):
    return (angle + np.pi) % (2 * np.pi) - np.pi


def _turning_walk(n, seed, up):
    """Root channels (tx, ty, tz, ex, ey, ez) of a body that walks on the ground
    and turns about the vertical only, from the origin at heading 0."""
    rng = np.random.default_rng(seed)
    X = np.zeros((n, 6))
    u = "xyz".index(up)
    ground = [(u + 1) % 3, (u + 2) % 3]
    X[1:, ground] = np.cumsum(rng.normal(size=(n - 1, 2)), axis=0)
    X[:, u] = 10.0 + rng.normal(size=n)
    X[:, 3 + u] = _wrap(np.cumsum(np.r_[0.0, rng.normal(scale=0.5, size=n - 1)]))
    return X


@pytest.mark.parametrize("up", ["x", "y", "z"])
@pytest.mark.parametrize("roles", ROLES, ids="+".join)
def test_a_partial_root_is_the_whole_root_with_its_other_channels_at_zero(roles, up):
    channels = _channels(roles, up)
    X = _turning_walk(60, 0, up)
    if "rotation" in roles:  # every orientation, not only turns
        X[:, 3:] = _random_root(60, seed=0, up=up)[:, 3:]
    kept = [ROOT_IN.index(c) for c in channels]
    zeroed = np.zeros_like(X)
    zeroed[:, kept] = X[:, kept]
    whole = RootRelativeEncoder(up_axis=up)
    expected = whole.fit_transform(zeroed)
    # the channels in another order than the whole root's
    partial = RootRelativeEncoder(up_axis=up, channels=channels[::-1])
    E = partial.fit_transform(X[:, kept[::-1]])
    names = list(partial.get_feature_names_out())
    assert len(names) == len(channels)
    whole_names = list(whole.get_feature_names_out())
    assert names == [n for n in whole_names if n in names]
    columns = [whole_names.index(n) for n in names]
    np.testing.assert_allclose(E, expected[:, columns], rtol=0, atol=1e-12)


@pytest.mark.parametrize("up", ["x", "y", "z"])
@pytest.mark.parametrize("roles", ROLES, ids="+".join)
def test_a_partial_root_round_trips_from_the_start_pose(roles, up):
    """Sequences that start at the origin facing heading 0 come back exactly;
    the other columns pass through."""
    root = np.vstack([_turning_walk(40, 1, up), _turning_walk(25, 2, up)])
    ids = np.repeat([0, 1], [40, 25])
    channels = _channels(roles, up)[::-1]
    other = np.random.default_rng(3).normal(size=(len(root), 2))
    X = np.column_stack([root[:, [ROOT_IN.index(c) for c in channels]], other])
    encoder = RootRelativeEncoder(up_axis=up, channels=channels).fit(X)
    k = len(channels)
    assert encoder.root_columns_.tolist() == list(range(k))
    E = encoder.transform(X, sequence_ids=ids)
    assert np.array_equal(E[:, k:], other)
    assert list(encoder.get_feature_names_out()[k:]) == [f"x{k}", f"x{k + 1}"]
    back = encoder.inverse_transform(E, sequence_ids=ids)
    np.testing.assert_allclose(back, X, rtol=0, atol=1e-12)


def test_a_ground_track_with_heading_forgets_where_it_starts_and_faces():
    X = _turning_walk(50, 4, "y")[:, [0, 2, 4]]  # tx, tz, ey
    moved = X.copy()
    turn, shift = 2.0, np.array([30.0, -7.0])
    # a turn of the whole track about +y: (x, z) -> (x cos + z sin, z cos - x sin)
    moved[:, 0] = X[:, 0] * np.cos(turn) + X[:, 1] * np.sin(turn) + shift[0]
    moved[:, 1] = X[:, 1] * np.cos(turn) - X[:, 0] * np.sin(turn) + shift[1]
    moved[:, 2] = _wrap(X[:, 2] + turn)
    vehicle = RootRelativeEncoder(channels=["tx", "tz", "ey"]).fit(X)
    assert list(vehicle.get_feature_names_out()) == ROOT_OUT[2:5]
    np.testing.assert_allclose(
        vehicle.transform(moved), vehicle.transform(X), rtol=0, atol=1e-12
    )
    # without the heading, the steps are in the world's axes: only the shift goes
    track = RootRelativeEncoder(channels=["tx", "tz"]).fit(X[:, :2])
    shifted = X[:, :2] + shift
    np.testing.assert_allclose(
        track.transform(shifted), track.transform(X[:, :2]), rtol=0, atol=1e-12
    )
    assert not np.allclose(track.transform(moved[:, :2]), track.transform(X[:, :2]))
    # world forward is +z, the body's right -x when y is up
    steps = np.diff(X[:, :2], axis=0)
    assert np.allclose(track.transform(X[:, :2])[:-1], steps[:, [1, 0]] * [1, -1])


def test_partial_root_channels_are_found_by_name_through_a_skeleton():
    """A rig whose root cannot move vertically: tx, tz and a rotation."""
    walker = make_walker(n_sequences=1, n_frames=30, random_state=5)
    bones = list(walker.skeleton.bones)
    flat_root = dataclasses.replace(bones[0], channels=("tx", "tz", "rx", "ry", "rz"))
    skeleton = type(walker.skeleton)([flat_root, *bones[1:]])
    X = ExpMapEncoder(skeleton).fit_transform(np.delete(walker.data, 1, axis=1))
    with pytest.raises(
        ValueError,
        match=r"lacks the root channels \['root_ty'\].*has the root channels "
        r"\['tx', 'tz', 'ex', 'ey', 'ez'\]: pass channels=",
    ):
        RootRelativeEncoder(skeleton).fit(X)
    channels = ("ex", "ey", "ez", "tx", "tz")
    named = RootRelativeEncoder(skeleton, channels=channels).fit(X)
    assert named.root_columns_.tolist() == [2, 3, 4, 0, 1]
    positional = RootRelativeEncoder(channels=channels).fit(X[:, [2, 3, 4, 0, 1]])
    np.testing.assert_array_equal(
        named.transform(X)[:, :5], positional.transform(X[:, [2, 3, 4, 0, 1]])[:, :5]
    )
    assert list(named.get_feature_names_out()[:5]) == ROOT_OUT[:5]
    assert np.array_equal(named.transform(X)[:, 5:], X[:, 5:])


@pytest.mark.parametrize(
    "channels, up, message",
    [
        (["tx"], "y", r"one ground-plane translation; .* both \['tx', 'tz'\]"),
        (["ty", "tz", "ez"], "z", r"one ground-plane translation"),
        (["ex"], "y", r"all of ex, ey, ez, or ey alone"),
        (["tx", "tz", "ex", "ey"], "y", r"rotation channels \['ex', 'ey'\]"),
        (["tx", "tx"], "y", "distinct root channels"),
        (["rx"], "y", "distinct root channels"),
        ([], "y", "distinct root channels"),
    ],
)
def test_impossible_channel_sets_raise(channels, up, message):
    with pytest.raises(ValueError, match=message):
        RootRelativeEncoder(up_axis=up, channels=channels).fit(np.zeros((4, 6)))


def test_too_few_columns_for_the_channels_raise():
    with pytest.raises(ValueError, match=r"X has 2 feature\(s\).* 3 root channels"):
        RootRelativeEncoder(channels=("tx", "tz", "ey")).fit(np.zeros((4, 2)))


def test_a_yaw_comes_back_wrapped():
    X = np.linspace(0.0, 9.0, 10)[:, None]  # a steady turn, past pi
    encoder = RootRelativeEncoder(channels=("ey",)).fit(X)
    E = encoder.transform(X)
    assert np.allclose(E, 1.0)
    np.testing.assert_allclose(encoder.inverse_transform(E), _wrap(X), atol=1e-12)


def test_transform_copies_the_other_channels_without_a_temporary():
    # all channels but the root's, gathered at once, were a second output
    walker = make_walker(n_sequences=8, n_frames=5000, random_state=0)
    E = ExpMapEncoder(walker.skeleton).fit_transform(walker.data)
    encoder = RootRelativeEncoder(walker.skeleton).fit(E)
    tracemalloc.start()
    try:
        base, _ = tracemalloc.get_traced_memory()
        Z = encoder.transform(E)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak - base < 1.7 * Z.nbytes  # the output, and the root's few columns
