"""
==================================================
Filling in a lost leg on-line (the paper's Fig. 4)
==================================================

Motion capture loses markers.  Taylor, Hinton & Roweis (2006, §4.4) erase the
left leg of a held-out walk from half-way through and let the trained model
fill it in on-line, frame by frame, from the past frames and the observed
joints of the current frame; the nearest-neighbour fill (copy the leg of the
training frame whose observed joints are closest) is the baseline.  Their
Fig. 4 shows the left hip's angles: the original (solid), the model's fill
(dashed) and the nearest neighbour's (dotted).  This example draws the same
curves for CMU trial 35_29, in the normalised exponential-map channels the
model sees.  Without the CMU data it runs on the synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion.

The figure is also written to ``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default:
``sklearn_crbm_examples`` in the temporary folder).
"""

# %%
# Train on the training trials
# ----------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_walker
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.plotting import plot_filled_channels
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
    train = load_cmu35(subset="train")
    test = load_cmu35(subset="test")
    walk = list(test.sequence_names).index("35_29")
    X_test_raw = test.data[test.sequence_ids == walk]
    n_iter = 1000
except FileNotFoundError:
    train = make_walker(n_sequences=6, n_frames=120, random_state=0)
    X_test_raw = make_walker(n_sequences=1, n_frames=124, random_state=1).data
    n_iter = 300

preprocessor = make_motion_preprocessor(train.skeleton)
Z_train = preprocessor.fit_transform(train.data, sequence_ids=train.sequence_ids)
Z_test = preprocessor.transform(X_test_raw)
names = preprocessor.get_feature_names_out()

imputer = CRBMImputer(
    ConditionalRBM(200, order=3, n_iter=n_iter, random_state=0), random_state=0
).fit(Z_train, sequence_ids=train.sequence_ids)
nearest = NearestNeighborImputer().fit(Z_train)

# %%
# Erase the left leg from half-way through and fill it in
# -------------------------------------------------------
left_leg = [
    i
    for i, n in enumerate(names)
    if n.split("_")[0] in ("lfemur", "ltibia", "lfoot", "ltoes")
]
start = len(Z_test) // 2
Z_missing = Z_test.copy()
Z_missing[start:, left_leg] = np.nan
Z_model = imputer.transform(Z_missing)
Z_nearest = nearest.transform(Z_missing)

for label, filled in (("model", Z_model), ("nearest neighbour", Z_nearest)):
    error = np.square(filled[start:, left_leg] - Z_test[start:, left_leg])
    print(
        f"{label}: mean squared error per joint angle, summed over frames: "
        f"{error.mean(axis=1).sum():.2f}"
    )

# %%
# The left hip's three angles, as in Fig. 4
# -----------------------------------------
hip = [n for n in names if n.startswith("lfemur_")]
axes = plot_filled_channels(
    Z_test,
    Z_model,
    Z_nearest,
    features=hip,
    feature_names=names,
    missing_from=start,
    frame_rate=30.0,
)
axes[0].figure.suptitle("Left hip of walk 35_29, erased from half-way (grey line)")
axes[0].figure.tight_layout()
axes[0].figure.savefig(OUTPUT / "fillin_channels.png", dpi=90)
plt.show()
