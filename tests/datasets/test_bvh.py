"""BVH files: reading, writing, conversion from ASF and MIT, malformed files."""

import re
import textwrap

import numpy as np
import pytest

from sklearn_crbm.datasets import (
    Bone,
    Skeleton,
    load_mit_walk,
    make_walker,
    read_amc,
    read_bvh,
    read_bvh_folder,
    write_bvh,
)

SMALL_BVH = textwrap.dedent(
    """\
    HIERARCHY
    ROOT Hips
    {
      OFFSET 0 0 0
      CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
      JOINT Spine
      {
        OFFSET 0 10 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 0 5 0
        }
      }
      JOINT Leg
      {
        OFFSET 3 -1 0
        CHANNELS 1 Xrotation
        End Site
        {
          OFFSET 0 -8 0
        }
      }
    }
    MOTION
    Frames: 2
    Frame Time: 0.04
    1 2 3 0 0 0 0 0 0 0
    1 2 4 90 0 0 0 0 0 90
    """
)


@pytest.fixture
def small_bvh(tmp_path):
    path = tmp_path / "small.bvh"
    path.write_text(SMALL_BVH)
    return path


def _line_error(path, lineno):
    return re.escape(f"{path}, line {lineno}:")


@pytest.mark.parametrize(
    "frame_time, rate",
    [
        ("0.0166667", 60.0),  # 59.99988 as 1 / Frame Time
        ("0.008333", 120.0),  # 120.0048
        ("0.0333333", 30.0),
        ("1.6666667e-02", 60.0),
        ("0.0416667", 24.0),
        ("0.04", 25.0),
        ("0.03333333333333333", 30.0),  # what write_bvh writes for 30
        ("0.0333667", 1 / 0.0333667),  # 29.97: not a whole number
        ("0.03", 1 / 0.03),  # 33.3: 1 / 33 written to two digits, but 1% off
        ("0.0166", 1 / 0.0166),  # 60.24: 1 / 60 is 0.0167 to four digits
    ],
)
def test_frame_rates_are_read_as_written(small_bvh, frame_time, rate):
    small_bvh.write_text(SMALL_BVH.replace("0.04", frame_time))
    assert read_bvh(small_bvh)[3] == rate
    other = small_bvh.with_name("other.bvh")
    other.write_text(SMALL_BVH.replace("0.04", "0.1"))
    with pytest.raises(ValueError, match=f" has {rate:g} frames per second"):
        read_bvh_folder(small_bvh.parent)


def test_read_small_bvh(small_bvh):
    skeleton, data, names, frame_rate = read_bvh(small_bvh)
    assert frame_rate == pytest.approx(25.0)
    assert skeleton.bone_names == ["Hips", "Spine", "Spine_end", "Leg", "Leg_end"]
    assert skeleton.convention == "bvh"
    hips = skeleton.bone("Hips")
    assert hips.channels == ("tx", "ty", "tz", "rz", "rx", "ry")
    assert hips.rotation_order == "yxz"  # R = Rz Rx Ry: y applied first
    assert skeleton.bone("Leg").rotation_order == "x"
    assert skeleton.bone("Spine_end").channels == ()
    assert list(names) == [
        "Hips_tx", "Hips_ty", "Hips_tz", "Hips_rz", "Hips_rx", "Hips_ry",
        "Spine_rz", "Spine_rx", "Spine_ry", "Leg_rx",
    ]  # fmt: skip
    assert data.shape == (2, 10)
    positions = skeleton.forward_kinematics(data)
    np.testing.assert_allclose(
        positions[0],
        [[1, 2, 3], [1, 12, 3], [1, 17, 3], [4, 1, 3], [4, -7, 3]],
        atol=1e-12,
    )
    # frame 2: hips turned 90 deg about z; the leg bent 90 deg about x
    np.testing.assert_allclose(
        positions[1],
        [[1, 2, 4], [-9, 2, 4], [-14, 2, 4], [2, 5, 4], [2, 5, -4]],
        atol=1e-12,
    )


def test_position_channels_replace_the_offset(tmp_path):
    # as pybvh, bvhio, bvhtoolbox and Blender read them: a root OFFSET and a
    # joint's OFFSET component are overridden by the joint's position channels
    text = SMALL_BVH.replace("OFFSET 0 0 0\n", "OFFSET 5 90 7\n", 1).replace(
        "CHANNELS 3", "CHANNELS 4 Yposition"
    )
    text = text.replace("1 2 3 0 0 0 0 0 0 0", "1 2 3 0 0 0 6 0 0 0 0")
    text = text.replace("1 2 4 90 0 0 0 0 0 90", "1 2 4 0 0 0 7 0 0 0 0")
    (tmp_path / "moving.bvh").write_text(text)
    skeleton, data, names, _ = read_bvh(tmp_path / "moving.bvh")
    assert "Spine_ty" in names
    positions = skeleton.forward_kinematics(data)
    np.testing.assert_allclose(positions[:, 0], [[1, 2, 3], [1, 2, 4]])
    np.testing.assert_allclose(positions[:, 1], [[1, 8, 3], [1, 9, 4]])
    np.testing.assert_allclose(
        skeleton.local_offsets(data)[:, :2],
        [[[1, 2, 3], [0, 6, 0]], [[1, 2, 4], [0, 7, 0]]],
    )
    write_bvh(tmp_path / "copy.bvh", data, skeleton, 25.0)
    copy, data2, _, _ = read_bvh(tmp_path / "copy.bvh")
    np.testing.assert_allclose(copy.forward_kinematics(data2), positions, atol=1e-12)


def test_skeleton_from_bvh_equals_read_bvh(small_bvh):
    skeleton = Skeleton.from_bvh(small_bvh)
    assert skeleton.bone_names == read_bvh(small_bvh)[0].bone_names
    np.testing.assert_array_equal(skeleton.feature_names, read_bvh(small_bvh)[2])


def test_bvh_round_trip_is_exact(tmp_path, small_bvh):
    skeleton, data, names, frame_rate = read_bvh(small_bvh)
    path = tmp_path / "copy.bvh"
    write_bvh(path, data, skeleton, frame_rate)
    skeleton2, data2, names2, frame_rate2 = read_bvh(path)
    # the one-channel Leg gets the two axes it lacks, as zero channels
    np.testing.assert_array_equal(names2, [*names, "Leg_ry", "Leg_rz"])
    np.testing.assert_array_equal(data2[:, :-2], data)
    np.testing.assert_array_equal(data2[:, -2:], 0.0)
    assert frame_rate2 == pytest.approx(frame_rate, rel=1e-12)
    assert skeleton2.bone_names == skeleton.bone_names
    np.testing.assert_allclose(
        [b.offset for b in skeleton2.bones],
        [b.offset for b in skeleton.bones],
        atol=1e-12,
    )
    write_bvh(tmp_path / "again.bvh", data2, skeleton2, frame_rate2)
    assert (tmp_path / "again.bvh").read_text() == path.read_text()


@pytest.fixture(scope="module")
def cmu(data_home):
    skeleton = Skeleton.from_asf(data_home / "cmu_subject35" / "35.asf")
    data, names = read_amc(data_home / "cmu_subject35" / "35_01.amc", skeleton)
    return skeleton, data, names


def _asf_points_in_bvh(asf, bvh):
    """Index of the BVH joint at the end of each ASF bone (the root: the root)."""
    index = []
    for name in asf.bone_names:
        children = asf.children(name)
        if name == "root":
            index.append(bvh.bone_names.index("root"))
        elif children:
            index.append(bvh.bone_names.index(children[0]))
        else:
            index.append(bvh.bone_names.index(name + "_end"))
    return index


def test_cmu_asf_amc_to_bvh(tmp_path, cmu):
    asf, data, names = cmu
    path = tmp_path / "35_01.bvh"
    write_bvh(path, data, asf, frame_rate=120.0)
    bvh, bvh_data, bvh_names, frame_rate = read_bvh(path)
    assert frame_rate == pytest.approx(120.0)
    assert bvh_data.shape[0] == 358
    # every ASF bone is a joint (leaves also get an end site)
    assert set(asf.bone_names) <= set(bvh.bone_names)
    # every ASF channel is in the BVH; bones without an axis pre-rotation
    # (root, spine, neck, head, clavicles) keep their values exactly
    assert set(names) <= set(bvh_names)
    column = {name: i for i, name in enumerate(bvh_names)}
    for j, name in enumerate(names):
        if not np.any(asf.bone(name.rsplit("_", 1)[0]).axis):
            np.testing.assert_array_equal(
                bvh_data[:, column[name]], data[:, j], err_msg=name
            )
    # forward kinematics agree
    asf_positions = asf.forward_kinematics(data)
    bvh_positions = bvh.forward_kinematics(bvh_data)[:, _asf_points_in_bvh(asf, bvh)]
    np.testing.assert_allclose(bvh_positions, asf_positions, atol=1e-9)


def test_walker_to_bvh_keeps_every_channel(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=20, random_state=0)
    write_bvh(tmp_path / "walk.bvh", walker.data, walker.skeleton, walker.frame_rate)
    bvh, data, names, frame_rate = read_bvh(tmp_path / "walk.bvh")
    # every joint has three rotation channels: the ones a bone lacks are zero
    assert set(walker.feature_names) < set(names)
    assert all(len(b.rotation_order) == 3 for b in bvh.bones if b.channels)
    column = {name: i for i, name in enumerate(names)}
    order = [column[name] for name in walker.feature_names]
    np.testing.assert_array_equal(data[:, order], walker.data)
    added = sorted(set(column.values()) - set(order))
    np.testing.assert_array_equal(data[:, added], 0.0)
    asf_positions = walker.skeleton.forward_kinematics(walker.data)
    bvh_positions = bvh.forward_kinematics(data)[
        :, _asf_points_in_bvh(walker.skeleton, bvh)
    ]
    np.testing.assert_allclose(bvh_positions, asf_positions, atol=1e-9)


def test_mit_to_bvh(tmp_path, data_home):
    mit = load_mit_walk(data_home)
    frames = mit.data[:40]
    write_bvh(tmp_path / "mit.bvh", frames, mit.skeleton, mit.frame_rate)
    bvh, data, names, frame_rate = read_bvh(tmp_path / "mit.bvh")
    assert not any(name.endswith(("_ox", "_ex")) for name in names)
    index = [bvh.bone_names.index(name) for name in mit.skeleton.bone_names]
    np.testing.assert_allclose(
        bvh.forward_kinematics(data)[:, index],
        mit.skeleton.forward_kinematics(frames),
        atol=1e-9,
    )


def test_write_bvh_from_another_root(tmp_path, small_bvh):
    skeleton, data, names, _ = read_bvh(small_bvh)
    positions = skeleton.forward_kinematics(data)
    write_bvh(tmp_path / "spine.bvh", data, skeleton, 25.0, root="Spine")
    spine, data2, names2, _ = read_bvh(tmp_path / "spine.bvh")
    assert spine.bone_names == ["Spine", "Spine_end"]
    assert list(names2) == ["Spine_tx", "Spine_ty", "Spine_tz"] + [
        "Spine_rz",
        "Spine_rx",
        "Spine_ry",
    ]
    np.testing.assert_allclose(
        spine.forward_kinematics(data2), positions[:, 1:3], atol=1e-12
    )
    with pytest.raises(ValueError, match="no bone 'Tail'"):
        write_bvh(tmp_path / "x.bvh", data, skeleton, 25.0, root="Tail")
    walker = make_walker(n_sequences=1, n_frames=2, random_state=0)
    with pytest.raises(ValueError, match="root= needs a BVH skeleton"):
        write_bvh(tmp_path / "x.bvh", walker.data, walker.skeleton, 25.0, root="lfemur")


def test_write_bvh_checks_its_input(tmp_path, small_bvh):
    skeleton, data, names, _ = read_bvh(small_bvh)
    with pytest.raises(ValueError, match="frame_rate"):
        write_bvh(tmp_path / "a.bvh", data, skeleton, 0)
    with pytest.raises(ValueError, match="Hips_tx"):
        write_bvh(
            tmp_path / "a.bvh", data[:, 1:], skeleton, 25, feature_names=names[1:]
        )
    forest = Skeleton(
        [Bone("a", None, [0, 0, 0], 0.0), Bone("b", None, [1, 0, 0], 1.0)]
    )
    with pytest.raises(ValueError, match="one ROOT"):
        write_bvh(tmp_path / "a.bvh", np.zeros((1, 0)), forest, 25)
    bad = data.copy()
    bad[0, 3] = np.inf
    with pytest.raises(ValueError, match="NaN or infinite"):
        write_bvh(tmp_path / "a.bvh", bad, skeleton, 25)


# ------------------------------------------------------------- malformed
# A fault in SMALL_BVH (old -> new): the line and the words of the error.
MALFORMED = {
    "no hierarchy": ("HIERARCHY", "HIERARCHIE", 1, "'HIERARCHY'"),
    "number in offset": ("OFFSET 0 10 0", "OFFSET 0 1O 0", 8, "'1O'"),
    "unknown channel": ("CHANNELS 1 Xrotation", "CHANNELS 1 Wrotation", 18, "'Wrotation'"),
    "unclosed brace": ("    }\n  }\n}\nMOTION", "    }\n  }\nMOTION", 23, "file ends"),
    "fractional frame count": ("Frames: 2", "Frames: 2.5", 26, "whole number"),
    "no frame count": ("Frames: 2", "Frames:", 26, "one number"),
    "zero frame time": ("Frame Time: 0.04", "Frame Time: 0", 27, "positive frame time"),
    "values in a frame": (
        "1 2 3 0 0 0 0 0 0 0", "1 2 3 0 0 0 0 0 0", 28, "9 values, expected 10"
    ),
    "truncated motion": ("1 2 4 90 0 0 0 0 0 90\n", "", 28, "truncated"),
    "number in motion": ("1 2 4 90", "1 2 4 9O", 29, "'9O'"),
    "more frames than announced": ("Frames: 2", "Frames: 1", 29, "more frames"),
    "no motion": ("MOTION", "MOTOR", 29, "'MOTION'"),
    "second offset": (
        "OFFSET 0 10 0\n", "OFFSET 0 10 0\n    OFFSET 0 9 0\n", 9,
        "a second OFFSET line in joint 'Spine'",
    ),
    "second channels": (
        "CHANNELS 1 Xrotation\n", "CHANNELS 1 Xrotation\n    CHANNELS 0\n", 19,
        "a second CHANNELS line in joint 'Leg'",
    ),
}  # fmt: skip


@pytest.mark.parametrize(
    "old, new, lineno, words", MALFORMED.values(), ids=list(MALFORMED)
)
def test_malformed_bvh_names_the_line(tmp_path, old, new, lineno, words):
    assert old in SMALL_BVH
    path = tmp_path / "bad.bvh"
    path.write_text(SMALL_BVH.replace(old, new, 1))
    message = _line_error(path, lineno) + ".*" + re.escape(words)
    with pytest.raises(ValueError, match=message):
        read_bvh(path)


def test_skeleton_from_malformed_bvh_names_the_line(tmp_path):
    path = tmp_path / "bad.bvh"
    path.write_text(SMALL_BVH.replace("HIERARCHY", "HIERARCHIE"))
    with pytest.raises(ValueError, match=_line_error(path, 1)):
        Skeleton.from_bvh(path)
