"""
==================================
Many styles from one factored CRBM
==================================

One :class:`~sklearn_crbm.FactoredCRBM` learns walks in several styles from
labelled takes and generates whichever style it is asked for, from the same
seed frames: here real frames of a *normal* walk turned into an *active* and
an *elderly* walk, and into a transition from active to elderly half-way.  A
:class:`~sklearn_crbm.metrics.StyleJudge`, a classifier of 2-s windows
trained on the real takes, says which style the generated motion has, frame
by frame, and whether its legs still move like that style's.

The model is small and trains for 200 epochs on three styles of the Bandai
Namco walks (:func:`~sklearn_crbm.datasets.load_bandai_walks`), so that the
example runs in well under a minute; so small and so briefly trained, it
does not keep every style for every training seed.  The defaults of
:class:`~sklearn_crbm.FactoredCRBM` train 600 hidden units for 200 epochs:
``python -m sklearn_crbm styles`` trains them on all seven styles (see
:ref:`styles`).  Without the Bandai data the example runs on synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion, its walks labelled slow or
brisk by their step frequency.
"""

# %%
# Load three styles of labelled walks
# -----------------------------------
import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import FactoredCRBM
from sklearn_crbm.datasets import bone_columns, load_bandai_walks, make_walker
from sklearn_crbm.metrics import StyleJudge, step_frequency
from sklearn_crbm.plotting import plot_motion_strip, plot_style_probabilities
from sklearn_crbm.preprocessing import make_motion_pipeline

sklearn.set_config(enable_metadata_routing=True)

try:
    walks = load_bandai_walks()
    labels = walks.target_names[walks.target]  # the style of every frame
    keep = np.isin(labels, ["normal", "active", "elderly"])
    X, y, ids = walks.data[keep], labels[keep], walks.sequence_ids[keep]
    skeleton, frame_rate = walks.skeleton, walks.frame_rate
    seed_style, first, second = "normal", "active", "elderly"
    legs = ["UpperLeg_L", "UpperLeg_R", "LowerLeg_L", "LowerLeg_R"]
except FileNotFoundError:
    walker = make_walker(n_sequences=8, n_frames=150, random_state=0)
    X, ids = walker.data, walker.sequence_ids
    skeleton, frame_rate = walker.skeleton, walker.frame_rate
    steps = step_frequency(
        X, sequence_ids=ids, features=["lfemur_rx"], feature_names=walker.feature_names
    )
    y = np.where(steps > np.median(steps), "brisk", "slow")[ids]
    seed_style, first, second = "slow", "brisk", "slow"
    legs = ["lfemur", "rfemur", "ltibia", "rtibia"]
print(
    f"{len(X)} frames in {len(np.unique(ids))} takes, styles {sorted(set(y.tolist()))}"
)

# %%
# Train the factored CRBM on the labelled frames
# ----------------------------------------------
# The pipeline preprocesses the raw channels (exponential maps, body-centred
# root, z-scores) and trains the model on them with the label of every frame.
# The takes are used as given: with the styles balanced (the default, which
# suits the full-size model), this small model froze its elderly walk.
model = FactoredCRBM(
    n_components=100,
    n_factors=50,
    n_style_features=20,
    cd_steps=1,
    n_iter=200,
    average_fraction=0.25,
    balance_styles=False,
    random_state=0,
)
pipe = make_motion_pipeline(skeleton, model).fit(X, y, sequence_ids=ids)
Z = pipe[:-1].transform(X, sequence_ids=ids)
judge = StyleJudge(legs=bone_columns(pipe[:-1].get_feature_names_out(), legs))
judge = judge.fit(Z, y, sequence_ids=ids)

# %%
# Generate two styles and a transition from the same seed frames
# --------------------------------------------------------------
# Every sequence starts from real frames of the seed style; ``style`` asks
# for one style throughout, or gives label weights frame by frame, here one
# style for the first half and the other for the second.
n_frames, n_sequences = 400, 3
seeds = pipe.style_windows(
    X, y, sequence_ids=ids, n_windows=n_sequences, random_state=0
)[seed_style]
switch = n_frames // 2
transition = np.zeros((n_frames, len(model.classes_)))
transition[:switch, list(model.classes_).index(first)] = 1.0
transition[switch:, list(model.classes_).index(second)] = 1.0
requests = {first: first, second: second, "transition": transition}
generated = {
    name: pipe.sample(
        n_frames, history=seeds, style=style, n_sequences=n_sequences, random_state=0
    )
    for name, style in requests.items()
}
generated_ids = np.repeat(np.arange(n_sequences), n_frames)

# %%
# The judge's verdict: every generated 2-s window from frame 100 on (of the
# transition: from the switch on) should be judged as the style asked for, and
# alive: its leg amplitude and step frequency within 25% and 15% of that
# style's real windows.
for name, raw in generated.items():
    Z_new = pipe[:-1].transform(raw, sequence_ids=generated_ids)
    style = second if name == "transition" else name
    verdict = judge.verdict(Z_new, style, sequence_ids=generated_ids)
    judged = verdict.starts >= (switch if name == "transition" else 100)
    print(
        f"{name:<11} {verdict.correct[judged].mean():.0%} of the windows judged "
        f"as {style}, {verdict.alive[judged].mean():.0%} alive"
    )

# %%
# Each style, real and generated
# ------------------------------
# Every 4th of the last 60 generated frames of the first sequence of each
# style, under 60 frames of a real take of that style (grey).
fig, axes = plt.subplots(4, 1, figsize=(12, 9))
for row, style in enumerate([first, second]):
    real = X[ids == ids[np.flatnonzero(y == style)[0]]][:60]
    plot_motion_strip(skeleton, real, step=4, ax=axes[2 * row], color="0.5")
    axes[2 * row].set_title(f"real {style} walk")
    plot_motion_strip(
        skeleton,
        generated[style][n_frames - 60 : n_frames],
        step=4,
        ax=axes[2 * row + 1],
    )
    axes[2 * row + 1].set_title(
        f"generated {style} walk, seeded with a {seed_style} walk: frames "
        f"{n_frames - 59}-{n_frames}"
    )
fig.tight_layout()
plt.show()

# %%
# A transition, and the judge's view of it
# ----------------------------------------
# The whole first sequence of the transition, and the probability the judge
# gives each style at every frame; the dashed line marks the switch of the
# labels.  A frame's probability is the mean over the 2-s windows that hold
# it, so the curves move up to 2 s before and after the motion does.
fig, (top, bottom) = plt.subplots(2, 1, figsize=(12, 6))
raw = generated["transition"][:n_frames]
plot_motion_strip(skeleton, raw, ax=top)
top.set_title(f"{first}, then {second} from frame {switch}")
proba = judge.predict_proba(pipe[:-1].transform(raw), per="frame")
plot_style_probabilities(
    proba, classes=judge.classes_, frame_rate=frame_rate, ax=bottom
)
bottom.axvline(switch / frame_rate, color="0.3", linestyle="--")
bottom.set_title("the style judge's probability of each style")
fig.tight_layout()
plt.show()
