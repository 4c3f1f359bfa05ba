"""Files that used to be read as silently wrong data, or failed with the wrong
exception: each now gives a ValueError or TypeError naming the file (and line)."""

import re
import textwrap

import numpy as np
import pytest

from sklearn_crbm.datasets import (
    Bone,
    Skeleton,
    make_walker,
    read_amc,
    read_bvh,
    read_bvh_folder,
    write_amc,
    write_bvh,
)

ASF = textwrap.dedent(
    """\
    :units
      length 1
      angle deg
    :root
      order TX TY TZ RX RY RZ
      axis XYZ
      position 0 0 0
      orientation 0 0 0
    :bonedata
      begin
        id 1
        name femur
        direction 0 -1 0
        length 10
        axis 0 0 0 XYZ
        dof rx ry rz
      end
    :hierarchy
      begin
        root femur
      end
    """
)


def _at(path, lineno):
    return re.escape(f"{path}, line {lineno}:")


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


# ----------------------------------------------------------- repeated lines
@pytest.mark.parametrize(
    "line", ["direction 1 0 0", "length 3", "axis 0 0 10 XYZ", "dof rx"]
)
def test_asf_bone_with_a_repeated_line_is_refused(tmp_path, line):
    lines = ASF.splitlines()
    lines.insert(16, "    " + line)  # after dof, inside the femur block
    path = _write(tmp_path, "twice.asf", "\n".join(lines) + "\n")
    keyword = line.split()[0]
    with pytest.raises(ValueError, match=_at(path, 17) + f".*second '{keyword}'"):
        Skeleton.from_asf(path)


def test_asf_bone_without_direction_but_with_a_length_is_refused(tmp_path):
    path = _write(
        tmp_path, "zero.asf", ASF.replace("direction 0 -1 0", "direction 0 0 0")
    )
    with pytest.raises(
        ValueError, match=_at(path, 13) + ".*direction 0 0 0.*length 10"
    ):
        Skeleton.from_asf(path)
    # a zero-length bone may have no direction
    fine = _write(
        tmp_path,
        "fine.asf",
        ASF.replace("direction 0 -1 0", "direction 0 0 0").replace(
            "length 10", "length 0"
        ),
    )
    assert Skeleton.from_asf(fine).bone("femur").length == 0


# ----------------------------------------------------------- AMC frame numbers
def _amc(numbers):
    frames = [f"{n}\nroot 0 0 0 0 0 0\nfemur 0 0 {k}" for k, n in enumerate(numbers)]
    return ":FULLY-SPECIFIED\n:DEGREES\n" + "\n".join(frames) + "\n"


@pytest.mark.parametrize(
    "numbers, lineno, what",
    [((1, 3), 6, "3 follows frame 1"), ((3, 2, 1), 6, "2 follows frame 3"),
     ((1, 2, 2), 9, "2 follows frame 2")],
    ids=["gap", "reversed", "repeated"],
)  # fmt: skip
def test_amc_frames_must_be_numbered_consecutively(tmp_path, numbers, lineno, what):
    skeleton = Skeleton.from_asf(_write(tmp_path, "a.asf", ASF))
    path = _write(tmp_path, "gaps.amc", _amc(numbers))
    with pytest.raises(ValueError, match=_at(path, lineno) + f".*frame {what}"):
        read_amc(path, skeleton)


def test_amc_frames_may_start_at_any_number(tmp_path):
    skeleton = Skeleton.from_asf(_write(tmp_path, "a.asf", ASF))
    data, _ = read_amc(_write(tmp_path, "late.amc", _amc((7, 8, 9))), skeleton)
    assert data[:, -1].tolist() == [0, 1, 2]


# ----------------------------------------------------------- empty channels
def test_bvh_without_channels_is_read(tmp_path):
    text = (
        "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 0\n  End Site\n  {\n"
        "    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames: 1\nFrame Time: 0.04\n\n"
    )
    skeleton, data, names, rate = read_bvh(_write(tmp_path, "still.bvh", text))
    assert data.shape == (1, 0) and len(names) == 0 and rate == pytest.approx(25)
    with pytest.raises(ValueError, match="frame has 1 values, expected 0"):
        read_bvh(_write(tmp_path, "more.bvh", text + "1\n"))


# ----------------------------------------------------------- wrong format
def test_readers_name_the_reader_for_the_other_format(tmp_path):
    amc = _write(tmp_path, "walk.amc", _amc((1, 2)))
    asf = _write(tmp_path, "walk.asf", ASF)
    for path in (amc, asf):
        with pytest.raises(
            ValueError, match=f"{path.name}.*read_amc.*Skeleton.from_asf"
        ):
            read_bvh(path)
    bvh = _write(tmp_path, "walk.bvh", "HIERARCHY\nROOT Hips\n{\n")
    with pytest.raises(ValueError, match=f"{bvh.name}.*BVH file.*read_bvh"):
        Skeleton.from_asf(bvh)
    with pytest.raises(ValueError, match=f"{bvh.name}.*BVH file.*read_bvh"):
        read_amc(bvh, Skeleton.from_asf(asf))


# ----------------------------------------------------------- empty files
@pytest.mark.parametrize("content, what", [("", "0 bytes"), ("\n  \n", "blank")])
def test_an_empty_file_is_said_to_be_empty(tmp_path, content, what):
    """A download that failed leaves an empty file: say so, not 'no MOTION'."""
    asf = _write(tmp_path, "walk.asf", ASF)
    readers = {
        "walk.bvh": read_bvh,
        "skeleton.asf": Skeleton.from_asf,
        "walk.amc": lambda path: read_amc(path, Skeleton.from_asf(asf)),
    }
    for name, read in readers.items():
        path = _write(tmp_path, name, content)
        with pytest.raises(ValueError, match=f"{name} is empty: .*{what}"):
            read(path)
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    write_bvh(tmp_path / "good.bvh", walker.data, walker.skeleton, 30.0)
    with pytest.raises(ValueError, match=r"walk\.bvh is empty"):
        read_bvh_folder(tmp_path)


# ----------------------------------------------------------- writers
@pytest.mark.parametrize("name", ["left leg", "", "a#b", ":root", "a\nMOTION", "12"])
def test_writers_refuse_names_their_readers_refuse(tmp_path, name):
    bones = [
        Bone("root", None, [0, 0, 0], 0, ("tx", "ty", "tz", "rx", "ry", "rz"), "xyz"),
        Bone(name, "root", [0, 1, 0], 2, ("rx",), "x"),
    ]
    skeleton = Skeleton(bones, convention="bvh")
    data = np.zeros((2, 7))
    pattern = f"bone name {re.escape(repr(name))}.*could not be read back"
    if name not in ("a#b", ":root", "12"):  # BVH reads those
        with pytest.raises(ValueError, match=pattern):
            write_bvh(tmp_path / "out.bvh", data, skeleton, 30.0)
        assert not (tmp_path / "out.bvh").exists()
    else:
        write_bvh(tmp_path / "out.bvh", data, skeleton, 30.0)
        assert read_bvh(tmp_path / "out.bvh")[0].bone_names[1] == name
    with pytest.raises(ValueError, match=pattern):
        write_amc(tmp_path / "out.amc", data, skeleton)
    assert not (tmp_path / "out.amc").exists()


# ----------------------------------------------------------- folders and labels
@pytest.fixture
def two_walks(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    for name in ("walk_a", "walk_b"):
        write_bvh(tmp_path / f"{name}.bvh", walker.data, walker.skeleton, 30.0)
    return tmp_path


def test_absolute_pattern_is_a_value_error(two_walks):
    with pytest.raises(ValueError, match="pattern.*relative"):
        read_bvh_folder(two_walks, pattern="/abs/*.bvh")


@pytest.mark.parametrize(
    "content, error, what",
    [(b'{"style": NaN}', ValueError, "NaN"),
     (b'{"style": {"a": 1}}', TypeError, "single value"),
     (b'{"style": ' + b"[" * 100000 + b"]" * 100000 + b"}", ValueError, "nested"),
     (b'{"style": "caf\xe9"}', ValueError, "UTF-8"),
     (b'{"style": ' + b"9" * 5000 + b"}", ValueError, "digits")],
    ids=["nan", "dict", "nested", "latin-1", "5000-digits"],
)  # fmt: skip
def test_bad_json_labels_name_their_file(two_walks, content, error, what):
    (two_walks / "walk_a.json").write_bytes(content)
    (two_walks / "walk_b.json").write_text('{"style": "x"}')
    with pytest.raises(error, match=f"walk_a.json.*{what}"):
        read_bvh_folder(two_walks, labels="style")


def test_label_names_file_that_is_not_utf8_names_itself(two_walks):
    for name in ("walk_a", "walk_b"):
        (two_walks / f"{name}.json").write_text('{"style": 0}')
    (two_walks / "style_label.txt").write_bytes(b"caf\xe9\n")
    with pytest.raises(ValueError, match="style_label.txt.*UTF-8"):
        read_bvh_folder(two_walks, labels="style")


@pytest.mark.parametrize(
    "a, b", [("true", "1"), ("1.0", "1"), ("false", "0"), ('"1"', "1")]
)
def test_labels_that_would_merge_or_mix_kinds_are_refused(two_walks, a, b):
    (two_walks / "walk_a.json").write_text(f'{{"style": {a}}}')
    (two_walks / "walk_b.json").write_text(f'{{"style": {b}}}')
    with pytest.raises(TypeError, match="same kind.*walk_a.json.*walk_b.json"):
        read_bvh_folder(two_walks, labels="style")


def test_labels_of_one_kind_stay_distinct(two_walks):
    for a, b in (("true", "false"), ("1.5", "1"), ("1.0", "2.0")):
        (two_walks / "walk_a.json").write_text(f'{{"style": {a}}}')
        (two_walks / "walk_b.json").write_text(f'{{"style": {b}}}')
        if a == "1.5":
            with pytest.raises(TypeError, match="same kind"):
                read_bvh_folder(two_walks, labels="style")
            continue
        walks = read_bvh_folder(two_walks, labels="style")
        assert len(walks.target_names) == 2


def test_label_function_returning_nan_is_refused(two_walks):
    with pytest.raises(ValueError, match="walk_a.bvh.*NaN"):
        read_bvh_folder(two_walks, labels=lambda path: float("nan"))
    with pytest.raises(TypeError, match="walk_a.bvh.*single value"):
        read_bvh_folder(two_walks, labels=lambda path: {"a": 1})
