"""Folders whose files disagree: which joint travels, up axis, skeleton, rate.

One odd file must not change the data of the others silently: it is
reconciled with a warning that names it, or refused with an error that does.
"""

import re
import shutil

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal

from sklearn_crbm.datasets import make_walker, read_bvh, read_bvh_folder, write_bvh
from sklearn_crbm.preprocessing import make_motion_preprocessor

DASH = "dataset-1_dash_normal_001.bvh"


def _two_joint_bvh(root_moves, frames=4):
    """A ground joint ``R`` above a pelvis ``H``, six channels each; either
    ``R`` travels along z (``H`` still) or ``H`` travels (``R`` still)."""
    rows = []
    for k in range(frames):
        travel = [0.5 * k, 0, 10.0 * k]
        turn = [5.0 * k, 2.0, 1.0]  # Zrotation Xrotation Yrotation
        still = [0, 0, 0, 0, 0, 0]
        hips = [1.0, 90.0 + 0.1 * k, 2.0, 3.0 * k, 1.0, -2.0]
        limbs = [10.0 * k, 0, 0, -5.0, 0, 0]  # Leg and Back
        if root_moves:
            rows.append(travel + turn + hips + limbs)
        else:
            moved = [h + t for h, t in zip(hips[:3], travel, strict=True)]
            rows.append(still + moved + hips[3:] + limbs)
    channels = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
    text = (
        f"HIERARCHY\nROOT R\n{{\n  OFFSET 0 0 0\n  {channels}\n  JOINT H\n  {{\n"
        f"    OFFSET 0 90 0\n    {channels}\n    JOINT Leg\n    {{\n"
        "      OFFSET 5 0 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "      End Site\n      {\n        OFFSET 0 -40 0\n      }\n    }\n"
        "    JOINT Back\n    {\n      OFFSET 0 20 0\n"
        "      CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "      End Site\n      {\n        OFFSET 0 30 0\n      }\n    }\n  }\n}\n"
        f"MOTION\nFrames: {frames}\nFrame Time: 0.0333333\n"
    )
    return text + "\n".join(" ".join(f"{v:g}" for v in row) for row in rows) + "\n"


def _columns(names, joint):
    return [i for i, name in enumerate(names) if name.startswith(f"{joint}_")]


def test_a_file_whose_ground_joint_travels_is_reconciled(tmp_path):
    for name, root_moves in (("a", False), ("b", False), ("odd", True)):
        (tmp_path / f"{name}.bvh").write_text(_two_joint_bvh(root_moves))
    with pytest.warns(UserWarning, match=r"odd\.bvh.*'R'.*'H'"):
        walks = read_bvh_folder(tmp_path)
    odd = walks.sequence_ids == 2
    assert np.ptp(walks.data[:, _columns(walks.feature_names, "R")], axis=0).max() == 0
    skeleton, data, _, _ = read_bvh(tmp_path / "odd.bvh")
    before = skeleton.forward_kinematics(data)[:, 1:]
    after = walks.skeleton.forward_kinematics(walks.data[odd])[:, 1:]
    assert_allclose(after, before, atol=1e-9)
    for k, name in enumerate(("a", "b")):
        assert_array_equal(
            walks.data[walks.sequence_ids == k], read_bvh(tmp_path / f"{name}.bvh")[1]
        )


def test_a_file_whose_pelvis_travels_below_a_travelling_root_is_refused(tmp_path):
    for name, root_moves in (("a", True), ("b", True), ("odd", False)):
        (tmp_path / f"{name}.bvh").write_text(_two_joint_bvh(root_moves))
    # the message names the files the others travel with, too
    with pytest.raises(
        ValueError, match=r"odd\.bvh.*'H', but with 'R' in 2 of the 3 files \(a\.bvh"
    ):
        read_bvh_folder(tmp_path)


def test_bandai_dash_in_a_folder_of_walks(data_home, tmp_path):
    shutil.copy(data_home / "odd_files" / DASH, tmp_path)
    for name in ("dataset-1_walk_normal_001.bvh", "dataset-2_run_active_001.bvh"):
        shutil.copy(data_home / "external_dev" / "bandai_namco" / name, tmp_path)
    with pytest.warns(UserWarning, match=f"{DASH}.*'joint_Root'.*'Hips'"):
        walks = read_bvh_folder(tmp_path)
    root = _columns(walks.feature_names, "joint_Root")
    assert np.ptp(walks.data[:, root], axis=0).max() == 0
    dash = walks.sequence_ids == 0
    skeleton, data, _, _ = read_bvh(tmp_path / DASH)
    before = skeleton.forward_kinematics(data)
    after = walks.skeleton.forward_kinematics(walks.data[dash])
    assert_allclose(after[:, 1:], before[:, 1:], atol=1e-6)
    hips = walks.data[dash][:, _columns(walks.feature_names, "Hips")[:3]]
    assert np.ptp(hips[:, 2]) > 250  # the dash's 273 units of travel, now the hips'
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(walks.skeleton)
        pre.fit(walks.data, sequence_ids=walks.sequence_ids)
    assert pre.named_steps["root"].root_ == "Hips"


def test_two_files_that_disagree_give_one_result_in_either_order(data_home, tmp_path):
    """One file travels with joint_Root, the other with Hips: whichever name
    sorts first, the dash's travel moves into Hips, with a warning naming both."""
    walk = data_home / "external_dev" / "bandai_namco" / "dataset-1_walk_normal_001.bvh"
    results = []
    for dash_name, walk_name in (("a_dash", "b_walk"), ("b_dash", "a_walk")):
        folder = tmp_path / dash_name
        folder.mkdir()
        shutil.copy(data_home / "odd_files" / DASH, folder / f"{dash_name}.bvh")
        shutil.copy(walk, folder / f"{walk_name}.bvh")
        with pytest.warns(UserWarning) as caught:
            both = read_bvh_folder(folder)
        (message,) = [str(w.message) for w in caught if "travels" in str(w.message)]
        assert re.search(
            rf"{dash_name}\.bvh: the body travels with joint 'joint_Root', but with "
            rf"'Hips' in 1 of the 2 files \({walk_name}\.bvh\)",
            message,
        )
        names = list(both.sequence_names)
        results.append(
            [
                both.data[both.sequence_ids == names.index(n)]
                for n in (dash_name, walk_name)
            ]
        )
    for first, second in zip(*results, strict=True):
        assert_array_equal(first, second)
    dash = results[0][0]
    assert np.ptp(dash[:, _columns(both.feature_names, "joint_Root")]) == 0


def _walker_file(path, up_axis="y", seed=0):
    walker = make_walker(n_sequences=1, n_frames=6, random_state=seed)
    walker.skeleton.up_axis = up_axis
    write_bvh(path, walker.data, walker.skeleton, 30.0)


def test_files_standing_along_another_up_axis_are_refused(tmp_path):
    _walker_file(tmp_path / "a.bvh")
    _walker_file(tmp_path / "b.bvh")
    with pytest.warns(UserWarning, match="declares up axis 'z'"):
        _walker_file(tmp_path / "c.bvh", up_axis="z")
        with pytest.raises(ValueError, match=r"c\.bvh.*up axis 'z'.*'y'"):
            read_bvh_folder(tmp_path)


def test_files_of_another_skeleton_with_the_same_channels_are_refused(tmp_path):
    text = _two_joint_bvh(False)
    (tmp_path / "a.bvh").write_text(text)
    # Back hangs below Leg instead of beside it: same channels, other skeleton
    nested = text.replace(
        "        OFFSET 0 -40 0\n      }\n    }\n    JOINT Back",
        "        OFFSET 0 -40 0\n      }\n    JOINT Back",
    ).replace("      }\n    }\n  }\n}\nMOTION", "      }\n    }\n    }\n  }\n}\nMOTION")
    (tmp_path / "b.bvh").write_text(nested)
    assert read_bvh(tmp_path / "b.bvh")[0].bone("Back").parent == "Leg"
    with pytest.raises(ValueError, match=r"b\.bvh.*a\.bvh.*skeleton.*'Back'"):
        read_bvh_folder(tmp_path)


def test_files_of_another_frame_rate_are_named(tmp_path):
    _walker_file(tmp_path / "a.bvh")
    walker = make_walker(n_sequences=1, n_frames=6, random_state=0)
    write_bvh(tmp_path / "b.bvh", walker.data, walker.skeleton, 120.0)
    with pytest.raises(ValueError, match=r"b\.bvh.*120.*frame_rate="):
        read_bvh_folder(tmp_path)


def test_a_faster_file_among_others_is_named_with_what_a_common_rate_does(
    tmp_path, recwarn
):
    walker = make_walker(n_sequences=1, n_frames=12, random_state=0)
    for name, rate in (("a", 30.0), ("b", 30.0), ("fast", 60.0)):
        write_bvh(tmp_path / f"{name}.bvh", walker.data, walker.skeleton, rate)
    message = (
        r"fast\.bvh has 60 frames per second, but the other 2 files \(a\.bvh and "
        r"b\.bvh\) have 30\. .*frame_rate=30 brings every file to 30 frames per "
        r"second by dropping frames: it keeps every 2nd frame of fast\.bvh \(60 "
        r"per second\) and a\.bvh and b\.bvh whole\."
    )
    with pytest.raises(ValueError, match=message):
        read_bvh_folder(tmp_path)
    assert not recwarn.list
    # and says so when it does it
    with pytest.warns(UserWarning, match=r"every 2nd frame of fast\.bvh"):
        both = read_bvh_folder(tmp_path, frame_rate=30.0)
    assert np.bincount(both.sequence_ids).tolist() == [12, 12, 6]
    # the same files at one rate are resampled without a word
    (tmp_path / "fast.bvh").unlink()
    read_bvh_folder(tmp_path, frame_rate=15.0)
    assert not [w for w in recwarn.list if "frame rate" in str(w.message)]
    # a rate above a file's names the file
    write_bvh(tmp_path / "slow.bvh", walker.data, walker.skeleton, 24.0)
    with pytest.raises(ValueError, match=r"up to 30 by dropping.*slow\.bvh has 24"):
        read_bvh_folder(tmp_path, frame_rate=30.0)


def _dash_walk_run(data_home):
    files = [data_home / "odd_files" / DASH] + [
        data_home / "external_dev" / "bandai_namco" / name
        for name in ("dataset-1_walk_normal_001.bvh", "dataset-2_run_active_001.bvh")
    ]
    return [read_bvh(path) for path in files]


def _fit_preprocessing(skeleton, sequences):
    X = np.concatenate(sequences)
    ids = np.repeat(np.arange(len(sequences)), [len(s) for s in sequences])
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(skeleton)
        return pre.fit(X, sequence_ids=ids)


def test_the_preprocessing_takes_the_joint_most_sequences_travel_with(data_home):
    read = _dash_walk_run(data_home)
    with pytest.warns(UserWarning, match=r"'joint_Root' in sequence 0.*'Hips'"):
        pre = _fit_preprocessing(read[1][0], [data for _, data, _, _ in read])
    assert pre.named_steps["root"].root_ == "Hips"


def test_a_still_sequence_does_not_count_as_travelling(data_home, recwarn):
    read = _dash_walk_run(data_home)
    sequences = [read[0][1][:1], read[1][1], read[2][1]]  # one frame of the dash
    pre = _fit_preprocessing(read[1][0], sequences)
    assert pre.named_steps["root"].root_ == "Hips"
    assert not [w for w in recwarn if "travels with" in str(w.message)]
