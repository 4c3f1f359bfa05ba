"""
=======================================================
What the hidden units do over time (the paper's Fig. 1)
=======================================================

The paper's Fig. 1 shows, for a trained model, the probability of each hidden
unit being on given the data, frame by frame, over a sequence that changes
style.  Here a 100-hidden-unit conditional RBM is trained on the walks and
jogs of CMU subject 35 and its hidden probabilities are drawn over a walk
followed by a jog: many units switch with the style, others follow the
phase of the gait cycle.  Without the CMU data the example runs on the
synthetic :func:`~sklearn_crbm.datasets.make_walker` motion.

The figure is also written to ``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default:
``sklearn_crbm_examples`` in the temporary folder).
"""

# %%
# Train a 100-hidden-unit model
# -----------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_walker
from sklearn_crbm.plotting import plot_hidden_activations
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
    picks = [list(motion.sequence_names).index(n) for n in ("35_01", "35_17", "35_02")]
except FileNotFoundError:
    motion = make_walker(n_sequences=3, n_frames=100, random_state=0)
    picks = [0, 1, 2]

preprocessor = make_motion_preprocessor(motion.skeleton)
Z = preprocessor.fit_transform(motion.data, sequence_ids=motion.sequence_ids)
model = ConditionalRBM(100, order=3, n_iter=500, random_state=0).fit(
    Z, sequence_ids=motion.sequence_ids
)

# %%
# Hidden probabilities over a walk, a jog and another walk
# --------------------------------------------------------
# ``transform`` gives p(h = 1 | frame, its 3 past frames) for every frame;
# the first 3 frames of each trial use the trial's first frame as their past.
rows = np.concatenate([np.flatnonzero(motion.sequence_ids == p) for p in picks])
hidden = model.transform(Z[rows], sequence_ids=motion.sequence_ids[rows])
# order the units by how differently they respond to the first two trials
first, second = (motion.sequence_ids[rows] == p for p in picks[:2])
units = np.argsort(hidden[first].mean(axis=0) - hidden[second].mean(axis=0))

fig, ax = plt.subplots(figsize=(10, 5))
plot_hidden_activations(
    hidden[:, units], sequence_ids=motion.sequence_ids[rows], frame_rate=30.0, ax=ax
)
labels = " | ".join(f"{motion.sequence_names[p]} ({motion.motion[p]})" for p in picks)
ax.set_title(f"p(h = 1 | data), units sorted by style preference: {labels}")
fig.tight_layout()
fig.savefig(OUTPUT / "hidden_activations.png", dpi=90)
plt.show()
