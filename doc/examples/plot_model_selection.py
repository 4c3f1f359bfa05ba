"""
=====================================================
Choosing the order and the hidden units by search
=====================================================

How many past frames should the model look at (``order``), and how many
hidden units does it need (``n_components``)?  This example answers with
scikit-learn's :class:`~sklearn.model_selection.GridSearchCV` over the whole
pipeline, preprocessing included, on CMU subject 35:

- :class:`~sklearn.model_selection.GroupKFold` holds out whole trials, so a
  model is judged on sequences it has never seen;
- ``sequence_ids`` is passed once to ``fit`` and metadata routing hands it to
  every step and to the score, so no history crosses from one trial into the
  next;
- the score is :meth:`ConditionalRBM.score
  <sklearn_crbm.ConditionalRBM.score>`: minus the mean squared error of the
  one-step-ahead prediction of each held-out frame from its past, in z-score
  units.

A second search tunes imputers with
:func:`~sklearn_crbm.model_selection.make_imputation_scorer`, which erases the
left leg of the held-out trials from half-way through and scores the fill.

Without the CMU data the example runs on the synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion.  The figure is also written
to ``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default: ``sklearn_crbm_examples`` in the
temporary folder).
"""

# %%
# Load the training trials
# ------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn
from sklearn.model_selection import GridSearchCV, GroupKFold
from sklearn.pipeline import Pipeline

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_walker
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.model_selection import make_imputation_scorer
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
    motion = load_cmu35(subset="train")  # 31 trials, 2644 frames
except FileNotFoundError:
    motion = make_walker(n_sequences=9, n_frames=100, random_state=0)
X, sequence_ids = motion.data, motion.sequence_ids
n_trials = len(np.unique(sequence_ids))
print(f"{X.shape[0]} frames of {X.shape[1]} channels in {n_trials} trials")

# %%
# Search order and hidden units
# -----------------------------
# Every candidate trains for 50 epochs at the paper's learning rate (the paper
# trains for much longer; the ranking of the orders shows early).
pipeline = Pipeline(
    make_motion_preprocessor(motion.skeleton).steps
    + [("crbm", ConditionalRBM(n_iter=50, random_state=0))]
)
grid = {"crbm__order": [0, 1, 2, 3], "crbm__n_components": [10, 50, 200]}
search = GridSearchCV(pipeline, grid, cv=GroupKFold(n_splits=3))
search.fit(X, groups=sequence_ids, sequence_ids=sequence_ids)

results = search.cv_results_
orders = np.array(results["param_crbm__order"], dtype=int)
units = np.array(results["param_crbm__n_components"], dtype=int)
means, stds = results["mean_test_score"], results["std_test_score"]
print("\norder  n_components  score (minus one-step MSE)")
for order, n, mean, std in zip(orders, units, means, stds, strict=True):
    print(f"{order:5d}  {n:12d}  {mean:8.4f} +/- {std:.4f}")
print(f"\nbest: {search.best_params_}, score {search.best_score_:.4f}")

# For scale: predicting every held-out frame by the mean training frame.
baseline = []
for train, test in GroupKFold(n_splits=3).split(X, groups=sequence_ids):
    scaled = make_motion_preprocessor(motion.skeleton).fit(
        X[train], sequence_ids=sequence_ids[train]
    )
    Z_train = scaled.transform(X[train], sequence_ids=sequence_ids[train])
    Z_test = scaled.transform(X[test], sequence_ids=sequence_ids[test])
    baseline.append(-np.mean(np.square(Z_test - Z_train.mean(axis=0))))
print(f"mean training frame as the prediction: {np.mean(baseline):.4f}")

# %%
# What the scores say
# -------------------
# Any history at all is the big step: without it (``order=0``) the model
# predicts one fixed frame for every time step (its mean-field fixed point,
# which is not the mean frame: it scores worse than the mean training frame
# does), while a single past frame brings the error down by an order of
# magnitude, and more past frames help a little more.  The number of hidden
# units hardly matters for this score: the one-step prediction comes mostly
# from the autoregressive weights, and the scores of 10, 50 and 200 units
# agree to within a small fraction of their spread across folds.  The search
# therefore settles the order with confidence, while among hidden-unit counts
# the "best" one wins by noise: the score does not reward a bigger model for
# being bigger.  (With a larger learning rate or longer training, big models
# overfit the training trials and score worse; the tests show it.)
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for n in np.unique(units):
    pick = units == n
    for axis in ax:
        axis.errorbar(
            orders[pick] + 0.04 * np.log2(n / 50),
            means[pick],
            yerr=stds[pick],
            marker="o",
            capsize=3,
            label=f"{n} hidden units",
        )
ax[0].set_title("All orders")
ax[1].set_title("Orders with history (zoom)")
ax[1].set_xlim(0.5, 3.5)
with_history = orders > 0
ax[1].set_ylim(
    (means - stds)[with_history].min() - 0.01,
    (means + stds)[with_history].max() + 0.01,
)
for axis in ax:
    axis.set_xlabel("order (past frames)")
ax[0].set_xticks(sorted(set(orders)))
ax[1].set_xticks(sorted(set(orders[with_history])))
ax[0].axhline(np.mean(baseline), color="grey", linestyle="--", label="mean frame")
ax[0].set_ylabel("score: minus one-step-ahead MSE")
ax[0].legend()
fig.tight_layout()
fig.savefig(OUTPUT / "model_selection.png", dpi=90)

# %%
# Tune imputers with the imputation scorer
# ----------------------------------------
# The imputers work in the normalised channels the model sees, so the
# preprocessing is fitted once beforehand (on all training trials: the
# scaler's means leak from the held-out trials, which is harmless for a
# comparison).  The scorer erases the left leg from half-way through every
# held-out trial, lets the imputer fill it on-line, and returns minus the
# mean squared error of the fill.  One pipeline with a swappable ``imputer``
# step lets one search compare the nearest-neighbour baseline with
# CRBMImputer of several orders.
preprocessor = make_motion_preprocessor(motion.skeleton)
Z = preprocessor.fit_transform(X, sequence_ids=sequence_ids)
names = preprocessor.get_feature_names_out()
left_leg = [b for b in ("lfemur", "ltibia", "lfoot", "ltoes") if f"{b}_ex" in names]
scorer = make_imputation_scorer(bones=left_leg, feature_names=names, start=0.5)

crbm_imputer = CRBMImputer(
    ConditionalRBM(50, n_iter=50, random_state=0), n_gibbs=10, random_state=0
)
imputer_grid = [
    {"imputer": [NearestNeighborImputer()]},
    {"imputer": [crbm_imputer], "imputer__estimator__order": [1, 3]},
]
imputer_search = GridSearchCV(
    Pipeline([("imputer", NearestNeighborImputer())]),
    imputer_grid,
    scoring=scorer,
    cv=GroupKFold(n_splits=3),
)
imputer_search.fit(Z, groups=sequence_ids, sequence_ids=sequence_ids)

print("\nimputer                        score (minus MSE of the filled leg)")
for params, mean, std in zip(
    imputer_search.cv_results_["params"],
    imputer_search.cv_results_["mean_test_score"],
    imputer_search.cv_results_["std_test_score"],
    strict=True,
):
    label = type(params["imputer"]).__name__
    if "imputer__estimator__order" in params:
        label += f", order {params['imputer__estimator__order']}"
    print(f"{label:30s} {mean:8.4f} +/- {std:.4f}")
plt.show()
