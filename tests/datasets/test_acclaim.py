"""ASF and AMC files: reading, writing, round trips and malformed files."""

import re

import numpy as np
import pytest

from sklearn_crbm.datasets import Skeleton, load_cmu35, make_walker, read_amc, write_amc


@pytest.fixture(scope="module")
def asf_path(data_home):
    return data_home / "cmu_subject35" / "35.asf"


@pytest.fixture(scope="module")
def amc_path(data_home):
    return data_home / "cmu_subject35" / "35_01.amc"


@pytest.fixture(scope="module")
def skeleton(asf_path):
    return Skeleton.from_asf(asf_path)


@pytest.fixture(scope="module")
def trial(amc_path, skeleton):
    return read_amc(amc_path, skeleton)


def _line_error(path, lineno):
    """Regex for an error message naming ``path`` and ``line lineno``."""
    return re.escape(f"{path}, line {lineno}:")


def test_read_amc_35_01(trial, skeleton):
    data, names = trial
    assert data.shape == (358, 62)
    assert data.dtype == np.float64
    np.testing.assert_array_equal(names, skeleton.feature_names)
    # frame 1 as printed in the file
    i = list(names).index
    np.testing.assert_array_equal(
        data[0, :6], [4.40047, 17.8934, -21.0986, -0.943965, -8.37963, -7.42612]
    )
    assert data[0, i("rfemur_rz")] == 34.5122
    assert data[0, i("ltoes_rx")] == 1.09177
    assert data[-1, i("ltoes_rx")] == -23.3886


def test_read_amc_takes_the_asf_path(amc_path, asf_path, trial):
    data, names = read_amc(amc_path, asf_path)
    np.testing.assert_array_equal(data, trial[0])


def test_cmu35_rows_are_35_01_every_4th_frame(data_home, trial):
    cmu = load_cmu35(data_home)
    np.testing.assert_array_equal(cmu.data[:90], trial[0][::4])
    np.testing.assert_array_equal(cmu.feature_names, trial[1])


def test_write_read_amc_round_trip(tmp_path, trial, skeleton):
    data, names = trial
    path = tmp_path / "copy.amc"
    write_amc(path, data, skeleton)
    again, again_names = read_amc(path, skeleton)
    np.testing.assert_array_equal(again_names, names)
    np.testing.assert_allclose(again, data, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(again, data)  # shortest repr: exact
    text = path.read_text().splitlines()
    assert text[1:5] == [
        ":FULLY-SPECIFIED",
        ":DEGREES",
        "1",
        "root 4.40047 17.8934 -21.0986 -0.943965 -8.37963 -7.42612",
    ]


def test_write_amc_orders_columns_by_name(tmp_path, trial, skeleton):
    data, names = trial
    order = np.random.default_rng(0).permutation(len(names))
    write_amc(tmp_path / "a.amc", data[:4], skeleton)
    write_amc(tmp_path / "b.amc", data[:4, order], skeleton, feature_names=names[order])
    assert (tmp_path / "a.amc").read_text() == (tmp_path / "b.amc").read_text()


def test_write_amc_rejects_missing_channels_and_nan(tmp_path, trial, skeleton):
    data, names = trial
    with pytest.raises(ValueError, match="lack these channels.*root_tx"):
        write_amc(tmp_path / "a.amc", data[:2, 1:], skeleton, feature_names=names[1:])
    bad = data[:2].copy()
    bad[1, 5] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        write_amc(tmp_path / "a.amc", bad, skeleton)


def test_write_amc_of_synthetic_walker(tmp_path):
    walker = make_walker(n_sequences=1, n_frames=10, random_state=1)
    write_amc(tmp_path / "walk.amc", walker.data, walker.skeleton)
    data, _ = read_amc(tmp_path / "walk.amc", walker.skeleton)
    np.testing.assert_array_equal(data, walker.data)


# ----------------------------------------------------------- malformed AMC
def _amc_lines(amc_path):
    return amc_path.read_text().splitlines()


def _write(tmp_path, lines, name="bad.amc"):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def test_amc_bad_number_names_file_and_line(tmp_path, amc_path, skeleton):
    lines = _amc_lines(amc_path)
    lines[6] = "upperback 0.47251 2.8x4449 2.26157"  # line 7 of the file
    path = _write(tmp_path, lines)
    with pytest.raises(ValueError, match=_line_error(path, 7) + ".*'2.8x4449'"):
        read_amc(path, skeleton)


def test_amc_truncated_frame_names_file_and_line(tmp_path, amc_path, skeleton):
    lines = _amc_lines(amc_path)
    last_frame = max(i for i, line in enumerate(lines) if line.strip() == "358")
    path = _write(tmp_path, lines[: last_frame + 10])
    with pytest.raises(
        ValueError, match=_line_error(path, last_frame + 1) + ".*lacks bones"
    ):
        read_amc(path, skeleton)


def test_amc_unknown_bone_names_file_and_line(tmp_path, amc_path, skeleton):
    lines = _amc_lines(amc_path)
    lines[40] = "tail 1 2 3"
    path = _write(tmp_path, lines)
    with pytest.raises(
        ValueError, match=_line_error(path, 41) + ".*unknown bone 'tail'"
    ):
        read_amc(path, skeleton)


def test_amc_wrong_number_of_values(tmp_path, amc_path, skeleton):
    lines = _amc_lines(amc_path)
    lines[8] = "lowerneck -15.9456 -3.55911"
    path = _write(tmp_path, lines)
    with pytest.raises(
        ValueError, match=_line_error(path, 9) + ".*2 values, expected 3"
    ):
        read_amc(path, skeleton)


def test_amc_values_before_a_frame_number(tmp_path, amc_path, skeleton):
    lines = _amc_lines(amc_path)
    del lines[3]  # the "1" of the first frame
    path = _write(tmp_path, lines)
    with pytest.raises(
        ValueError, match=_line_error(path, 4) + ".*expected a frame number"
    ):
        read_amc(path, skeleton)


def test_amc_bone_twice_in_a_frame(tmp_path, amc_path, skeleton):
    lines = _amc_lines(amc_path)
    lines[6] = lines[5]
    path = _write(tmp_path, lines)
    with pytest.raises(ValueError, match=_line_error(path, 7) + ".*twice"):
        read_amc(path, skeleton)


# ----------------------------------------------------------- malformed ASF
def _asf_with(tmp_path, asf_path, old, new):
    text = asf_path.read_text()
    assert old in text
    path = tmp_path / "bad.asf"
    path.write_text(text.replace(old, new, 1))
    return path


def _lineno(path, fragment):
    lines = path.read_text().splitlines()
    return next(i for i, line in enumerate(lines, start=1) if fragment in line)


def test_asf_missing_root_section(tmp_path, asf_path):
    path = _asf_with(tmp_path, asf_path, ":root", ":rooot")
    n_lines = len(path.read_text().splitlines())
    with pytest.raises(ValueError, match=_line_error(path, n_lines) + ".*':root'"):
        Skeleton.from_asf(path)


def test_asf_bad_number(tmp_path, asf_path):
    path = _asf_with(tmp_path, asf_path, "length 7.41015", "length 7.4l015")
    lineno = _lineno(path, "7.4l015")
    with pytest.raises(ValueError, match=_line_error(path, lineno) + ".*'7.4l015'"):
        Skeleton.from_asf(path)


def test_asf_unknown_bone_in_hierarchy(tmp_path, asf_path):
    path = _asf_with(tmp_path, asf_path, "lfoot ltoes\n", "lfoot ltoez\n")
    lineno = _lineno(path, "lfoot ltoez")
    with pytest.raises(
        ValueError, match=_line_error(path, lineno) + ".*unknown bone 'ltoez'"
    ):
        Skeleton.from_asf(path)


def test_asf_bone_without_parent(tmp_path, asf_path):
    path = _asf_with(tmp_path, asf_path, "lfoot ltoes\n", "")
    lineno = _lineno(path, "name ltoes") - 2  # its 'begin'
    with pytest.raises(
        ValueError, match=_line_error(path, lineno) + ".*'ltoes' has no parent"
    ):
        Skeleton.from_asf(path)


def test_asf_unsupported_dof(tmp_path, asf_path):
    path = _asf_with(tmp_path, asf_path, "dof rx ry rz", "dof rx ry rz l")
    lineno = _lineno(path, "dof rx ry rz l")
    with pytest.raises(ValueError, match=_line_error(path, lineno) + ".*'l'"):
        Skeleton.from_asf(path)


def test_asf_unclosed_bone_block(tmp_path, asf_path):
    text = asf_path.read_text()
    path = tmp_path / "bad.asf"
    path.write_text(text.replace("  end\n  begin\n     id 2", "  begin\n     id 2", 1))
    lineno = _lineno(path, "id 2") - 1
    with pytest.raises(ValueError, match=_line_error(path, lineno) + ".*missing 'end'"):
        Skeleton.from_asf(path)


def test_asf_in_radians(tmp_path, asf_path, skeleton):
    text = asf_path.read_text().replace(
        "axis 0 0 20  XYZ", "axis 0 0 0.3490658503988659  XYZ", 1
    )
    path = tmp_path / "rad.asf"
    path.write_text(text.replace("angle deg", "angle rad"))
    sk = Skeleton.from_asf(path)
    assert sk.angle_unit == "rad"
    np.testing.assert_allclose(
        sk.bone("lfemur").axis, [0, 0, 20]
    )  # axis kept in degrees


def test_asf_repeated_dof(tmp_path, asf_path):
    path = _asf_with(tmp_path, asf_path, "dof rx ry rz", "dof rx rx rz")
    lineno = _lineno(path, "name lfemur") - 2
    with pytest.raises(ValueError, match=_line_error(path, lineno) + ".*repeats"):
        Skeleton.from_asf(path)


def test_asf_truncated_inside_a_bone(tmp_path, asf_path):
    lines = asf_path.read_text().splitlines()
    cut = next(i for i, line in enumerate(lines) if "name lfemur" in line) + 3
    path = tmp_path / "cut.asf"
    path.write_text("\n".join(lines[:cut]) + "\n")
    with pytest.raises(ValueError, match=_line_error(path, cut - 4) + ".*no 'end'"):
        Skeleton.from_asf(path)


def test_asf_bones_in_a_cycle(tmp_path, asf_path):
    path = _asf_with(
        tmp_path, asf_path, "lfoot ltoes\n", "lfoot ltoes\n    ltoes lhipjoint\n"
    )
    path.write_text(
        path.read_text().replace("root lhipjoint rhipjoint", "root rhipjoint")
    )
    n_lines = len(path.read_text().splitlines())
    with pytest.raises(
        ValueError, match=_line_error(path, n_lines) + ".*not connected"
    ):
        Skeleton.from_asf(path)
