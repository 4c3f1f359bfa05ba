"""Metrics for motion: the paper's fill-in error and generated-motion statistics."""

from ._fillin import fillin_angle_rmse, fillin_error
from ._generation import (
    forward_speed,
    gait_statistics,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
    step_frequency,
)

__all__ = [
    "fillin_angle_rmse",
    "fillin_error",
    "forward_speed",
    "gait_statistics",
    "motion_amplitude",
    "nearest_style",
    "spectral_similarity",
    "step_frequency",
]
