"""Metrics for motion: the paper's fill-in error, generated-motion statistics, style."""

from ._fillin import fillin_angle_rmse, fillin_error
from ._generation import (
    forward_speed,
    gait_statistics,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
    step_frequency,
)
from ._style import StyleJudge

__all__ = [
    "StyleJudge",
    "fillin_angle_rmse",
    "fillin_error",
    "forward_speed",
    "gait_statistics",
    "motion_amplitude",
    "nearest_style",
    "spectral_similarity",
    "step_frequency",
]
