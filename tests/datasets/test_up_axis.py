"""The up axis: detected from the poses, kept through write and read, and
warned about when an explicit setting disagrees."""

import warnings

import numpy as np
import pytest
import sklearn

from sklearn_crbm.datasets import (
    Bone,
    Skeleton,
    load_mit_walk,
    make_walker,
    read_amc,
    read_bvh,
    write_bvh,
)
from sklearn_crbm.preprocessing import make_motion_preprocessor

# The axis Blender 5.0's BVH importer needs as "Up" for each body to stand
# upright (measured by importing every file with Up=Y and with Up=Z and
# finding the axis its legs and spine spread along in Blender's world).  The
# other files of external_dev and every Bandai walk need Y.
Z_UP = {"pybvh/bvh_example.bvh", "pybvh/bvh_test3.bvh", "pybvh/standard_skeleton.bvh"}
ASF_AMC = [("backflip.asf", "backflip.amc"), ("charleston.asf", "charleston1.amc")]


@pytest.fixture(autouse=True)
def no_warnings():
    """Reading real files must not warn: the detected axis is the right one."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def _bvh_files(data_home):
    folder = data_home / "external_dev"
    paths = sorted(folder.glob("*/*.bvh"))
    assert len(paths) == 23
    return {str(p.relative_to(folder)): p for p in paths}


def test_every_external_file_gets_the_axis_blender_needs(data_home):
    for name, path in _bvh_files(data_home).items():
        skeleton, data, _, _ = read_bvh(path)
        expected = "z" if name in Z_UP else "y"
        assert skeleton.up_axis == expected, name
        assert skeleton.detect_up_axis(data) == expected, name
    for asf, amc in ASF_AMC:
        folder = data_home / "external_dev" / "cmu_asfamc_gsimchoni"
        skeleton = Skeleton.from_asf(folder / asf)
        data, _ = read_amc(folder / amc, skeleton)
        assert skeleton.up_axis == skeleton.detect_up_axis(data) == "y", asf


def test_every_bandai_walk_is_y_up(data_home):
    paths = sorted((data_home / "bandai_walk_styles").glob("*.bvh"))
    assert len(paths) == 42
    for path in paths:
        assert read_bvh(path)[0].up_axis == "y", path.name


def test_a_rest_pose_of_stacked_position_channels_cannot_tell(data_home):
    """Bandai files place every joint by position channels: their rest pose
    (every channel 0) is a single point, so only the motion tells."""
    path = _bvh_files(data_home)["bandai_namco/dataset-1_walk_normal_001.bvh"]
    skeleton, data, _, _ = read_bvh(path)
    assert skeleton.detect_up_axis() is None
    assert Skeleton.from_bvh(path).up_axis == "y"  # the default
    # a file whose root stands a y-up rest pose on the z axis is z up
    path = _bvh_files(data_home)["pybvh/bvh_test3.bvh"]
    skeleton, data, _, _ = read_bvh(path)
    assert (skeleton.detect_up_axis(), skeleton.detect_up_axis(data)) == ("y", "z")


@pytest.mark.parametrize("name", sorted(Z_UP) + ["cmu_bvh_bvh11/131_01.bvh"])
def test_the_axis_survives_write_and_read(data_home, tmp_path, name):
    skeleton, data, _, rate = read_bvh(_bvh_files(data_home)[name])
    write_bvh(tmp_path / "out.bvh", data, skeleton, rate)
    first = (tmp_path / "out.bvh").read_text().splitlines()[0]
    assert first == f"HIERARCHY # sklearn_crbm up_axis {skeleton.up_axis}"
    assert read_bvh(tmp_path / "out.bvh")[0].up_axis == skeleton.up_axis
    assert Skeleton.from_bvh(tmp_path / "out.bvh").up_axis == skeleton.up_axis


def test_mit_data_stays_z_up_through_a_bvh_file(data_home, tmp_path):
    mit = load_mit_walk(data_home)
    write_bvh(tmp_path / "mit.bvh", mit.data[:50], mit.skeleton, mit.frame_rate)
    assert read_bvh(tmp_path / "mit.bvh")[0].up_axis == "z"


def test_the_comment_changes_nothing_else(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=20, random_state=0)
    write_bvh(tmp_path / "walk.bvh", walker.data, walker.skeleton, 30.0)
    lines = (tmp_path / "walk.bvh").read_text().splitlines(keepends=True)
    (tmp_path / "plain.bvh").write_text("HIERARCHY\n" + "".join(lines[1:]))
    with_comment, plain = (
        read_bvh(tmp_path / "walk.bvh"),
        read_bvh(tmp_path / "plain.bvh"),
    )
    assert with_comment[0].bone_names == plain[0].bone_names
    np.testing.assert_array_equal(with_comment[1], plain[1])


def test_a_declared_axis_wins_but_a_wrong_one_warns(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=20, random_state=0)
    walker.skeleton.up_axis = "x"
    write_bvh(tmp_path / "walk.bvh", walker.data, walker.skeleton, 30.0)
    with pytest.warns(UserWarning, match=r"declares up axis 'x', but the body stands"):
        skeleton = read_bvh(tmp_path / "walk.bvh")[0]
    assert skeleton.up_axis == "x"


def test_an_explicit_axis_that_disagrees_warns_when_fitting(data_home):
    skeleton, data, _, _ = read_bvh(_bvh_files(data_home)["pybvh/bvh_example.bvh"])
    with sklearn.config_context(enable_metadata_routing=True):
        make_motion_preprocessor(skeleton).fit(data)
        make_motion_preprocessor(skeleton, up_axis="z").fit(data)
        with pytest.warns(UserWarning, match="sets up axis 'y'.*use up_axis='z'"):
            make_motion_preprocessor(skeleton, up_axis="y").fit(data)


def test_read_amc_warns_when_the_skeleton_says_another_axis(data_home):
    folder = data_home / "cmu_subject35"
    skeleton = Skeleton.from_asf(folder / "35.asf")
    skeleton.up_axis = "z"
    with pytest.warns(UserWarning, match="has up axis 'z', but the body stands"):
        read_amc(folder / "35_01.amc", skeleton)


def test_a_skeleton_without_branches_stands_along_its_length():
    bones = [
        Bone("root", None, [0, 0, 0], 0.0, channels=["tx", "ty", "tz"]),
        Bone("a", "root", [0, 0, 5], 5.0),
        Bone("b", "a", [0, 0, 5], 5.0),
    ]
    skeleton = Skeleton(bones, convention="bvh")
    assert skeleton.detect_up_axis() == "z"
