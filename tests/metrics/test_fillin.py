"""The fill-in metrics against values computed by hand."""

import numpy as np
import pytest

from sklearn_crbm.metrics import fillin_angle_rmse, fillin_error


def test_fillin_error_hand_computed():
    y_true = np.zeros((4, 3))
    y_pred = np.array(
        [[9.0, 9.0, 9.0], [1.0, 2.0, 0.0], [0.0, 0.0, 3.0], [2.0, 2.0, 2.0]]
    )
    mask = np.array(
        [[False] * 3, [True, True, False], [False, False, True], [True, True, True]]
    )
    # frame 0 not erased; (1 + 4) / 2 + 9 / 1 + (4 + 4 + 4) / 3
    assert fillin_error(y_true, y_pred, missing_mask=mask) == pytest.approx(15.5)


def test_fillin_error_without_mask_sums_per_frame_means():
    y_true = np.array([[1.0, 2.0], [3.0, 4.0]])
    y_pred = np.array([[2.0, 2.0], [3.0, 7.0]])
    assert fillin_error(y_true, y_pred) == pytest.approx(0.5 + 4.5)


def test_fillin_error_ignores_values_outside_the_mask():
    y_true = np.zeros((2, 2))
    y_pred = np.array([[-1e9, 1.0], [1e9, 2.0]])
    mask = np.array([[False, True], [False, True]])
    assert fillin_error(y_true, y_pred, missing_mask=mask) == pytest.approx(5.0)


def test_fillin_error_matches_paper_style_loop():
    rng = np.random.default_rng(0)
    y_true, y_pred = rng.normal(size=(2, 30, 7))
    mask = np.zeros((30, 7), dtype=bool)
    mask[15:, [1, 4, 5]] = True
    expected = sum(
        np.mean((y_true[t, [1, 4, 5]] - y_pred[t, [1, 4, 5]]) ** 2)
        for t in range(15, 30)
    )
    assert fillin_error(y_true, y_pred, missing_mask=mask) == pytest.approx(expected)


def test_angle_rmse_hand_computed_and_wrapped():
    y_true = np.array([[179.0, 10.0, -90.0], [0.0, 20.0, 5.0]])
    y_pred = np.array([[-179.0, 13.0, 270.0], [-4.0, 0.0, 5.0]])
    mask = np.array([[True, True, True], [True, False, False]])
    # differences 2, 3, 0 (270 is -90) and 4 degrees
    assert fillin_angle_rmse(y_true, y_pred, missing_mask=mask) == pytest.approx(
        np.sqrt((4 + 9 + 0 + 16) / 4)
    )


def test_angle_rmse_radians_and_no_period():
    y_true = np.array([[np.pi - 0.1], [0.0]])
    y_pred = np.array([[-np.pi + 0.1], [0.3]])
    assert fillin_angle_rmse(y_true, y_pred, period=2 * np.pi) == pytest.approx(
        np.sqrt((0.2**2 + 0.3**2) / 2)
    )
    assert fillin_angle_rmse(y_true, y_pred, period=None) == pytest.approx(
        np.sqrt(((2 * np.pi - 0.2) ** 2 + 0.3**2) / 2)
    )


@pytest.mark.parametrize("metric", [fillin_error, fillin_angle_rmse])
def test_input_errors(metric):
    y = np.zeros((3, 2))
    with pytest.raises(ValueError, match="same shape"):
        metric(y, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="shape of y_true"):
        metric(y, y, missing_mask=np.ones((3, 3), dtype=bool))
    with pytest.raises(TypeError, match="booleans"):
        metric(y, y, missing_mask=np.ones((3, 2)))
    with pytest.raises(ValueError, match="no entry"):
        metric(y, y, missing_mask=np.zeros((3, 2), dtype=bool))


def test_angle_rmse_rejects_bad_period():
    y = np.zeros((2, 2))
    with pytest.raises(ValueError, match="period"):
        fillin_angle_rmse(y, y, period=-1.0)
