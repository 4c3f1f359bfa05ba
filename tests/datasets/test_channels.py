import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import bone_columns, load_cmu35


def test_bone_columns_select_by_name():
    names = ["root_tx", "lfemur_ex", "lfemur_ey", "lfemur_ez", "ltibia_ex", "rfemur_ex"]
    assert_array_equal(bone_columns(names, ["ltibia", "lfemur"]), [1, 2, 3, 4])
    assert_array_equal(bone_columns(np.array(names), "rfemur"), [5])
    with pytest.raises(ValueError, match="No column belongs to bone 'lhand'"):
        bone_columns(names, ["lhand"])
    assert_array_equal(bone_columns(names, ["lhand", "rfemur"], strict=False), [5])
    with pytest.raises(ValueError, match="None of the bones"):
        bone_columns(names, ["lhand"], strict=False)


def test_descendants_give_the_paper_body_parts(data_home):
    skeleton = load_cmu35(data_home, subset="test").skeleton
    assert skeleton.descendants("lfemur") == ["lfemur", "ltibia", "lfoot", "ltoes"]
    upper = skeleton.descendants("lowerback")
    assert upper[0] == "lowerback" and "head" in upper and "rthumb" in upper
    assert not {"lfemur", "rfemur", "root"} & set(upper)
    with pytest.raises(ValueError):
        skeleton.descendants("tail")
