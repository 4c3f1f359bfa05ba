"""write_bvh(..., channels="source"): the file's own channel layout, read back exactly."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import Skeleton, make_walker, read_bvh, write_bvh


def _dev_files(data_home):
    return sorted((data_home / "external_dev").glob("*/*.bvh")) + [
        data_home / "odd_files" / "dataset-1_dash_normal_001.bvh"
    ]


def test_source_layout_round_trips_every_development_file(data_home, tmp_path):
    files = _dev_files(data_home)
    assert len(files) == 24
    for path in files:
        skeleton, data, names, rate = read_bvh(path)
        out = tmp_path / path.name
        write_bvh(out, data, skeleton, rate, channels="source")
        again, data_again, names_again, rate_again = read_bvh(out)
        assert_array_equal(data_again, data)
        assert list(names_again) == list(names)
        assert rate_again == pytest.approx(rate, rel=1e-12)
        assert again.bone_names == skeleton.bone_names
        assert again.up_axis == skeleton.up_axis
        for a, b in zip(again.bones, skeleton.bones, strict=True):
            assert (a.parent, a.channels, a.rotation_order) == (
                b.parent, b.channels, b.rotation_order
            )  # fmt: skip
            assert_array_equal(a.offset, b.offset)


def test_source_layout_keeps_six_channels_per_joint(data_home, tmp_path):
    path = data_home / "external_dev" / "bandai_namco" / "dataset-2_run_active_001.bvh"
    skeleton, data, names, rate = read_bvh(path)
    write_bvh(tmp_path / "six.bvh", data, skeleton, rate, channels="source")
    write_bvh(tmp_path / "portable.bvh", data, skeleton, rate)
    assert read_bvh(tmp_path / "six.bvh")[1].shape[1] == 132
    assert read_bvh(tmp_path / "portable.bvh")[1].shape[1] < 132
    text = (tmp_path / "six.bvh").read_text()
    assert text.count("CHANNELS 6 Xposition Yposition Zposition") == 22


def test_source_layout_needs_a_bvh_skeleton(data_home, tmp_path):
    skeleton = Skeleton.from_asf(data_home / "cmu_subject35" / "35.asf")
    data = np.zeros((2, len(skeleton.feature_names)))
    with pytest.raises(ValueError, match="channels='source'.*channels='portable'"):
        write_bvh(tmp_path / "a.bvh", data, skeleton, 30.0, channels="source")
    walker = make_walker(n_sequences=1, n_frames=2, random_state=0)
    with pytest.raises(ValueError, match="channels must be 'portable' or 'source'"):
        write_bvh(tmp_path / "a.bvh", walker.data, walker.skeleton, 30.0, channels="x")
    skeleton, data, _, rate = read_bvh(
        data_home / "external_dev" / "bandai_namco" / "dataset-2_run_active_001.bvh"
    )
    with pytest.raises(ValueError, match="root=.*channels='source'"):
        write_bvh(
            tmp_path / "a.bvh", data, skeleton, rate, root="Hips", channels="source"
        )
