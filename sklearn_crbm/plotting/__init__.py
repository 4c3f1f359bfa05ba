"""Pictures of motion and of what a model learned (needs matplotlib).

Install matplotlib with the ``plot`` extra: ``pip install sklearn_crbm[plot]``.
matplotlib is imported only when a function is called.

- :func:`plot_skeleton`: one frame as a stick figure, up axis vertical.
- :func:`plot_motion_strip`: every few frames side by side (paper Fig. 3).
- :func:`animate_motion`, :func:`save_animation`, :func:`motion_to_html`:
  a moving stick figure as a matplotlib animation, a GIF/MP4/HTML file, or
  an HTML/JavaScript player for notebooks; :func:`animate_motions`: several
  sequences side by side (real beside generated, one per style), optionally
  over the probability of each style.
- :func:`plot_hidden_activations`: hidden probabilities over frames
  (paper Fig. 1).
- :func:`plot_filled_channels`: filled-in against true channels, with a
  nearest-neighbour fill (paper Fig. 4).
- :func:`plot_style_probabilities`: the probability of each style over the
  frames of a sequence (a style judge's verdict on a transition).
"""

from ._animation import (
    animate_motion,
    animate_motions,
    motion_to_html,
    save_animation,
)
from ._figures import (
    plot_filled_channels,
    plot_hidden_activations,
    plot_style_probabilities,
)
from ._skeleton import plot_motion_strip, plot_skeleton

__all__ = [
    "animate_motion",
    "animate_motions",
    "motion_to_html",
    "plot_filled_channels",
    "plot_hidden_activations",
    "plot_motion_strip",
    "plot_skeleton",
    "plot_style_probabilities",
    "save_animation",
]
