"""The default preprocessing on other people's mocap files (``external_dev``).

Every BVH and ASF/AMC file of ``../shared/data/external_dev`` (see its
README: Bandai Namco, CMU BVH conversions, pybvh's fixtures, a CMU backflip)
goes through ``make_motion_preprocessor(skeleton)`` and back: the joint
rotations and the forward kinematics must come back exactly, up to the
documented start pose of the root (heading 0, ground position (0, 0)).
"""

import warnings

import numpy as np
import pytest

from sklearn_crbm.datasets import Skeleton, read_amc, read_bvh
from sklearn_crbm.preprocessing import ExpMapEncoder, make_motion_preprocessor
from sklearn_crbm.utils._rotations import expmap_to_matrix

ASF_AMC = [("backflip.asf", "backflip.amc"), ("charleston.asf", "charleston1.amc")]


def _read(path):
    if path.suffix == ".bvh":
        skeleton, data, _, _ = read_bvh(path)
        return skeleton, data
    asf = dict((amc, asf) for asf, amc in ASF_AMC)[path.name]
    skeleton = Skeleton.from_asf(path.with_name(asf))
    return skeleton, read_amc(path, skeleton)[0]


@pytest.fixture(scope="module")
def files(data_home):
    """``{relative path: (skeleton, data)}`` for every file of the set."""
    folder = data_home / "external_dev"
    paths = sorted(folder.glob("*/*.bvh"))
    paths += [folder / "cmu_asfamc_gsimchoni" / amc for _, amc in ASF_AMC]
    assert len(paths) >= 25
    return {str(p.relative_to(folder)): _read(p) for p in paths}


def _rotation_error_deg(A, B):
    """Angle (degrees) of ``A^T B``, accurate near 0 (unlike arccos of the trace)."""
    chord = np.linalg.norm(A - B, axis=(-2, -1)) / np.sqrt(8.0)
    return np.rad2deg(2.0 * np.arcsin(np.clip(chord, 0.0, 1.0)))


def round_trip_errors(skeleton, data, **params):
    """Max joint-rotation error (degrees) and position error (file units) of the
    default preprocessing's round trip, once the start pose is aligned."""
    pre = make_motion_preprocessor(skeleton, **params)
    back = pre.inverse_transform(pre.fit_transform(data))
    root = skeleton.bone_names.index(pre.named_steps["root"].root_)
    joints = np.delete(np.arange(len(skeleton.bones)), root)
    local, local_back = (skeleton.local_rotations(x)[:, joints] for x in (data, back))
    joint_error = _rotation_error_deg(local, local_back).max(initial=0.0)
    glob, glob_back = (skeleton.global_rotations(x)[:, root] for x in (data, back))
    # the start pose: a rotation about the vertical and a ground-plane shift
    up = "xyz".index(pre.named_steps["root"].up_axis_)
    turn = glob[0] @ glob_back[0].T
    assert np.allclose(turn[:, up], np.eye(3)[up], atol=1e-12)
    root_error = _rotation_error_deg(glob, turn @ glob_back).max()
    # the body: the root and the bones below it (not a static bone above it)
    body = [
        skeleton.bone_names.index(b)
        for b in skeleton.descendants(skeleton.bone_names[root])
    ]
    positions, positions_back = (
        skeleton.forward_kinematics(x)[:, body] for x in (data, back)
    )
    start, start_back = positions[0, 0], positions_back[0, 0]
    aligned = (positions_back - start_back) @ turn.T + start
    return max(joint_error, root_error), np.abs(aligned - positions).max()


def test_default_round_trip_is_exact_on_every_file(files):
    errors = {}
    with warnings.catch_warnings():
        # pybvh's bvh_test3 is z-up and read as y-up: it warns, and round-trips
        warnings.filterwarnings("ignore", "The root's forward axis")
        for name, (skeleton, data) in files.items():
            errors[name] = round_trip_errors(skeleton, data)
    bad = {n: e for n, e in errors.items() if not (e[0] < 1e-9 and e[1] < 1e-9)}
    assert not bad, f"round trip (degrees, units) not exact: {bad}"


def test_z_up_files_round_trip_with_their_up_axis(files):
    # pybvh's z-up files: the character stands along z (two of them in their
    # rest pose, bvh_test3 through its root rotation)
    for name in ["bvh_example.bvh", "standard_skeleton.bvh", "bvh_test3.bvh"]:
        skeleton, data = files[f"pybvh/{name}"]
        positions = skeleton.forward_kinematics(data)
        height = np.ptp(positions[0], axis=0)
        assert np.argmax(height) == 2 or name == "standard_skeleton.bvh", name
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            rotation_error, position_error = round_trip_errors(
                skeleton, data, up_axis="z"
            )
        assert rotation_error < 1e-9 and position_error < 1e-9, name


def test_the_papers_encoding_mirrors_the_backflip_and_says_so(files):
    skeleton, data = files["cmu_asfamc_gsimchoni/backflip.amc"]
    with pytest.warns(UserWarning, match=r"cannot encode frames \d+, .*mirrored"):
        rotation_error, position_error = round_trip_errors(
            skeleton, data, roll="taylor", reference="rest"
        )
    # the paper's roll loses the upside-down frames (the issue: up to 178 degrees)
    assert rotation_error > 90.0 and position_error > 5.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rotation_error, position_error = round_trip_errors(skeleton, data)
    assert rotation_error < 1e-9 and position_error < 1e-9


def test_root_channels_are_named_after_the_skeletons_root(files):
    expected = {
        # a static joint_Root at the origin above the moving Hips
        "bandai_namco/dataset-1_walk_normal_001.bvh": "Hips",
        "pybvh/bvh_test2.bvh": "Hips",
        "cmu_asfamc_gsimchoni/charleston1.amc": "root",
    }
    for name, root in expected.items():
        skeleton, data = files[name]
        pre = make_motion_preprocessor(skeleton).fit(data)
        assert pre.named_steps["root"].root_ == root
        names = list(pre.named_steps["root"].get_feature_names_out())
        suffixes = ["pitch", "roll", "dheading", "dforward", "dsideways", "height"]
        first = names.index(f"{root}_pitch")
        assert names[first : first + 6] == [f"{root}_{s}" for s in suffixes]


def test_a_one_frame_file_inverts(files):
    skeleton, data = files["pybvh/standard_skeleton.bvh"]
    assert data.shape[0] == 1
    pre = make_motion_preprocessor(skeleton)
    Z = pre.fit_transform(data)
    assert Z.shape == (1, 0)  # every channel is constant
    back = pre.inverse_transform(Z)
    assert back.shape == data.shape
    assert np.allclose(skeleton.local_rotations(back), skeleton.local_rotations(data))


def _flips(skeleton, data, reference):
    """Frames where a joint's exponential map jumps by more than 1 radian while
    its rotation moves by less than 1 radian (chordal), summed over joints."""
    encoder = ExpMapEncoder(skeleton, reference=reference).fit(data)
    Z = encoder.transform(data)
    root = make_motion_preprocessor(skeleton).fit(data).named_steps["root"].root_
    starts = [
        i
        for i, n in enumerate(encoder.get_feature_names_out())
        if n.endswith("_ex") and not n.startswith(f"{root}_")
    ]
    maps = np.stack([Z[:, i : i + 3] for i in starts], axis=1)
    step = np.linalg.norm(np.diff(maps, axis=0), axis=-1)
    turn = np.linalg.norm(np.diff(expmap_to_matrix(maps), axis=0), axis=(-2, -1))
    return int(np.sum((step > 1.0) & (turn < 1.0)))


@pytest.mark.filterwarnings("ignore:The root's forward axis")
def test_default_exponential_maps_do_not_flip_in_walks_and_runs(files):
    bandai = [n for n in files if n.startswith("bandai")]
    assert len(bandai) == 14
    # measured from the rest pose, a Bandai thigh sits near pi and its map flips
    assert sum(_flips(*files[n], "rest") for n in bandai) > 100
    for name, (skeleton, data) in files.items():
        if "backflip" not in name:  # a flip in which a foot turns by ~pi
            assert _flips(skeleton, data, "mean") == 0, name


def test_a_wrong_up_axis_is_reported(files):
    skeleton, data = files["pybvh/bvh_test3.bvh"]  # z up, and read as z up
    assert skeleton.up_axis == "z"
    with pytest.warns(UserWarning, match="try up_axis='z'"):
        with pytest.warns(UserWarning, match="sets up axis 'y', but the body"):
            make_motion_preprocessor(skeleton, up_axis="y").fit(data)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        make_motion_preprocessor(skeleton).fit(data)
        make_motion_preprocessor(skeleton, up_axis="z").fit(data)
