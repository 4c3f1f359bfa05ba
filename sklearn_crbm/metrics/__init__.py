"""Metrics for motion: the paper's fill-in error, generated-motion statistics, style.

:func:`judge_generated_motion` puts the statistics together: the style of
every generated sequence and whether it died out, stalled or blew up.
:class:`StyleJudge` names the style of windows of motion and whether they
move like it.
"""

from ._divergence import divergence
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
from ._liveliness import liveliness, most_moving_channels
from ._positions import foot_skating, jitter
from ._style import StyleJudge

__all__ = [
    "StyleJudge",
    "divergence",
    "fillin_angle_rmse",
    "fillin_error",
    "foot_skating",
    "forward_speed",
    "gait_statistics",
    "jitter",
    "judge_generated_motion",
    "liveliness",
    "most_moving_channels",
    "motion_amplitude",
    "nearest_style",
    "spectral_similarity",
    "step_frequency",
]
