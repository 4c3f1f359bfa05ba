"""Fuzzing the file readers: only ValueError or TypeError on bad files.

Real files (CMU subject 35's ASF and AMC, and a BVH written from them; from
the development set a Bandai Namco BVH with six channels on every joint and
the CMU backflip's ASF and AMC) are mutated by hypothesis: truncated, bytes
flipped, lines deleted, duplicated or swapped, garbage tokens inserted or
substituted.  A reader must either reject the result with a ValueError (a
TypeError for a label that is not a value; an OSError for undecodable paths)
or return well-formed, finite data; any other exception is a bug in the
reader.  The label readers get mutated JSON label files, label-name files,
JSON values of every kind and label functions returning anything.
"""

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from sklearn_crbm.datasets import (
    Skeleton,
    make_walker,
    read_amc,
    read_bvh,
    read_bvh_folder,
    write_bvh,
)
from sklearn_crbm.utils import check_sequence_ids

SETTINGS = dict(
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

GARBAGE = [
    b"nan", b"inf", b"-inf", b"1e999", b"-1e999", b"1e-320", b"0", b"-0", b"-1",
    b"99999999999999999999", b"1.5e308", b"\xc2\xb2", b"\xd9\xa6", b"\x00", b"\xff",
    b"{", b"}", b"(", b")", b"#", b":", b"::", b"ROOT", b"JOINT", b"End", b"Site",
    b"OFFSET", b"CHANNELS", b"Xrotation", b"Wrotation", b"Xposition", b"MOTION",
    b"HIERARCHY", b"Frames:", b"Frame", b"Time:", b":root", b":bonedata",
    b":hierarchy", b":units", b":documentation", b"begin", b"end", b"name", b"dof",
    b"rx", b"rw", b"tx", b"axis", b"XYZ", b"XXZ", b"direction", b"length",
    b"order", b"position", b"orientation", b"angle", b"rad", b"root", b"lfemur",
    b"upperback", b"\t", b"\r", b"1", b"2", b"3", b"6",
]  # fmt: skip


@st.composite
def mutated(draw, original):
    """``original`` bytes after one to three random mutations."""
    data = original
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(
            st.sampled_from(
                ["truncate", "flip", "delete", "duplicate", "swap", "insert", "replace"]
            )
        )
        lines = data.split(b"\n")
        if kind == "truncate":
            data = data[: draw(st.integers(0, max(len(data) - 1, 0)))]
        elif kind == "flip" and data:
            buffer = bytearray(data)
            for _ in range(draw(st.integers(1, 4))):
                i = draw(st.integers(0, len(buffer) - 1))
                buffer[i] = draw(st.integers(0, 255))
            data = bytes(buffer)
        elif kind == "delete":
            for _ in range(draw(st.integers(1, 5))):
                if lines:
                    del lines[draw(st.integers(0, len(lines) - 1))]
            data = b"\n".join(lines)
        elif kind == "duplicate":
            i = draw(st.integers(0, len(lines) - 1))
            j = draw(st.integers(0, len(lines)))
            lines.insert(j, lines[i])
            data = b"\n".join(lines)
        elif kind == "swap":
            i = draw(st.integers(0, len(lines) - 1))
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
            data = b"\n".join(lines)
        elif kind in ("insert", "replace"):
            for _ in range(draw(st.integers(1, 4))):
                i = draw(st.integers(0, len(lines) - 1))
                words = lines[i].split()
                token = draw(st.sampled_from(GARBAGE))
                if kind == "replace" and words:
                    words[draw(st.integers(0, len(words) - 1))] = token
                else:
                    words.insert(draw(st.integers(0, len(words))), token)
                lines[i] = b" ".join(words)
            data = b"\n".join(lines)
    return data


@pytest.fixture(scope="module")
def originals(real_files, tmp_path_factory):
    """The bytes of a real ASF, the first three frames of a real AMC, and a
    three-frame BVH written from them."""
    skeleton = Skeleton.from_asf(real_files["asf"])
    amc_lines = real_files["amc"].read_bytes().split(b"\n")
    amc = b"\n".join(amc_lines[: 3 + 30 * 3]) + b"\n"
    folder = tmp_path_factory.mktemp("originals")
    (folder / "three.amc").write_bytes(amc)
    data, _ = read_amc(folder / "three.amc", skeleton)
    write_bvh(folder / "three.bvh", data, skeleton, 30.0)
    return {
        "skeleton": skeleton,
        "asf": real_files["asf"].read_bytes(),
        "amc": amc,
        "bvh": (folder / "three.bvh").read_bytes(),
    }


@pytest.fixture(scope="module")
def dev_originals(data_home):
    """The first three frames of a Bandai Namco BVH file (six channels on each
    of 22 joints) and of the CMU backflip's AMC, with its ASF."""
    dev = data_home / "external_dev"
    bandai = (dev / "bandai_namco" / "dataset-2_run_active_001.bvh").read_bytes()
    head, _, motion = bandai.partition(b"MOTION")
    lines = motion.strip().split(b"\n")
    bvh = b"\n".join([head + b"MOTION", b"Frames: 3", lines[1], *lines[2:5], b""])
    asf = dev / "cmu_asfamc_gsimchoni" / "backflip.asf"
    amc = (dev / "cmu_asfamc_gsimchoni" / "backflip.amc").read_bytes().split(b"\n")
    starts = [i for i, line in enumerate(amc) if line.strip() == b"4"]
    return {
        "skeleton": Skeleton.from_asf(asf),
        "asf": asf.read_bytes(),
        "amc": b"\n".join(amc[: starts[0]]) + b"\n",
        "bvh": bvh,
    }


def _check_skeleton(skeleton):
    assert isinstance(skeleton, Skeleton)
    for bone in skeleton.bones:
        assert np.isfinite(bone.direction).all()
        assert np.isfinite(bone.length) and bone.length >= 0
        assert np.isfinite(bone.axis).all()
    assert len(set(skeleton.bone_names)) == len(skeleton.bones)


def _read(kind, path, skeleton):
    """Call the reader; check what it returns when it accepts the file."""
    if kind == "asf":
        _check_skeleton(Skeleton.from_asf(path))
    elif kind == "bvh-skeleton":
        _check_skeleton(Skeleton.from_bvh(path))
    elif kind == "amc":
        data, names = read_amc(path, skeleton)
        assert data.ndim == 2 and data.shape[0] >= 1
        assert data.shape[1] == len(names) == len(skeleton.feature_names)
        assert np.isfinite(data).all()
    else:
        read_skeleton, data, names, frame_rate = read_bvh(path)
        _check_skeleton(read_skeleton)
        assert data.shape == (data.shape[0], len(names))
        assert np.isfinite(data).all()
        assert np.isfinite(frame_rate) and frame_rate > 0


def _fuzz(kind, content, originals, tmp_path):
    path = tmp_path / f"fuzzed.{kind.split('-')[0]}"
    path.write_bytes(content)
    try:
        _read(kind, path, originals["skeleton"])
    except (ValueError, TypeError) as exc:
        # a clear message: it names the file (and the line) or the problem
        assert str(exc)


READERS = ["asf", "amc", "bvh", "bvh-skeleton"]


@pytest.mark.parametrize("kind", READERS)
def test_real_files_are_read(kind, originals, tmp_path):
    path = tmp_path / f"original.{kind.split('-')[0]}"
    path.write_bytes(originals[kind.split("-")[0]])
    _read(kind, path, originals["skeleton"])


@pytest.mark.parametrize("kind", READERS)
@settings(max_examples=120, **SETTINGS)
@given(data=st.data())
def test_mutated_files_raise_only_value_errors(kind, data, originals, tmp_path):
    content = data.draw(mutated(originals[kind.split("-")[0]]))
    _fuzz(kind, content, originals, tmp_path)


@pytest.mark.parametrize("kind", READERS)
@settings(max_examples=40, **SETTINGS)
@given(content=st.binary(max_size=300))
def test_random_bytes_raise_only_value_errors(kind, content, originals, tmp_path):
    _fuzz(kind, content, originals, tmp_path)


@pytest.mark.parametrize("kind", READERS)
@settings(max_examples=40, **SETTINGS)
@given(
    lines=st.lists(
        st.lists(st.sampled_from(GARBAGE), min_size=0, max_size=6), max_size=25
    )
)
def test_token_soup_raises_only_value_errors(kind, lines, originals, tmp_path):
    content = b"\n".join(b" ".join(words) for words in lines)
    _fuzz(kind, content, originals, tmp_path)


@pytest.mark.parametrize("kind", READERS)
@settings(max_examples=40, **SETTINGS)
@given(data=st.data())
def test_mutated_development_files_raise_only_value_errors(
    kind, data, dev_originals, tmp_path
):
    content = data.draw(mutated(dev_originals[kind.split("-")[0]]))
    _fuzz(kind, content, dev_originals, tmp_path)


# ----------------------------------------------------------------- labels
@pytest.fixture(scope="module")
def labelled_folder(tmp_path_factory):
    """Two small BVH files with JSON labels and label names beside them."""
    folder = tmp_path_factory.mktemp("labelled")
    walker = make_walker(n_sequences=1, n_frames=2, random_state=0)
    for name in ("walk_a", "walk_b"):
        write_bvh(folder / f"{name}.bvh", walker.data, walker.skeleton, 30.0)
    return folder


LABEL_JSON = b'{"content": 0, "style": 1}'
LABEL_NAMES = b"active\nelderly\nnormal\n"
json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=4),
    lambda inner: (
        st.lists(inner, max_size=3)
        | st.dictionaries(st.text(max_size=3), inner, max_size=3)
    ),
    max_leaves=6,
)


def _read_labels(folder, json_a, names=None, n_classes=None, **params):
    (folder / "walk_a.json").write_bytes(json_a)
    (folder / "walk_b.json").write_bytes(LABEL_JSON)
    names_file = folder / "style_label.txt"
    names_file.unlink(missing_ok=True)
    if names is not None:
        names_file.write_bytes(names)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            walks = read_bvh_folder(folder, **{"labels": "style", **params})
    except (ValueError, TypeError) as exc:
        assert str(exc)
        return
    assert walks.target.shape == (4,)
    assert 0 <= walks.target.min() and walks.target.max() < len(walks.target_names)
    for name in walks.target_names:
        assert not (isinstance(name, float) and math.isnan(name))
    if n_classes is not None:
        assert len(np.unique(walks.target)) == n_classes


@settings(max_examples=60, **SETTINGS)
@given(data=st.data())
def test_mutated_label_files_raise_only_value_or_type_errors(data, labelled_folder):
    if data.draw(st.booleans()):
        _read_labels(labelled_folder, data.draw(mutated(LABEL_JSON)), LABEL_NAMES)
    else:
        _read_labels(labelled_folder, LABEL_JSON, data.draw(mutated(LABEL_NAMES)))


@settings(max_examples=60, **SETTINGS)
@given(value=json_values, named=st.booleans())
@example(value=float("nan"), named=False)
@example(value=True, named=False)
@example(value=1.0, named=False)
def test_any_json_label_raises_only_value_or_type_errors(value, named, labelled_folder):
    # beside walk_b's label 1, an accepted label is a class of its own unless
    # it is the integer 1
    content = json.dumps({"style": value}).encode()
    same = type(value) is int and value == 1
    _read_labels(
        labelled_folder,
        content,
        LABEL_NAMES if named else None,
        n_classes=None if named else 1 if same else 2,
    )


@settings(max_examples=40, **SETTINGS)
@given(value=json_values | st.binary(max_size=3) | st.tuples(st.integers()))
def test_label_functions_returning_anything_raise_only_value_or_type_errors(
    value, labelled_folder
):
    _read_labels(
        labelled_folder,
        LABEL_JSON,
        labels=lambda path: value if path.stem == "walk_a" else "b",
    )


def test_deeply_nested_bvh_is_a_value_error(tmp_path):
    nested = "".join(f"JOINT j{i}\n{{\nOFFSET 0 0 1\n" for i in range(5000))
    path = tmp_path / "deep.bvh"
    path.write_text(
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\n"
        + nested
        + "}\n" * 5001
        + "MOTION\nFrames: 0\nFrame Time: 0.1\n"
    )
    with pytest.raises(ValueError, match=r"deep\.bvh, line \d+: joints are nested"):
        read_bvh(path)


# ----------------------------------------------------------- sequence ids
id_arrays = st.one_of(
    st.lists(st.integers(-(2**70), 2**70), max_size=8).map(
        lambda v: np.array(v, dtype=object)
    ),
    st.lists(st.floats(), max_size=8).map(np.array),
    st.lists(st.integers(-5, 5), max_size=8).map(np.array),
    st.lists(st.booleans(), max_size=8).map(np.array),
    st.lists(st.text(max_size=2), max_size=8).map(np.array),
    st.lists(
        st.one_of(st.none(), st.integers(0, 3), st.text(max_size=1)), max_size=8
    ).map(lambda v: np.array(v, dtype=object)),
)


@settings(max_examples=150, deadline=None)
@given(ids=id_arrays, n_frames=st.integers(0, 8))
def test_sequence_ids_fail_only_with_value_or_type_errors(ids, n_frames):
    try:
        sequences = check_sequence_ids(ids, n_frames)
    except (ValueError, TypeError) as exc:
        assert "sequence" in str(exc)
        return
    # accepted: the runs tile the frames exactly
    assert sequences.n_frames == n_frames == len(ids)
    assert np.all(sequences.lengths >= 1)
    assert np.array_equal(sequences.starts[1:], sequences.stops[:-1])
    assert len(np.unique(sequences.ids)) == sequences.n_sequences
