"""compare_imputers: every imputer scored on every case, as the cases score fills."""

import numpy as np
import pytest
from sklearn.impute import KNNImputer

from sklearn_crbm import ConditionalRBM, CRBMImputer
from sklearn_crbm.datasets import make_walker
from sklearn_crbm.impute import NearestNeighborImputer
from sklearn_crbm.model_selection import compare_imputers, make_fillin_cases
from sklearn_crbm.preprocessing import make_motion_preprocessor


@pytest.fixture(scope="module")
def fitted():
    walker = make_walker(n_sequences=4, n_frames=50, random_state=0)
    train = walker.sequence_ids < 3
    pre = make_motion_preprocessor(walker.skeleton)
    Z = pre.fit_transform(walker.data[train])
    cases = make_fillin_cases(walker, pre, trials={"walk": "walk_3", "also": "walk_2"})
    imputers = {
        "NN": NearestNeighborImputer().fit(Z),
        "KNN(5)": KNNImputer(n_neighbors=5).fit(Z),
        "CRBM": CRBMImputer(
            ConditionalRBM(8, order=2, n_iter=3, random_state=0), random_state=0
        ).fit(Z),
    }
    return imputers, cases


def test_scores_are_the_cases_errors_of_each_fill(fitted):
    imputers, cases = fitted
    scores = compare_imputers(imputers, cases)
    assert list(scores) == list(imputers)
    for name, imputer in imputers.items():
        assert list(scores[name]) == list(cases)
        for key, case in cases.items():
            error, degrees = case.errors(imputer.transform(case.X_missing))
            assert scores[name][key] == {
                "error": float(error),
                "angle_rmse": float(degrees),
            }


def test_repeats_average_single_draws_of_imputers_that_sample(fitted):
    imputers, cases = fitted
    scores = compare_imputers(imputers, cases, n_repeats=3, random_state=7)
    case = cases["walk", "left leg"]
    draws = imputers["CRBM"].sample(case.X_missing, n_samples=3, random_state=7)
    errors = np.array([case.errors(draw) for draw in draws])
    assert scores["CRBM"]["walk", "left leg"]["error"] == pytest.approx(
        errors[:, 0].mean(), rel=1e-12
    )
    assert scores["CRBM"]["walk", "left leg"]["angle_rmse"] == pytest.approx(
        errors[:, 1].mean(), rel=1e-12
    )
    # the draws differ, so their mean error is not that of one draw
    assert len(set(errors[:, 0])) == 3
    # deterministic imputers fill once, whatever n_repeats
    assert scores["NN"] == compare_imputers({"NN": imputers["NN"]}, cases)["NN"]
    # same random_state, same numbers
    again = compare_imputers(imputers, cases, n_repeats=3, random_state=7)
    assert again == scores


@pytest.mark.parametrize(
    "imputers, n_repeats, error, match",
    [
        ({}, None, TypeError, "non-empty dict"),
        ([KNNImputer()], None, TypeError, "non-empty dict"),
        ({"KNN": KNNImputer()}, 0, ValueError, "n_repeats must be None or an int"),
        ({"KNN": KNNImputer()}, 2.5, ValueError, "n_repeats must be None or an int"),
    ],
)
def test_bad_arguments_say_what_is_wrong(imputers, n_repeats, error, match):
    with pytest.raises(error, match=match):
        compare_imputers(imputers, {}, n_repeats=n_repeats)
