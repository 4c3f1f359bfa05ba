"""Skeleton: construction from ASF and MIT, lookups, forward kinematics."""

import numpy as np
import pytest

from sklearn_crbm.datasets import Bone, Skeleton, load_mit_walk, read_amc
from sklearn_crbm.datasets._mit import MIT_BONE_NAMES

# The 62 channels of cmu35WalkJog.mat, from the data README (ASF bone order).
CMU35_CHANNELS = (
    ["root_tx", "root_ty", "root_tz", "root_rx", "root_ry", "root_rz"]
    + ["lfemur_rx", "lfemur_ry", "lfemur_rz", "ltibia_rx", "lfoot_rx", "lfoot_rz"]
    + ["ltoes_rx", "rfemur_rx", "rfemur_ry", "rfemur_rz", "rtibia_rx", "rfoot_rx"]
    + ["rfoot_rz", "rtoes_rx"]
    + [
        f"{bone}_{c}"
        for bone in [
            "lowerback",
            "upperback",
            "thorax",
            "lowerneck",
            "upperneck",
            "head",
        ]
        for c in ["rx", "ry", "rz"]
    ]
    + ["lclavicle_ry", "lclavicle_rz", "lhumerus_rx", "lhumerus_ry", "lhumerus_rz"]
    + ["lradius_rx", "lwrist_ry", "lhand_rx", "lhand_rz", "lfingers_rx"]
    + ["lthumb_rx", "lthumb_rz"]
    + ["rclavicle_ry", "rclavicle_rz", "rhumerus_rx", "rhumerus_ry", "rhumerus_rz"]
    + ["rradius_rx", "rwrist_ry", "rhand_rx", "rhand_rz", "rfingers_rx"]
    + ["rthumb_rx", "rthumb_rz"]
)


@pytest.fixture(scope="module")
def cmu_skeleton(data_home):
    return Skeleton.from_asf(data_home / "cmu_subject35" / "35.asf")


@pytest.fixture(scope="module")
def cmu_trial(data_home, cmu_skeleton):
    data, _ = read_amc(data_home / "cmu_subject35" / "35_01.amc", cmu_skeleton)
    return data


def _bone_vectors(skeleton, positions):
    """Vector from each non-root bone's parent position to its own position."""
    parents = skeleton.parent_indices
    return positions[:, 1:] - positions[:, parents[1:]]


def test_from_asf_reads_cmu_skeleton(cmu_skeleton):
    sk = cmu_skeleton
    assert sk.name == "35"
    assert len(sk.bones) == 31
    assert sk.bones[0].name == "root"
    assert list(sk.feature_names) == CMU35_CHANNELS
    assert sk.feature_names.dtype == object
    assert (sk.up_axis, sk.angle_unit, sk.length_scale) == ("y", "deg", 0.45)
    assert sk.convention == "acclaim"
    root = sk.bone("root")
    assert root.channels == ("tx", "ty", "tz", "rx", "ry", "rz")
    assert root.rotation_order == "xyz"
    assert root.length == 0.0
    lfemur = sk.bone("lfemur")
    assert lfemur.parent == "lhipjoint"
    np.testing.assert_allclose(lfemur.axis, [0, 0, 20])
    assert lfemur.axis_order == "xyz"
    np.testing.assert_allclose(lfemur.direction, [0.34202, -0.939693, 0], atol=1e-6)
    assert lfemur.length == pytest.approx(7.41015)
    lfoot = sk.bone("lfoot")
    assert (lfoot.channels, lfoot.rotation_order) == (("rx", "rz"), "xz")
    assert sk.bone("lhipjoint").channels == ()
    assert sk.bone("lhipjoint").rotation_order == ""
    assert sk.children("thorax") == ["lowerneck", "lclavicle", "rclavicle"]
    assert sk.children("ltoes") == []


def test_parents_come_before_children(cmu_skeleton):
    parents = cmu_skeleton.parent_indices
    assert parents[0] == -1
    assert np.all(parents[1:] < np.arange(1, len(parents)))


def test_unknown_bone_is_a_value_error_naming_it(cmu_skeleton):
    with pytest.raises(ValueError, match="no bone 'tail'"):
        cmu_skeleton.bone("tail")
    with pytest.raises(ValueError, match="no bone 'tail'"):
        cmu_skeleton.children("tail")


def test_rest_pose_is_the_sum_of_bone_offsets(cmu_skeleton):
    zeros = np.zeros((1, len(cmu_skeleton.feature_names)))
    positions = cmu_skeleton.forward_kinematics(zeros)[0]
    for i, bone in enumerate(cmu_skeleton.bones[1:], start=1):
        parent = cmu_skeleton.parent_indices[i]
        np.testing.assert_allclose(
            positions[i], positions[parent] + bone.offset, atol=1e-12
        )


def test_fk_preserves_bone_lengths_at_every_frame(cmu_skeleton, cmu_trial):
    positions = cmu_skeleton.forward_kinematics(cmu_trial)
    assert positions.shape == (358, 31, 3)
    lengths = np.linalg.norm(_bone_vectors(cmu_skeleton, positions), axis=-1)
    expected = [bone.length for bone in cmu_skeleton.bones[1:]]
    np.testing.assert_allclose(
        lengths, np.broadcast_to(expected, lengths.shape), atol=1e-9
    )


def test_cmu_subject_stands_upright_at_frame_zero(cmu_skeleton, cmu_trial):
    positions = cmu_skeleton.forward_kinematics(cmu_trial[:1])[0]
    y = {name: positions[i, 1] for i, name in enumerate(cmu_skeleton.bone_names)}
    for foot in ("lfoot", "rfoot", "ltoes", "rtoes"):
        assert y["head"] > y[foot] + 20
    assert y["ltibia"] < y["lfemur"] < y["root"] < y["thorax"] < y["head"]
    np.testing.assert_allclose(positions[0], cmu_trial[0, :3])  # root at root_t*


def test_fk_uses_columns_by_name(cmu_skeleton, cmu_trial):
    rng = np.random.default_rng(0)
    order = rng.permutation(cmu_trial.shape[1])
    names = cmu_skeleton.feature_names[order]
    extra = np.column_stack([cmu_trial[:5, order], np.ones(5)])
    got = cmu_skeleton.forward_kinematics(extra, feature_names=[*names, "unused"])
    np.testing.assert_array_equal(got, cmu_skeleton.forward_kinematics(cmu_trial[:5]))


def test_fk_missing_channels_raise_naming_them(cmu_skeleton, cmu_trial):
    names = list(cmu_skeleton.feature_names)
    keep = [i for i, n in enumerate(names) if n not in ("lfemur_rx", "head_rz")]
    with pytest.raises(ValueError, match=r"lfemur_rx.*head_rz"):
        cmu_skeleton.forward_kinematics(cmu_trial[:, keep], [names[i] for i in keep])
    with pytest.raises(ValueError, match="62 feature names for data with 61 columns"):
        cmu_skeleton.forward_kinematics(cmu_trial[:, :61], names)
    with pytest.raises(ValueError, match="2-D"):
        cmu_skeleton.forward_kinematics(cmu_trial[0])


def _two_bone_skeleton(convention, **child):
    root = Bone("root", None, [0, 0, 0], 0.0, ("tx", "ty", "tz", "rz"), "z")
    arm = Bone("arm", "root", [1, 0, 0], 2.0, **child)
    hand = Bone("hand", "arm", [1, 0, 0], 1.0)
    return Skeleton([root, arm, hand], convention=convention)


def test_acclaim_bones_turn_with_their_own_rotation():
    sk = _two_bone_skeleton("acclaim", channels=("rz",), rotation_order="z")
    positions = sk.forward_kinematics([[1.0, 0.0, 0.0, 90.0, 90.0]])[0]
    # root turned 90 deg about z; the arm turns a further 90 deg and its end
    # lies 2 units along -x from the root; the hand follows the arm
    np.testing.assert_allclose(
        positions, [[1, 0, 0], [-1, 0, 0], [-2, 0, 0]], atol=1e-12
    )


def test_bvh_offsets_turn_with_the_parent_rotation():
    sk = _two_bone_skeleton("bvh", channels=("rz",), rotation_order="z")
    positions = sk.forward_kinematics([[1.0, 0.0, 0.0, 90.0, 90.0]])[0]
    # the arm joint sits at its offset turned by the root only; the arm's
    # rotation moves the hand
    np.testing.assert_allclose(positions, [[1, 0, 0], [1, 2, 0], [0, 2, 0]], atol=1e-12)


def test_asf_axis_pre_rotation_changes_the_rotation_axis():
    # with axis 90 deg about z, the bone's rx rotates about the global y axis
    sk = _two_bone_skeleton(
        "acclaim", channels=("rx",), rotation_order="x", axis=[0, 0, 90]
    )
    positions = sk.forward_kinematics([[0.0, 0.0, 0.0, 0.0, 90.0]])[0]
    np.testing.assert_allclose(positions[1], [0, 0, -2], atol=1e-12)


def test_euler_rotation_order_is_applied_first_to_last():
    bone = dict(channels=("rx", "rz"), rotation_order="xz")
    sk = _two_bone_skeleton("acclaim", **bone)
    # x then z: (1,0,0) is unchanged by x, then z turns it to (0,1,0)
    pos = sk.forward_kinematics([[0.0, 0.0, 0.0, 0.0, 90.0, 90.0]])[0]
    np.testing.assert_allclose(pos[1], [0, 2, 0], atol=1e-12)
    sk = _two_bone_skeleton("acclaim", channels=("rx", "rz"), rotation_order="zx")
    # z then x: (1,0,0) -> (0,1,0) -> (0,0,1)
    pos = sk.forward_kinematics([[0.0, 0.0, 0.0, 0.0, 90.0, 90.0]])[0]
    np.testing.assert_allclose(pos[1], [0, 0, 2], atol=1e-12)


def test_radians_skeleton():
    sk = _two_bone_skeleton("acclaim", channels=("rz",), rotation_order="z")
    sk.angle_unit = "rad"
    pos = sk.forward_kinematics([[0.0, 0.0, 0.0, 0.0, np.pi / 2]])[0]
    np.testing.assert_allclose(pos[1], [0, 2, 0], atol=1e-12)


def test_global_and_local_rotations(cmu_skeleton, cmu_trial):
    local = cmu_skeleton.local_rotations(cmu_trial[:3])
    glob = cmu_skeleton.global_rotations(cmu_trial[:3])
    assert local.shape == glob.shape == (3, 31, 3, 3)
    i = cmu_skeleton.bone_names.index("lfemur")
    parent = cmu_skeleton.parent_indices[i]
    np.testing.assert_allclose(glob[:, i], glob[:, parent] @ local[:, i], atol=1e-12)
    np.testing.assert_allclose(
        local @ np.swapaxes(local, -1, -2),
        np.broadcast_to(np.eye(3), local.shape),
        atol=1e-12,
    )


@pytest.mark.parametrize(
    "bones, message",
    [
        ([Bone("a", "root", [1, 0, 0], 1.0)], "must be the root"),
        (
            [Bone("root", None, [0, 0, 0], 0), Bone("root", "root", [1, 0, 0], 1)],
            "occurs twice",
        ),
        (
            [Bone("root", None, [0, 0, 0], 0), Bone("b", "a", [1, 0, 0], 1)],
            "before its parent",
        ),
        ([], "at least one bone"),
    ],
)
def test_invalid_skeletons(bones, message):
    with pytest.raises(ValueError, match=message):
        Skeleton(bones)


def test_invalid_bones_and_settings():
    with pytest.raises(ValueError, match="rotation_order"):
        Bone("a", None, [0, 0, 0], 0, ("rx", "ry"), "xz")
    with pytest.raises(ValueError, match="unknown channels"):
        Bone("a", None, [0, 0, 0], 0, ("l",))
    with pytest.raises(ValueError, match="exponential map"):
        Bone("a", None, [0, 0, 0], 0, ("ex", "ey"))
    root = [Bone("root", None, [0, 0, 0], 0)]
    with pytest.raises(ValueError, match="angle_unit"):
        Skeleton(root, angle_unit="grad")
    with pytest.raises(ValueError, match="up_axis"):
        Skeleton(root, up_axis="w")
    with pytest.raises(ValueError, match="convention"):
        Skeleton(root, convention="fbx")


# ---------------------------------------------------------------------- MIT
@pytest.fixture(scope="module")
def mit(data_home):
    return load_mit_walk(data_home)


def test_from_mit_names_and_channels(mit, data_home):
    sk = mit.skeleton
    assert sk.bone_names == list(MIT_BONE_NAMES)
    assert (sk.up_axis, sk.angle_unit, sk.convention) == ("z", "rad", "bvh")
    assert sk.bone("root").channels == ("ex", "ey", "ez", "tx", "ty", "tz")
    assert sk.bone("lknee").channels == ("ex", "ey", "ez", "ox", "oy", "oz")
    assert [sk.bone(n).parent for n in ("lhip", "rhip", "spine")] == ["root"] * 3
    assert sk.children("spine") == ["lcollar", "rcollar"]
    # left is +y in the body frame (x forward, z up)
    assert sk.bone("lhip").direction[1] > 0.99 and sk.bone("rhip").direction[1] < -0.99
    assert sk.bone("lshoulder").direction[1] > 0.9
    from_path = Skeleton.from_mit(data_home / "taylor_mhmublv_mit" / "data.mat")
    np.testing.assert_allclose(
        [b.offset for b in from_path.bones], [b.offset for b in sk.bones]
    )


def test_mit_offsets_match_offset_columns(mit):
    sk = mit.skeleton
    for bone in sk.bones[1:]:
        cols = [list(mit.feature_names).index(f"{bone.name}_o{a}") for a in "xyz"]
        np.testing.assert_allclose(
            mit.data[:, cols], np.tile(bone.offset, (len(mit.data), 1))
        )


def test_mit_fk_upright_and_lengths(mit):
    sk = mit.skeleton
    positions = sk.forward_kinematics(mit.data[::50])
    lengths = np.linalg.norm(_bone_vectors(sk, positions), axis=-1)
    expected = [bone.length for bone in sk.bones[1:]]
    np.testing.assert_allclose(
        lengths, np.broadcast_to(expected, lengths.shape), rtol=1e-12
    )
    z = positions[..., 2]
    names = sk.bone_names
    for toe in ("ltoe", "rtoe"):
        assert np.all(z[:, names.index("lcollar")] > z[:, names.index(toe)] + 1000)
    # only rotation and translation columns are needed
    needed = [n for n in mit.feature_names if n[-2:] not in ("ox", "oy", "oz")]
    cols = [list(mit.feature_names).index(n) for n in needed]
    np.testing.assert_array_equal(
        sk.forward_kinematics(mit.data[::50][:, cols], needed), positions
    )


def test_from_mit_without_offsets_has_zero_lengths(data_home):
    import scipy.io

    skel = scipy.io.loadmat(data_home / "taylor_mhmublv_mit" / "data.mat")["skel"]
    sk = Skeleton.from_mit(skel)
    assert all(b.length == 0.0 for b in sk.bones)
    assert len(sk.feature_names) == 108


def test_skeleton_deepcopies_and_pickles(cmu_skeleton, cmu_trial):
    import copy
    import pickle

    expected = cmu_skeleton.forward_kinematics(cmu_trial[:3])
    for clone in (
        copy.deepcopy(cmu_skeleton),
        pickle.loads(pickle.dumps(cmu_skeleton)),
    ):
        assert clone.bone_names == cmu_skeleton.bone_names
        np.testing.assert_array_equal(clone.forward_kinematics(cmu_trial[:3]), expected)
    assert "n_bones=31" in repr(cmu_skeleton)


def test_public_names():
    import sklearn_crbm.datasets as datasets

    for name in datasets.__all__:
        assert getattr(datasets, name).__doc__
