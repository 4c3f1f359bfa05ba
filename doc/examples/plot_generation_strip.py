"""
=======================================================
Walking and jogging from one model (the paper's Fig. 3)
=======================================================

Taylor, Hinton & Roweis (2006, §4.1) train a single conditional RBM on the
walks and jogs of CMU subject 35 and let it generate: seeded with three
frames of walking it walks, seeded with three frames of jogging it jogs.  This
example does the same and draws every 4th generated frame side by side, as in
the paper's Fig. 3, with the real trial the seed came from for comparison.

The model is trained with the default ``history_noise``: noise on the past
frames that feed the directed connections, which keeps long generated sequences in
their style (``benchmarks/paper_generation.py`` measures it; with the paper's
schedule alone, some training seeds turn every walk into a jog).  The
generated frames go back to raw joint angles through the preprocessing's exact
``inverse_transform`` and to joint positions through the skeleton's forward
kinematics.  Without the CMU data the example runs on the synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion.

The figures and a GIF of the generated walk are also written to the folder
``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default: ``sklearn_crbm_examples`` in the
temporary folder).
"""

# %%
# Load and preprocess the motion
# ------------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_walker
from sklearn_crbm.plotting import animate_motion, plot_motion_strip, save_animation
from sklearn_crbm.preprocessing import make_motion_preprocessor

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
    n_iter = 1000
except FileNotFoundError:
    motion = make_walker(n_sequences=4, n_frames=120, random_state=0)
    n_iter = 300

preprocessor = make_motion_preprocessor(motion.skeleton)
Z = preprocessor.fit_transform(motion.data, sequence_ids=motion.sequence_ids)
print(f"{Z.shape[0]} frames of {Z.shape[1]} preprocessed channels")

# %%
# Train one model on walking and jogging
# --------------------------------------
# 200 hidden units and order 3 as in the paper; about half a minute on a
# laptop core.
model = ConditionalRBM(200, order=3, n_iter=n_iter, random_state=0).fit(
    Z.astype(np.float32), sequence_ids=motion.sequence_ids
)

# %%
# Generate from a walk seed and a jog seed
# ----------------------------------------
# Each seed is three consecutive real frames; the model generates 240 new
# frames (8 seconds) from each, 30 alternating Gibbs iterations per frame.
styles = list(dict.fromkeys(motion.motion))  # "walk", "jog" (synthetic: "walk")
trials = [int(np.flatnonzero(motion.motion == style)[0]) for style in styles]
seeds = np.stack([Z[motion.sequence_ids == trial][10:13] for trial in trials])
n_new = 240
generated = model.sample(n_new, history=seeds, random_state=0)
generated_ids = np.repeat(np.arange(len(trials)), n_new)
raw = preprocessor.inverse_transform(
    generated.astype(np.float64), sequence_ids=generated_ids
)

# %%
# Draw every 4th frame, as in Fig. 3
# ----------------------------------
# The last 60 generated frames (6 to 8 seconds after the seed) on top of
# each pair, the real trial the seed came from below; the stick figures move
# from left to right with the skeleton's up axis vertical.
fig, axes = plt.subplots(2 * len(trials), 1, figsize=(12, 2.6 * 2 * len(trials)))
for k, (style, trial) in enumerate(zip(styles, trials, strict=True)):
    real = motion.data[motion.sequence_ids == trial][13 : 13 + 60]
    late = raw[generated_ids == k][-60:]
    plot_motion_strip(motion.skeleton, late, step=4, ax=axes[2 * k])
    axes[2 * k].set_title(f"generated from a {style} seed, frames {n_new - 59}-{n_new}")
    plot_motion_strip(motion.skeleton, real, step=4, ax=axes[2 * k + 1], color="0.4")
    axes[2 * k + 1].set_title(f"real {style} ({motion.sequence_names[trial]})")
fig.tight_layout()
fig.savefig(OUTPUT / "generation_strip.png", dpi=90)

# %%
# Animate the generated walk
# --------------------------
# ``save_animation`` writes a GIF (Pillow) or an HTML player; in a notebook,
# ``IPython.display.HTML(motion_to_html(skeleton, frames))`` plays it inline.
animation = animate_motion(
    motion.skeleton, raw[generated_ids == 0], title="generated walk"
)
save_animation(animation, OUTPUT / "generated_walk.gif", dpi=60)
print(f"figures written to {OUTPUT}")
plt.show()
