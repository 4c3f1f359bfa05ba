"""
==============================================
Generating from a two-level model (paper §5)
==============================================

A :class:`~sklearn_crbm.StackedCRBM` adds layers like a deep belief net: the
first conditional RBM models the motion, the second models the sequence of the
first layer's hidden probabilities, and generation runs top-down as Taylor's
two-level code did: the top layer generates its own sequence, and one
deterministic pass through the first layer turns it into motion.  Seeding a
two-level model of order 3 takes ``2 * 3 = 6`` real frames
(``stack.history_length``).

This example trains the two-level model on Taylor's MIT walking data and
draws every 4th generated frame, early and late in a 300-frame sequence, side
by side; ``horizontal="facing"`` shows each figure from its own side, since
the MIT subject walks in curves.
Without the MIT data it runs on the synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion.  The figure is also written
to ``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default: ``sklearn_crbm_examples`` in the
temporary folder).
"""

# %%
# Train the two-level model
# -------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import StackedCRBM
from sklearn_crbm.datasets import load_mit_walk, make_walker
from sklearn_crbm.plotting import plot_motion_strip
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
    motion = load_mit_walk()
    n_iter = 500
except FileNotFoundError:
    motion = make_walker(n_sequences=4, n_frames=120, random_state=0)
    n_iter = 200

preprocessor = make_motion_preprocessor(motion.skeleton)
Z = preprocessor.fit_transform(motion.data, sequence_ids=motion.sequence_ids)
stack = StackedCRBM(
    (200, 200), order=3, n_iter=n_iter, history_noise=0.4, random_state=0
).fit(Z.astype(np.float32), sequence_ids=motion.sequence_ids)
print(f"{Z.shape[1]} channels; seeding needs {stack.history_length} frames")

# %%
# Generate top-down and draw the last frames
# ------------------------------------------
seed = Z[motion.sequence_ids == motion.sequence_ids[-1]][
    100 : 100 + stack.history_length
]
generated = stack.sample(300, history=seed, random_state=0)
raw = preprocessor.inverse_transform(generated.astype(np.float64))

fig, axes = plt.subplots(2, 1, figsize=(12, 5.5))
plot_motion_strip(motion.skeleton, raw[:60], step=4, horizontal="facing", ax=axes[0])
axes[0].set_title("two-level model: generated frames 1-60")
plot_motion_strip(
    motion.skeleton, raw[240:300], step=4, horizontal="facing", ax=axes[1]
)
axes[1].set_title("generated frames 241-300")
fig.tight_layout()
fig.savefig(OUTPUT / "stacked_generation.png", dpi=90)
plt.show()
