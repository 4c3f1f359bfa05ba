"""Frame rates (resample_frames) and reading folders of motion files."""

import shutil

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import (
    Skeleton,
    load_cmu35,
    make_walker,
    read_amc,
    read_amc_folder,
    read_bvh,
    read_bvh_folder,
    resample_frames,
    write_amc,
    write_bvh,
)


# ------------------------------------------------------------ frame rates
def test_resample_frames_keeps_every_kth_frame_of_each_sequence():
    X = np.arange(20.0).reshape(10, 2)
    ids = np.array([3, 3, 3, 3, 3, 7, 7, 7, 7, 7])
    X2, ids2 = resample_frames(X, ids, frame_rate=120, target_rate=60, sequence_ids=ids)
    # each sequence restarts at its own first frame: rows 0, 2, 4 and 5, 7, 9
    assert_array_equal(X2[:, 0], [0, 4, 8, 10, 14, 18])
    assert_array_equal(ids2, [3, 3, 3, 7, 7, 7])
    assert_array_equal(resample_frames(X, frame_rate=120, target_rate=30), X[::4])
    assert_array_equal(resample_frames(X, frame_rate=30, target_rate=30), X)


def test_resample_frames_uneven_ratio_keeps_the_nearest_frames():
    # 25 -> 10 frames per second: times 0, 0.1, 0.2 ... fall on frames
    # 0, 2.5, 5, 7.5, 10, 12.5; the nearest frames (ties to even) are kept
    kept = resample_frames(np.arange(14), frame_rate=25, target_rate=10)
    assert_array_equal(kept, [0, 2, 5, 8, 10, 12])


def test_resample_frames_takes_rounded_frame_times_as_whole_ratios():
    # "Frame Time: 0.008333" is 120.0048 Hz; 30 Hz still keeps every 4th frame
    frames = np.arange(100_000)
    kept = resample_frames(frames, frame_rate=1 / 0.008333, target_rate=30)
    assert_array_equal(kept, frames[::4])


def test_resample_frames_checks_its_input():
    X = np.zeros((6, 2))
    with pytest.raises(ValueError, match="up to 60 by dropping frames"):
        resample_frames(X, frame_rate=30, target_rate=60)
    with pytest.raises(ValueError, match="target_rate must be positive"):
        resample_frames(X, frame_rate=30, target_rate=0)
    with pytest.raises(ValueError, match="frame_rate must be positive"):
        resample_frames(X, frame_rate="120", target_rate=30)
    with pytest.raises(ValueError, match="inconsistent numbers of samples"):
        resample_frames(X, np.zeros(5), frame_rate=120, target_rate=30)
    with pytest.raises(ValueError, match="more than one contiguous run"):
        resample_frames(
            X, frame_rate=120, target_rate=30, sequence_ids=[0, 0, 1, 1, 0, 0]
        )
    with pytest.raises(ValueError, match="at least one array"):
        resample_frames(frame_rate=120, target_rate=30)


# ---------------------------------------------------------------- folders
@pytest.fixture(scope="module")
def bandai_train(data_home):
    return data_home / "external_dev" / "bandai_walk_normal_train"


def test_read_bvh_folder_stacks_the_files_in_order(bandai_train):
    walks = read_bvh_folder(bandai_train)
    paths = sorted(bandai_train.glob("*.bvh"))
    assert len(paths) == 12
    assert list(walks.sequence_names) == [p.stem for p in paths]
    assert list(walks.filenames) == [str(p) for p in paths]
    for k, path in enumerate(paths):
        skeleton, data, names, frame_rate = read_bvh(path)
        assert_array_equal(walks.data[walks.sequence_ids == k], data)
        assert walks.skeletons[k].bone_names == skeleton.bone_names
    assert_array_equal(walks.feature_names, names)
    assert walks.skeleton is walks.skeletons[0]
    assert walks.frame_rate == pytest.approx(30.0, rel=1e-5)
    # to 15 Hz: every other frame of each file, from its first
    slow = read_bvh_folder(bandai_train, frame_rate=15.0)
    assert slow.frame_rate == 15.0
    for k in range(12):
        assert_array_equal(
            slow.data[slow.sequence_ids == k], walks.data[walks.sequence_ids == k][::2]
        )


def test_read_bvh_folder_brings_files_to_a_common_rate(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=12, random_state=0)
    write_bvh(tmp_path / "a.bvh", walker.data, walker.skeleton, 120.0)
    write_bvh(tmp_path / "b.bvh", walker.data, walker.skeleton, 60.0)
    # as many files one way as the other: the faster is the odd one
    with pytest.raises(
        ValueError, match=r"a\.bvh has 120 frames per second.*frame_rate=60"
    ):
        read_bvh_folder(tmp_path)
    with pytest.warns(UserWarning, match="every 4th frame of a.bvh"):
        both = read_bvh_folder(tmp_path, frame_rate=30.0)
    assert np.bincount(both.sequence_ids).tolist() == [3, 6]


def test_read_bvh_folder_patterns_and_errors(tmp_path, data_home):
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    (tmp_path / "sub").mkdir()
    write_bvh(tmp_path / "sub" / "w.bvh", walker.data, walker.skeleton, 30.0)
    with pytest.raises(FileNotFoundError, match="matches '\\*.bvh'"):
        read_bvh_folder(tmp_path)
    assert list(read_bvh_folder(tmp_path, pattern="**/*.bvh").sequence_names) == [
        "sub/w"
    ]
    with pytest.raises(FileNotFoundError, match="is not a folder"):
        read_bvh_folder(tmp_path / "missing")
    with pytest.raises(TypeError, match="path of a folder"):
        read_bvh_folder(3)
    # files of different skeletons cannot share the columns of one data set
    with pytest.raises(ValueError, match="different channels"):
        read_bvh_folder(data_home / "external_dev" / "pybvh")


def test_read_amc_folder_is_the_papers_30_hz_data(data_home):
    # GPmat's cmu35WalkJog.mat holds every 4th frame of 35_01.amc
    cmu = read_amc_folder(data_home / "cmu_subject35", frame_rate=30.0)
    paper = load_cmu35(data_home, subset="train")
    assert list(cmu.sequence_names) == ["35_01"]
    assert cmu.frame_rate == 30.0
    assert_array_equal(cmu.data, paper.data[paper.sequence_ids == 0])
    assert_array_equal(cmu.feature_names, paper.feature_names)


def test_read_amc_folder_pairs_each_amc_with_its_asf(data_home, tmp_path):
    folder = data_home / "external_dev" / "cmu_asfamc_gsimchoni"
    motions = read_amc_folder(folder)
    assert list(motions.sequence_names) == ["backflip", "charleston1"]
    assert motions.frame_rate == 120.0
    for k, (asf, amc) in enumerate(
        [("backflip.asf", "backflip.amc"), ("charleston.asf", "charleston1.amc")]
    ):
        skeleton = Skeleton.from_asf(folder / asf)
        data, _ = read_amc(folder / amc, skeleton)
        assert_array_equal(motions.data[motions.sequence_ids == k], data)
        assert [b.length for b in motions.skeletons[k].bones] == [
            b.length for b in skeleton.bones
        ]
    # one skeleton for all files, given as a path
    shared = read_amc_folder(folder, folder / "charleston.asf", amc_frame_rate=60)
    assert shared.skeletons[0] is shared.skeletons[1]
    assert shared.frame_rate == 60.0
    # an AMC file without an ASF file to go with it
    shutil.copy(folder / "backflip.asf", tmp_path / "backflip.asf")
    shutil.copy(folder / "backflip.asf", tmp_path / "other.asf")
    skeleton = Skeleton.from_asf(folder / "backflip.asf")
    write_amc(tmp_path / "zombie.amc", np.zeros((2, 62)), skeleton)
    with pytest.raises(FileNotFoundError, match="No ASF file for .*zombie.amc"):
        read_amc_folder(tmp_path)
