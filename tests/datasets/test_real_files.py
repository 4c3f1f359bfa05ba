"""Other people's mocap files (``../shared/data/external_dev``), checked
against an independent BVH reader.

The reader is the ``bvh`` package from PyPI (a small pure-Python parser)
with rotations from :mod:`scipy.spatial.transform` and forward kinematics
written here from the BVH format as pybvh, bvhio, bvhtoolbox and Blender read
it: a joint sits at its parent's position plus the parent's rotation applied
to its offset, and the joint's position channels replace the matching
components of its OFFSET.  Nothing here uses the package's own parsing,
rotations or forward kinematics.
"""

from pathlib import Path

import numpy as np
import pytest
from bvh import Bvh
from scipy.spatial.transform import Rotation

from sklearn_crbm.datasets import Skeleton, read_amc, read_bvh, write_bvh

BVH_FILES = [
    "pybvh/bvh_example.bvh",
    "pybvh/bvh_test2.bvh",
    "pybvh/bvh_test3.bvh",
    "pybvh/cmu_12_01_walk.bvh",
    "pybvh/full_precision_frame_time.bvh",
    "pybvh/rotation_first_root.bvh",  # rotation channels before position
    "pybvh/standard_skeleton.bvh",  # one frame
    "cmu_bvh_bvh11/131_01.bvh",
    "cmu_bvh_bvh11/131_03.bvh",
    "bandai_namco/dataset-1_walk_normal_001.bvh",  # position channels everywhere
    "bandai_namco/dataset-2_run_active_001.bvh",
    "bandai_walk_normal_train/dataset-2_walk_normal_001.bvh",
]
ASF_AMC_FILES = [
    ("cmu_asfamc_gsimchoni/backflip.asf", "cmu_asfamc_gsimchoni/backflip.amc"),
    ("cmu_asfamc_gsimchoni/charleston.asf", "cmu_asfamc_gsimchoni/charleston1.amc"),
    ("cmu_subject35/35.asf", "cmu_subject35/35_01.amc"),
]
N_FRAMES = 40  # frames written per file: enough motion, a fast test


def _parse(path):
    # the parser drops a last line that has no line break
    return Bvh(Path(path).read_text() + "\n")


def independent_positions(path):
    """``{joint name: positions (n_frames, 3)}`` of a BVH file, end sites
    named ``"{joint}_end"``, computed without the package."""
    mocap = _parse(path)
    frames = np.array(mocap.frames, dtype=np.float64).reshape(mocap.nframes, -1)
    n_frames, start = len(frames), 0
    positions, rotations = {}, {}
    for joint in mocap.get_joints():
        channels = joint["CHANNELS"][1:]
        values = frames[:, start : start + len(channels)]
        start += len(channels)
        offset = np.tile(np.array(joint["OFFSET"], dtype=np.float64), (n_frames, 1))
        angles, axes = [], ""
        for k, channel in enumerate(channels):
            if channel.endswith("position"):
                offset[:, "XYZ".index(channel[0])] = values[:, k]
            else:
                angles.append(values[:, k])
                axes += channel[0]
        # upper-case axes: intrinsic rotations, R = R1 R2 R3 in file order
        local = (
            Rotation.from_euler(axes, np.column_stack(angles), degrees=True)
            if axes
            else Rotation.identity(n_frames)
        )
        parent = mocap.joint_parent(joint.name)
        if parent is None:
            positions[joint.name], rotations[joint.name] = offset, local
        else:
            origin, turn = positions[parent.name], rotations[parent.name]
            positions[joint.name] = origin + turn.apply(offset)
            rotations[joint.name] = turn * local
        for end in joint.filter("End"):
            tip = np.array(end["OFFSET"], dtype=np.float64)
            positions[f"{joint.name}_end"] = positions[joint.name] + rotations[
                joint.name
            ].apply(np.tile(tip, (n_frames, 1)))
    return positions


def assert_same_positions(skeleton, positions, expected, atol):
    """``positions`` (the package's, per bone) equal ``expected`` (a dict)."""
    assert set(skeleton.bone_names) == set(expected)
    for i, name in enumerate(skeleton.bone_names):
        np.testing.assert_allclose(
            positions[:, i], expected[name], rtol=0, atol=atol, err_msg=name
        )


@pytest.fixture(scope="module")
def external_dev(data_home):
    return data_home / "external_dev"


@pytest.mark.parametrize("name", BVH_FILES)
def test_forward_kinematics_agrees_with_an_independent_reader(external_dev, name):
    skeleton, data, _, _ = read_bvh(external_dev / name)
    expected = independent_positions(external_dev / name)
    assert_same_positions(
        skeleton, skeleton.forward_kinematics(data), expected, atol=1e-9
    )


@pytest.mark.parametrize("name", BVH_FILES)
def test_written_bvh_opens_in_an_independent_reader(tmp_path, external_dev, name):
    skeleton, data, _, frame_rate = read_bvh(external_dev / name)
    data = data[:N_FRAMES]
    write_bvh(tmp_path / "out.bvh", data, skeleton, frame_rate)
    expected = independent_positions(tmp_path / "out.bvh")
    assert_same_positions(
        skeleton, skeleton.forward_kinematics(data), expected, atol=1e-9
    )
    mocap = _parse(tmp_path / "out.bvh")
    for joint in mocap.get_joints():  # Blender reads 0 or 3 rotation channels
        rotations = [c for c in mocap.joint_channels(joint.name) if "rotation" in c]
        assert len(rotations) == 3, joint.name


@pytest.mark.parametrize(("asf", "amc"), ASF_AMC_FILES)
def test_asf_amc_written_as_bvh_opens_in_an_independent_reader(
    tmp_path, data_home, external_dev, asf, amc
):
    folder = data_home if asf.startswith("cmu_subject35") else external_dev
    skeleton = Skeleton.from_asf(folder / asf)
    data, _ = read_amc(folder / amc, skeleton)
    data = data[::10][:N_FRAMES]  # the backflip turns over within 400 frames
    write_bvh(tmp_path / "out.bvh", data, skeleton, 12.0)
    joints = independent_positions(tmp_path / "out.bvh")
    # an ASF bone's position is its end: where its first child joint, or its
    # end site, is in the BVH file
    expected = {
        name: joints[
            name if name == "root" else (skeleton.children(name) or [f"{name}_end"])[0]
        ]
        for name in skeleton.bone_names
    }
    assert_same_positions(
        skeleton, skeleton.forward_kinematics(data), expected, atol=1e-9
    )


def test_bandai_hips_written_as_root_opens_everywhere(tmp_path, external_dev):
    # the Bandai root is a ground marker above a moving Hips joint; tools that
    # read position channels on the root only need Hips as the ROOT
    name = "bandai_namco/dataset-2_run_active_001.bvh"
    skeleton, data, _, frame_rate = read_bvh(external_dev / name)
    positions = skeleton.forward_kinematics(data[:N_FRAMES])
    write_bvh(tmp_path / "out.bvh", data[:N_FRAMES], skeleton, frame_rate, root="Hips")
    mocap = _parse(tmp_path / "out.bvh")
    assert mocap.get_joints_names()[0] == "Hips"
    moving = [
        joint
        for joint in mocap.get_joints_names()
        if any("position" in c for c in mocap.joint_channels(joint))
    ]
    assert moving == ["Hips"]  # the constant position channels became OFFSETs
    joints = independent_positions(tmp_path / "out.bvh")
    assert set(joints) == set(skeleton.bone_names) - {"joint_Root"}
    for name, expected in joints.items():
        np.testing.assert_allclose(
            positions[:, skeleton.bone_names.index(name)],
            expected,
            rtol=0,
            atol=1e-9,
            err_msg=name,
        )
