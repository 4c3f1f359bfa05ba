"""load_cmu35, load_mit_walk and get_data_home."""

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from sklearn_crbm.datasets import get_data_home, load_cmu35, load_mit_walk


@pytest.fixture(scope="module")
def cmu_all(data_home):
    return load_cmu35(data_home)


def _run_lengths(sequence_ids):
    change = np.flatnonzero(np.diff(sequence_ids)) + 1
    starts = np.r_[0, change]
    return sequence_ids[starts], np.diff(np.r_[starts, len(sequence_ids)])


def test_load_cmu35_all(cmu_all):
    cmu = cmu_all
    assert cmu.data.shape == (2813, 62)
    assert cmu.data.dtype == np.float64
    assert cmu.frame_rate == 30.0
    assert len(cmu.sequence_names) == 33
    assert list(cmu.sequence_names[:3]) == ["35_01", "35_02", "35_03"]
    assert list(cmu.sequence_names[-2:]) == ["35_18", "35_29"]
    assert "35_27" not in cmu.sequence_names
    ids, lengths = _run_lengths(cmu.sequence_ids)
    np.testing.assert_array_equal(ids, np.arange(33))  # one contiguous run each
    assert lengths.sum() == 2813
    assert dict(zip(cmu.sequence_names, lengths, strict=True))["35_29"] == 125
    assert (cmu.motion == "walk").sum() == 23 and (cmu.motion == "jog").sum() == 10
    jogs = {
        name
        for name, motion in zip(cmu.sequence_names, cmu.motion, strict=True)
        if motion == "jog"
    }
    assert jogs == {"35_17", "35_18", *(f"35_{i}" for i in range(19, 27))}
    np.testing.assert_array_equal(cmu.feature_names, cmu.skeleton.feature_names)
    assert cmu.feature_names[0] == "root_tx" and cmu.feature_names[6] == "lfemur_rx"
    assert "mocap.cs.cmu.edu" in cmu.DESCR and "NSF EIA-0196217" in cmu.DESCR


def test_load_cmu35_subsets(cmu_all, data_home):
    train = load_cmu35(data_home, subset="train")
    test = load_cmu35(data_home, subset="test")
    assert train.data.shape == (2644, 62) and test.data.shape == (169, 62)
    assert len(train.sequence_names) == 31
    assert list(test.sequence_names) == ["35_18", "35_29"]
    assert list(test.motion) == ["jog", "walk"]
    np.testing.assert_array_equal(np.bincount(test.sequence_ids), [44, 125])
    np.testing.assert_array_equal(np.r_[train.data, test.data], cmu_all.data)
    raw = scipy.io.loadmat(data_home / "cmu_subject35" / "cmu35WalkJog.mat")
    np.testing.assert_array_equal(test.data, raw["Ytest"])
    np.testing.assert_array_equal(train.sequence_ids, cmu_all.sequence_ids[:2644])


def test_load_cmu35_invalid_subset(data_home):
    with pytest.raises(ValueError, match="subset"):
        load_cmu35(data_home, subset="validation")


def test_missing_data_tells_how_to_fetch(tmp_path):
    with pytest.raises(OSError, match=r"fetch_cmu35\(data_home=.*SKLEARN_CRBM_DATA"):
        load_cmu35(tmp_path / "nowhere")
    with pytest.raises(FileNotFoundError, match=r"fetch_mit_walk\(data_home="):
        load_mit_walk(tmp_path)


def test_get_data_home(monkeypatch, tmp_path):
    monkeypatch.delenv("SKLEARN_CRBM_DATA", raising=False)
    assert get_data_home() == Path.home() / "sklearn_crbm_data"
    monkeypatch.setenv("SKLEARN_CRBM_DATA", str(tmp_path))
    assert get_data_home() == tmp_path
    assert get_data_home(tmp_path / "given") == tmp_path / "given"
    assert get_data_home("~/x") == Path.home() / "x"


def test_loaders_use_the_environment_variable(monkeypatch, data_home):
    monkeypatch.setenv("SKLEARN_CRBM_DATA", str(data_home))
    assert load_cmu35(subset="test").data.shape == (169, 62)


def test_load_mit_walk(data_home):
    mit = load_mit_walk(data_home)
    assert mit.data.shape == (3826, 108)
    assert mit.frame_rate == 30.0
    np.testing.assert_array_equal(np.bincount(mit.sequence_ids), [438, 260, 3128])
    assert len(mit.sequence_names) == 3 and list(mit.motion) == ["walk"] * 3
    assert len(mit.feature_names) == 108
    assert list(mit.feature_names[:6]) == [
        "root_ex",
        "root_ey",
        "root_ez",
        "root_tx",
        "root_ty",
        "root_tz",
    ]
    assert list(mit.feature_names[6:12]) == [
        "lhip_ex",
        "lhip_ey",
        "lhip_ez",
        "lhip_ox",
        "lhip_oy",
        "lhip_oz",
    ]
    assert (mit.skeleton.up_axis, mit.skeleton.angle_unit) == ("z", "rad")
    assert "Hsu" in mit.DESCR
    raw = scipy.io.loadmat(data_home / "taylor_mhmublv_mit" / "data.mat")["Motion"]
    np.testing.assert_array_equal(mit.data[:438], raw.flat[0][::4])
    # Taylor's motion.mat is the same frames after preprocess1, which only
    # changes the six root columns
    motion = scipy.io.loadmat(data_home / "taylor_theano_motion" / "motion.mat")[
        "Motion"
    ]
    np.testing.assert_allclose(
        np.concatenate(list(motion.flat))[:, 6:], mit.data[:, 6:]
    )
