"""The module names that stored pickles give, resolved where the classes live now."""

import importlib
import pickle
import sys
from pathlib import Path

import pytest

import sklearn_crbm
from sklearn_crbm.layers import CRBMLayer
from sklearn_crbm.utils._persistence import MOVED_MODULES

DATA = Path(__file__).parent / "data"


@pytest.mark.parametrize("old", sorted(MOVED_MODULES))
def test_an_old_module_name_gives_the_classes_where_they_live_now(old):
    module = importlib.import_module(old)
    new = importlib.import_module(MOVED_MODULES[old])
    names = [name for name, value in vars(new).items() if isinstance(value, type)]
    assert names
    for name in names:
        assert getattr(module, name) is getattr(new, name)
    with pytest.raises(AttributeError):
        module.no_such_class  # noqa: B018


def test_a_renamed_class_is_found_under_its_old_name():
    assert importlib.import_module("sklearn_crbm._labelled").LabelledLayer is CRBMLayer


def test_old_names_answer_what_tools_ask_of_every_module():
    # inspect, hypothesis and doctest read __file__ and the like of every
    # module in sys.modules, those a pickle of format 0 made too
    with pytest.raises(ValueError, match="pickle format 0"):
        pickle.loads((DATA / "crbm_08bf639.pkl").read_bytes())
    for name, module in list(sys.modules.items()):
        if name.startswith("sklearn_crbm"):
            getattr(module, "__file__", None)
            getattr(module, "__wrapped__", None)
    removed = sys.modules["sklearn_crbm._crbm_math"]
    with pytest.raises(AttributeError):
        removed.anything_else  # noqa: B018
    assert sklearn_crbm.ConditionalRBM.__module__ == "sklearn_crbm.models._crbm"
