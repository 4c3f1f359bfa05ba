"""
==================================================
Generated walks and jogs for every training seed
==================================================

A model is only as good as its worst training seed: whether a conditional RBM
keeps generating lively walks and jogs used to depend on the seed alone (a walk
that freezes, a jog that shuffles in place with its legs barely moving). This
example trains one model per training seed with the defaults of
:class:`~sklearn_crbm.ConditionalRBM` (200 hidden units, order 3, 1000 epochs:
``ConditionalRBM(random_state=seed)``), lets each generate 300 frames from a
walk seed and from a jog seed, and draws every 4th of the last 60 generated
frames beside the real motion, one strip per seed and style, with each
sequence's leg amplitude (RMS of the per-channel standard deviations of the hip
and knee channels over its last 100 frames) against the real trials of its
style. ``benchmarks/generation_seeds.py`` measures the same on 12 sequences per
seed over 1000 frames.

Without the CMU data the example runs on the synthetic
:func:`~sklearn_crbm.datasets.make_walker` motion (walking only).  The
figure is also written to ``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default:
``sklearn_crbm_examples`` in the temporary folder).
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
from sklearn_crbm.metrics import motion_amplitude
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
    motion = load_cmu35()
    settings, seeds = {}, [0, 1, 2, 3, 4]  # the defaults
except FileNotFoundError:
    motion = make_walker(n_sequences=4, n_frames=120, random_state=0)
    settings, seeds = dict(n_iter=200), [0, 1]

preprocessor = make_motion_preprocessor(motion.skeleton)
Z = preprocessor.fit_transform(motion.data, sequence_ids=motion.sequence_ids)
names = preprocessor.get_feature_names_out()
legs = [n for n in names if n.split("_")[0] in ("lfemur", "rfemur", "ltibia", "rtibia")]
legs = legs or list(names)  # the synthetic skeleton names its bones otherwise


def leg_amplitude(frames, ids=None):
    return motion_amplitude(
        frames, sequence_ids=ids, feature_names=names, features=legs
    )


# %%
# One model per training seed, defaults otherwise
# -----------------------------------------------
# Each generates 300 frames from three real frames of a walk and of a jog.
styles = list(dict.fromkeys(motion.motion))  # "walk", "jog" (synthetic: "walk")
trials = [int(np.flatnonzero(motion.motion == style)[0]) for style in styles]
history = np.stack([Z[motion.sequence_ids == trial][10:13] for trial in trials])
real_amplitude = {
    style: float(
        np.mean(
            leg_amplitude(Z, motion.sequence_ids)[np.asarray(motion.motion) == style]
        )
    )
    for style in styles
}
n_new = 300
generated = {}
for seed in seeds:
    model = ConditionalRBM(random_state=seed, **settings)
    model.fit(Z.astype(np.float32), sequence_ids=motion.sequence_ids)
    frames = model.sample(n_new, history=history, random_state=seed)
    generated[seed] = frames.reshape(len(styles), n_new, -1)

# %%
# Every 4th of the last 60 frames, seed by seed
# ---------------------------------------------
# For each style the real trial first (grey), then the sequence each
# training seed generated, with its leg amplitude over its last 100 frames.
rows = [(style, None) for style in styles] + [
    (style, seed) for style in styles for seed in seeds
]
rows.sort(key=lambda row: (styles.index(row[0]), row[1] is not None))
fig, axes = plt.subplots(len(rows), 1, figsize=(12, 1.9 * len(rows)))
for ax, (style, seed) in zip(axes, rows, strict=True):
    k = styles.index(style)
    if seed is None:
        real = motion.data[motion.sequence_ids == trials[k]][:60]
        plot_motion_strip(motion.skeleton, real, step=4, ax=ax, color="0.4")
        ax.set_title(
            f"real {style} ({motion.sequence_names[trials[k]]}), leg amplitude of "
            f"the real {style}s {real_amplitude[style]:.2f}"
        )
        continue
    frames = generated[seed][k]
    raw = preprocessor.inverse_transform(frames[-60:].astype(np.float64))
    plot_motion_strip(motion.skeleton, raw, step=4, ax=ax)
    ax.set_title(
        f"training seed {seed}, generated from a {style} seed: frames "
        f"{n_new - 59}-{n_new}, leg amplitude {leg_amplitude(frames[-100:])[0]:.2f}"
    )
fig.tight_layout()
fig.savefig(OUTPUT / "generation_seeds.png", dpi=70)
print(f"figure written to {OUTPUT / 'generation_seeds.png'}")
plt.show()
