"""Metrics for motion: the paper's fill-in error and generated-motion statistics.

:func:`judge_generated_motion` puts the statistics together: the style of
every generated sequence and whether it died out, stalled or blew up.
"""

from ._fillin import fillin_angle_rmse, fillin_error
from ._generation import (
    forward_speed,
    gait_statistics,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
    step_frequency,
)
from ._judge import judge_generated_motion

__all__ = [
    "fillin_angle_rmse",
    "fillin_error",
    "forward_speed",
    "gait_statistics",
    "judge_generated_motion",
    "motion_amplitude",
    "nearest_style",
    "spectral_similarity",
    "step_frequency",
]
