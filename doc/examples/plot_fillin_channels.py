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
from sklearn_crbm.metrics import fillin_error
from sklearn_crbm.model_selection import erasure_mask
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
# :func:`~sklearn_crbm.model_selection.erasure_mask` erases from half-way
# through by default (the last half of the frames, rounded down, as in the
# paper); the left leg is the left thigh and every bone below it.
missing = erasure_mask(
    Z_test, bones=train.skeleton.descendants("lfemur"), feature_names=names
)
start = np.flatnonzero(missing.any(axis=1))[0]
Z_missing = np.where(missing, np.nan, Z_test)
Z_model = imputer.transform(Z_missing)
Z_nearest = nearest.transform(Z_missing)

for label, filled in (("model", Z_model), ("nearest neighbour", Z_nearest)):
    error = fillin_error(Z_test, filled, missing_mask=missing)
    print(f"{label}: the paper's error (MSE per frame, summed) {error:.2f}")

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
