"""Labelled corpora: a label per file, per frame, from JSON files, names or functions."""

import json
import re
import shutil

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import (
    load_bandai_walks,
    make_walker,
    read_amc_folder,
    read_bvh_folder,
    write_bvh,
)

STYLES = [
    "active",
    "elderly",
    "exhausted",
    "feminine",
    "masculine",
    "normal",
    "youthful",
]


@pytest.fixture(scope="module")
def styles_folder(data_home):
    return data_home / "bandai_walk_styles"


@pytest.fixture(scope="module")
def bandai(data_home):
    return load_bandai_walks(data_home)


def _style_in_name(name):
    return name.split("_")[2]  # dataset-2_walk_{style}_{take}


def test_json_labels_are_given_to_every_frame_of_their_file(styles_folder):
    walks = read_bvh_folder(styles_folder, labels="style")
    # the names come from style_label.txt beside the files, without the
    # "dataset-2_" written before every one there
    assert list(walks.target_names) == STYLES
    assert walks.target.shape == (walks.data.shape[0],)
    for k, name in enumerate(walks.sequence_names):
        frames = walks.target[walks.sequence_ids == k]
        style = json.loads((styles_folder / f"{name}.json").read_text())["style"]
        assert_array_equal(frames, style)
        assert walks.target_names[style] == _style_in_name(name)
    assert np.bincount(walks.target).tolist() == [
        1237,
        2525,
        1797,
        1545,
        1263,
        1600,
        1370,
    ]


def test_labels_from_names_and_functions_agree_with_the_json_files(styles_folder):
    from_json = read_bvh_folder(styles_folder, labels="style")
    from_names = read_bvh_folder(
        styles_folder, labels=re.compile(r"walk_([a-z]+)_\d+$")
    )
    from_function = read_bvh_folder(
        styles_folder, labels=lambda path: _style_in_name(path.stem)
    )
    # the names sort as style_label.txt lists them, so the codes agree
    assert list(from_names.target_names) == STYLES
    assert list(from_function.target_names) == STYLES
    assert_array_equal(from_names.target, from_json.target)
    assert_array_equal(from_function.target, from_json.target)
    # without a group the whole match is the label
    whole = read_bvh_folder(styles_folder, labels=re.compile(r"[a-z]+(?=_0)"))
    assert list(whole.target_names) == STYLES
    # label_names fixes the order of the codes, and may name absent labels
    reverse = STYLES[::-1] + ["proud"]
    named = read_bvh_folder(
        styles_folder,
        pattern="*_00[12].bvh",
        labels=re.compile(r"walk_([a-z]+)_"),
        label_names=reverse,
    )
    assert list(named.target_names) == reverse
    assert_array_equal(named.target[named.sequence_ids == 0], 6)  # active


def test_the_label_names_are_found_in_the_repositorys_cfg_folder(
    styles_folder, tmp_path
):
    # the Bandai Namco repository keeps the names in cfg/ beside data/
    (tmp_path / "data").mkdir()
    (tmp_path / "cfg").mkdir()
    for name in ["dataset-2_walk_elderly_001", "dataset-2_walk_youthful_002"]:
        for suffix in (".bvh", ".json"):
            shutil.copyfile(
                styles_folder / (name + suffix), tmp_path / "data" / (name + suffix)
            )
    shutil.copyfile(
        styles_folder / "style_label.txt", tmp_path / "cfg" / "style_label.txt"
    )
    shutil.copyfile(
        styles_folder / "content_label.txt", tmp_path / "cfg" / "content_label.txt"
    )
    walks = read_bvh_folder(tmp_path / "data", labels="style")
    assert len(walks.target_names) == 7
    assert [
        walks.target_names[walks.target[walks.sequence_ids == k][0]] for k in (0, 1)
    ] == ["elderly", "youthful"]
    content = read_bvh_folder(tmp_path / "data", labels="content")
    assert set(content.target) == {0}
    assert content.target_names[0] == "walk"
    # a names file passed by path, without any beside the files
    shutil.rmtree(tmp_path / "cfg")
    walks = read_bvh_folder(
        tmp_path / "data",
        labels="style",
        label_names=styles_folder / "style_label.txt",
    )
    assert len(walks.target_names) == 7
    # no names at all: the distinct values, sorted, as text
    walks = read_bvh_folder(tmp_path / "data", labels="style")
    assert list(walks.target_names) == ["1", "6"]
    assert_array_equal(np.unique(walks.target), [0, 1])


def test_label_names_are_text_ready_to_use(data_home, tmp_path):
    """target_names[target] are class labels: text, without a prefix that
    every name of the names file repeats."""
    contents = data_home / "bandai_contents"
    runs = read_bvh_folder(contents, pattern="*_r*_001.bvh", labels="content")
    assert list(runs.target_names[:4]) == [
        "walk",
        "walk-turn-left",
        "walk-turn-right",
        "run",
    ]
    per_frame = runs.target_names[runs.target]
    assert set(per_frame) == {
        "run",
        "raise-up-both-hands",
        "raise-up-left-hand",
        "raise-up-right-hand",
    }
    assert all(isinstance(name, str) for name in per_frame)
    # numbers are text too, in numeric order
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    for name, code in (("walk_a", 10), ("walk_b", 2), ("walk_c", 3)):
        write_bvh(tmp_path / f"{name}.bvh", walker.data, walker.skeleton, 30.0)
        (tmp_path / f"{name}.json").write_text(json.dumps({"take": code}))
    takes = read_bvh_folder(tmp_path, labels="take")
    assert list(takes.target_names) == ["2", "3", "10"]
    # a prefix is left out only up to an underscore, and only where the
    # names stay names; names passed as a list are kept as given
    for names, expected in (
        ("my_slow\nmy_brisk\nmy_slow-ish\n", ["slow", "brisk", "slow-ish"]),
        ("slow\nslow-ish\nbrisk\n", ["slow", "slow-ish", "brisk"]),
        ("walk_slow\nwalk_slow_fast\n", ["slow", "slow_fast"]),
        ("a_\na_b\n", ["a_", "a_b"]),
    ):
        (tmp_path / "take_label.txt").write_text(names)
        (tmp_path / "walk_a.json").write_text('{"take": 0}')
        (tmp_path / "walk_b.json").write_text('{"take": 1}')
        (tmp_path / "walk_c.json").write_text('{"take": 1}')
        labelled = read_bvh_folder(tmp_path, labels="take")
        assert list(labelled.target_names) == expected
    kept = read_bvh_folder(tmp_path, labels="take", label_names=["my_a", "my_b"])
    assert list(kept.target_names) == ["my_a", "my_b"]


def test_a_file_name_given_as_key_is_told_to_have_a_group(data_home):
    contents = data_home / "bandai_contents"
    message = (
        r"has no key 'dataset-2_run'; it has \['content', 'style'\]\. .* give a "
        r"pattern with a group around the label: labels=re\.compile\("
        r"r'dataset-2_\(\[\^_\]\+\)'\) \(on the command line, --labels "
        r"'dataset-2_\(\[\^_\]\+\)'; without a group, --labels is a key\)"
    )
    with pytest.raises(ValueError, match=message):
        read_bvh_folder(contents, pattern="*_r*_001.bvh", labels="dataset-2_run")
    # the pattern it suggests reads the labels
    pattern = re.compile(r"dataset-2_([^_]+)")
    runs = read_bvh_folder(contents, pattern="*_r*_001.bvh", labels=pattern)
    assert "run" in runs.target_names


def test_labels_follow_the_frames_kept_at_a_lower_rate(styles_folder):
    full = read_bvh_folder(styles_folder, pattern="*_00[1].bvh", labels="style")
    half = read_bvh_folder(
        styles_folder, pattern="*_00[1].bvh", labels="style", frame_rate=15.0
    )
    assert half.target.shape == half.sequence_ids.shape
    for k in range(7):
        assert_array_equal(
            half.target[half.sequence_ids == k],
            full.target[full.sequence_ids == k][::2],
        )


def test_amc_folders_take_labels_too(data_home, tmp_path):
    cmu = data_home / "cmu_subject35"
    shutil.copyfile(cmu / "35.asf", tmp_path / "35.asf")
    for name in ("35_slow_1", "35_fast_1", "35_fast_2"):
        shutil.copyfile(cmu / "35_01.amc", tmp_path / f"{name}.amc")
    walks = read_amc_folder(
        tmp_path,
        frame_rate=30.0,
        labels=re.compile(r"_(slow|fast)_"),
        label_names=["slow", "fast"],
    )
    # files in sorted order: fast_1, fast_2, slow_1; 90 frames each at 30 Hz
    assert walks.target.tolist() == [1] * 90 + [1] * 90 + [0] * 90


def test_labels_errors(styles_folder, tmp_path):
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    write_bvh(tmp_path / "walk_a.bvh", walker.data, walker.skeleton, 30.0)
    with pytest.raises(FileNotFoundError, match="walk_a.json beside it"):
        read_bvh_folder(tmp_path, labels="style")
    (tmp_path / "walk_a.json").write_text('{"content": 1}')
    with pytest.raises(ValueError, match=r"has no key 'style'; it has \['content'\]"):
        read_bvh_folder(tmp_path, labels="style")
    (tmp_path / "walk_a.json").write_text("{style: 1}")
    with pytest.raises(ValueError, match="is not valid JSON"):
        read_bvh_folder(tmp_path, labels="style")
    (tmp_path / "walk_a.json").write_text('{"style": 3}')
    with pytest.raises(ValueError, match="has label 3, but there are 2 label names"):
        read_bvh_folder(tmp_path, labels="style", label_names=["a", "b"])
    (tmp_path / "walk_a.json").write_text('{"style": "proud"}')
    with pytest.raises(ValueError, match="'proud', which is not one of the label"):
        read_bvh_folder(tmp_path, labels="style", label_names=["a", "b"])
    (tmp_path / "walk_a.json").write_text('{"style": [1, 2]}')
    with pytest.raises(TypeError, match="must be a single value"):
        read_bvh_folder(tmp_path, labels="style")
    with pytest.raises(ValueError, match="'walk_a' does not match labels="):
        read_bvh_folder(tmp_path, labels=re.compile("jog"))
    with pytest.raises(TypeError, match="labels must be a key of the JSON file"):
        read_bvh_folder(tmp_path, labels=3)
    with pytest.raises(ValueError, match="label_names must be distinct"):
        read_bvh_folder(tmp_path, labels=lambda p: "a", label_names=["a", "a"])
    with pytest.raises(ValueError, match="pass labels= too"):
        read_bvh_folder(tmp_path, label_names=["a"])
    write_bvh(tmp_path / "walk_b.bvh", walker.data, walker.skeleton, 30.0)
    with pytest.raises(TypeError, match="not all of the same kind.*give label_names"):
        read_bvh_folder(tmp_path, labels=lambda p: 1 if p.stem == "walk_a" else "b")


def test_several_labels_are_columns_of_names(data_home):
    """labels=["content", "style"]: a style model's 2-D y, as the user names
    the labels, only those present."""
    corpus = data_home / "bandai_dataset2"
    takes = read_bvh_folder(
        corpus, pattern="*_r*_e*_001.bvh", labels=["content", "style"]
    )
    assert takes.target.shape == (len(takes.data), 2)
    contents, styles = takes.target_names
    assert list(contents) == [
        "run",
        "raise-up-both-hands",
        "raise-up-left-hand",
        "raise-up-right-hand",
    ]
    assert list(styles) == ["elderly", "exhausted"]
    for k, name in enumerate(takes.sequence_names):
        _, content, style, _ = name.split("_")
        assert takes.target[takes.sequence_ids == k].tolist()[0] == [content, style]
    one = read_bvh_folder(corpus, pattern="*_run_e*_001.bvh", labels=["style"])
    assert one.target.shape == (len(one.data), 1)


def test_several_labels_errors(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    write_bvh(tmp_path / "walk_a.bvh", walker.data, walker.skeleton, 30.0)
    (tmp_path / "walk_a.json").write_text('{"content": 1, "style": 0}')
    with pytest.raises(ValueError, match="label_names must be None or a list of 2"):
        read_bvh_folder(tmp_path, labels=["content", "style"], label_names=["a"])
    with pytest.raises(ValueError, match="has label 1, but there are 1 label names"):
        read_bvh_folder(
            tmp_path, labels=["content", "style"], label_names=[["walk"], None]
        )
    with pytest.raises(ValueError, match="empty list"):
        read_bvh_folder(tmp_path, labels=[])
    named = read_bvh_folder(
        tmp_path, labels=["content", "style"], label_names=[["walk", "run"], None]
    )
    assert named.target.tolist() == [["run", "0"]] * 4


def test_load_bandai_walks(bandai, styles_folder):
    assert bandai.data.shape == (11337, 132)
    assert list(bandai.target_names) == STYLES
    assert bandai.frame_rate == 30.0
    assert len(bandai.sequence_names) == 42
    assert bandai.takes.tolist() == list(range(1, 7)) * 7
    for k, name in enumerate(bandai.sequence_names):
        styles = bandai.target[bandai.sequence_ids == k]
        assert set(bandai.target_names[styles]) == {_style_in_name(name)}
    # the same frames as the folder read as it is
    walks = read_bvh_folder(styles_folder)
    assert_array_equal(bandai.data, walks.data)
    assert bandai.skeleton.bone_names[:2] == ["joint_Root", "Hips"]
    assert "CC BY-NC" in bandai.DESCR or "Attribution-NonCommercial" in bandai.DESCR


def test_load_bandai_walks_says_how_to_fetch_them(tmp_path):
    with pytest.raises(FileNotFoundError, match="fetch_bandai_walks"):
        load_bandai_walks(tmp_path)
