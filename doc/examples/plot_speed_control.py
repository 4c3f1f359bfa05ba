"""
=================================================
A walk that speeds up into a jog and slows down
=================================================

One :class:`~sklearn_crbm.ConditionalRBM` is trained on the walks and jogs of
CMU subject 35 with every frame's forward speed as its ``context``, as Taylor,
Hinton & Roweis (2011) conditioned their models on real-valued style inputs.
At generation the speed is no longer measured but requested, frame by frame:
3 seconds at the walks' mean speed, 5 seconds speeding up to the jogs', 4
seconds of jogging, 5 seconds slowing down and 3 more of walking, from one
seed of real walking.  The model goes through gaits it never saw (no training
trial runs at half-way speeds) and changes its gait, not only its speed: the
jog has its own stride, lean and arm swing.

:class:`~sklearn_crbm.preprocessing.MotionContext` measures the speed of the
training trials and, with the same smoothing, of the generated motion; the
speed goes to the model z-scored, on the scale of the preprocessed channels.
Without the CMU data the example runs on the synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion, whose walks differ less in
speed.

The figures and a GIF of the generated motion are also written to the folder
``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default: ``sklearn_crbm_examples`` in the
temporary folder).
"""

# %%
# Measure the speed of every training frame
# -----------------------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_walker
from sklearn_crbm.plotting import animate_motion, plot_motion_strip, save_animation
from sklearn_crbm.preprocessing import MotionContext, make_motion_pipeline

sklearn.set_config(enable_metadata_routing=True)
OUTPUT = Path(
    os.environ.get(
        "SKLEARN_CRBM_EXAMPLES_OUTPUT",
        Path(tempfile.gettempdir()) / "sklearn_crbm_examples",
    )
)
OUTPUT.mkdir(parents=True, exist_ok=True)

try:
    motion = load_cmu35()
    n_iter = "auto"
except FileNotFoundError:
    motion = make_walker(n_sequences=6, n_frames=120, random_state=0)
    n_iter = 300
ids = motion.sequence_ids

speed = MotionContext(motion.skeleton, signals=["forward_speed"])
speeds = speed.fit_transform(motion.data, sequence_ids=ids)
styles = np.asarray(motion.motion)[ids]
style_speeds = [speeds[styles == s].mean() for s in dict.fromkeys(styles)]
if len(style_speeds) == 2:  # the walks' and the jogs' mean
    slow, fast = style_speeds
else:  # the synthetic walks: their slowest and fastest
    slow, fast = np.percentile(speeds, [5, 95])
print(f"mean forward speed: {slow:.1f} and {fast:.1f} length units per second")

# %%
# Train on the motion and its speed
# ---------------------------------
# The default model in the default pipeline; ``context`` reaches the model
# through metadata routing, as ``sequence_ids`` reaches every step, in the
# data's units (the model standardises it).  A few minutes on a laptop core.
pipeline = make_motion_pipeline(
    motion.skeleton, ConditionalRBM(n_iter=n_iter, random_state=0)
)
pipeline.fit(motion.data, sequence_ids=ids, context=speeds)

# %%
# Ask for a walk that speeds up into a jog and back
# -------------------------------------------------
# One requested speed per generated frame, 30 frames per second, from a
# window of real walking.
seconds = [(3, slow, slow), (5, slow, fast), (4, fast, fast), (5, fast, slow)]
seconds.append((3, slow, slow))
requested = np.concatenate(
    [np.linspace(a, b, 30 * n, endpoint=False) for n, a, b in seconds]
)
walk_seed = pipeline.style_windows(
    motion.data, styles, sequence_ids=ids, n_windows=1, random_state=0
)[styles[0]]
raw = pipeline.sample(
    len(requested),
    history=walk_seed,
    context=requested[:, None],
    random_state=0,
)
generated = speed.transform(raw)[:, 0]

fig, ax = plt.subplots(figsize=(9, 3))
time = np.arange(len(requested)) / 30
ax.plot(time, requested, label="requested")
ax.plot(time, generated, label="generated (1-s window)")
ax.set_xlabel("seconds")
ax.set_ylabel("forward speed (units/s)")
ax.legend()
fig.tight_layout()
fig.savefig(OUTPUT / "speed_control.png", dpi=90)
print(f"correlation: {np.corrcoef(requested, generated)[0, 1]:.3f}")

# %%
# Look at the gaits
# -----------------
# Every 4th frame of two seconds of each phase: the walk at the start, the
# jog at full speed, the walk again after slowing down.
phases = {"walking": 30, "jogging": 270, "walking again": 540}
fig, axes = plt.subplots(len(phases), 1, figsize=(12, 2.6 * len(phases)))
for panel, (name, start) in zip(axes, phases.items(), strict=True):
    plot_motion_strip(motion.skeleton, raw[start : start + 60], step=4, ax=panel)
    panel.set_title(f"{name}: seconds {start // 30} to {start // 30 + 2}")
fig.tight_layout()
fig.savefig(OUTPUT / "speed_control_strip.png", dpi=90)

# %%
# Animate it
# ----------
animation = animate_motion(motion.skeleton, raw, title="walk, jog, walk")
save_animation(animation, OUTPUT / "speed_control.gif", dpi=60)
print(f"figures written to {OUTPUT}")
plt.show()
