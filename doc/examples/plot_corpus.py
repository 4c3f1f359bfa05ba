"""
===================================================
Any content in any style from one model of a corpus
===================================================

One :class:`~sklearn_crbm.LabelledCRBM` learns a corpus of several contents,
each in several styles, with two label factors: the content and the style of
every frame, each one-hot into the model's context, their contributions
adding.  Asked for a pair of labels, it generates that content in that
style, also a pair it never saw: here the elderly runs are held out of
training, and the model is asked for one all the same.  Every sequence starts
from the same real frames of a normal walk.

The takes are three contents (walk, run, left-hand wave) in three styles of
the Bandai Namco dataset-2 (:func:`~sklearn_crbm.datasets.load_bandai_dataset2`),
two takes of each; the model is small (100 hidden units) and trains for 300
epochs at three times the default learning rate, so that the example runs in
well under a minute.  So small and so briefly trained, it does not keep every
cell alive: its waves come to rest (a ``GenerationWarning`` names each cell
that does).  See :ref:`corpus` for the whole corpus and how the generated
motion is judged.  Without the Bandai data the example runs on
synthetic :func:`~sklearn_crbm.datasets.make_walker` walks, labelled slow or
brisk by their step frequency and short or long by their stride.

The GIF of every content in every style, contents down and styles across, is
written to the folder ``$SKLEARN_CRBM_EXAMPLES_OUTPUT`` (default:
``sklearn_crbm_examples`` in the temporary folder).
"""

# %%
# Load a few cells of the corpus
# ------------------------------
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import sklearn

from sklearn_crbm import LabelledCRBM
from sklearn_crbm.datasets import load_bandai_dataset2, make_walker
from sklearn_crbm.metrics import motion_amplitude, step_frequency
from sklearn_crbm.plotting import animate_motions, save_animation
from sklearn_crbm.preprocessing import make_motion_pipeline

sklearn.set_config(enable_metadata_routing=True)
OUTPUT = Path(
    os.environ.get(
        "SKLEARN_CRBM_EXAMPLES_OUTPUT",
        Path(tempfile.gettempdir()) / "sklearn_crbm_examples",
    )
)
OUTPUT.mkdir(parents=True, exist_ok=True)

try:
    corpus = load_bandai_dataset2(
        contents=["walk", "run", "wave-left-hand"],
        styles=["normal", "elderly", "exhausted"],
        takes=[1, 2],
    )
    X, y, ids = corpus.data, corpus.target, corpus.sequence_ids
    skeleton, frame_rate = corpus.skeleton, corpus.frame_rate
    contents, styles = (list(names) for names in corpus.target_names)
    held_out, seed = ("run", "elderly"), ("walk", "normal")
except FileNotFoundError:
    walker = make_walker(n_sequences=12, n_frames=150, random_state=0)
    X, ids = walker.data, walker.sequence_ids
    skeleton, frame_rate = walker.skeleton, walker.frame_rate
    hips = dict(features=["lfemur_rx"], feature_names=walker.feature_names)
    steps = step_frequency(X, sequence_ids=ids, **hips)
    strides = motion_amplitude(X, sequence_ids=ids, **hips)
    content = np.where(steps > np.median(steps), "brisk", "slow")
    style = np.where(strides > np.median(strides), "long", "short")
    y = np.column_stack([content, style])[ids]
    contents, styles = ["slow", "brisk"], ["short", "long"]
    held_out, seed = ("brisk", "long"), ("slow", "short")
cells = sorted({tuple(labels) for labels in y.tolist()})
print(f"{len(X)} frames in {len(np.unique(ids))} takes; cells: {cells}")

# %%
# Fit one model of every content and style, one cell held out
# -----------------------------------------------------------
# ``y`` has one column per factor; ``classes_`` becomes a list with the
# labels of each.
train = ~np.all(y == held_out, axis=1)
model = LabelledCRBM(n_components=100, n_iter=300, learning_rate=3e-3, random_state=0)
pipe = make_motion_pipeline(skeleton, model)
pipe.fit(X[train], y[train], sequence_ids=ids[train])
print("labels of each factor:", [names.tolist() for names in model.classes_])

# %%
# Generate every cell from the same seed
# --------------------------------------
# ``y=(content, style)`` asks for one pair for all the generated frames; the
# seed is real frames of the seed cell, drawn from the training takes
# (``style_windows`` keys the windows of a 2-D ``y`` by the tuple of labels).
n_frames = 240
seeds = pipe.style_windows(
    X[train], y[train], sequence_ids=ids[train], n_windows=1, random_state=0
)[seed]
generated = {
    (content, style): pipe.sample(
        n_frames, history=seeds, y=(content, style), random_state=0
    )
    for content in contents
    for style in styles
}

# %%
# The grid: contents down, styles across
# --------------------------------------
# :func:`~sklearn_crbm.plotting.animate_motions` with ``ncols`` lays one
# panel per cell out row by row; the last 120 generated frames of each, every
# other frame (real time at half the frames), all seen from the side.  The
# cell held out of training is marked.
titles = [
    f"{content}, {style}" + (" (never seen)" if (content, style) == held_out else "")
    for content, style in generated
]
animation = animate_motions(
    skeleton,
    [raw[-120:] for raw in generated.values()],
    titles=titles,
    ncols=len(styles),
    frame_rate=frame_rate,
    step=2,
    view="side",
)
save_animation(animation, OUTPUT / "corpus_grid.gif", frame_rate=frame_rate / 2, dpi=50)
print(f"wrote {OUTPUT / 'corpus_grid.gif'}")
plt.show()
