"""Style recognition: FactoredCRBM's predict and predict_proba on held-out takes.

The Bandai walks (default preprocessing fitted on takes 001-005); a
default-size ``FactoredCRBM`` trained on them for ``--n-iter`` epochs
(recognition's time does not depend on it); the first ``--frames`` (120)
frames of every take 006.  Per seed, one BLAS thread: wall and CPU seconds
of ``predict`` then ``predict_proba`` of the same frames, of
``predict_proba`` alone on a fresh model, and the takes recognised; means
over seeds with 95% bootstrap intervals.

Run from the repository root::

    python benchmarks/recognition.py --seeds 0 1 2
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import copy  # noqa: E402

import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from _common import (  # noqa: E402
    announce,
    bootstrap_mean,
    parser,
    print_table,
    time_both,
    write_json,
)

from sklearn_crbm import FactoredCRBM  # noqa: E402
from sklearn_crbm.datasets import load_bandai_walks  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402


def held_out_split(data_home, n_frames):
    """Training frames (takes 001-005) and the first frames of every take 006."""
    walks = load_bandai_walks(data_home)
    takes = walks.takes[walks.sequence_ids]
    ids = walks.sequence_ids
    position = np.arange(len(ids)) - np.searchsorted(ids, ids)
    train = takes <= 5
    test = (takes == 6) & (position < n_frames)
    labels = walks.target_names[walks.target]
    with sklearn.config_context(enable_metadata_routing=True):
        preprocessor = make_motion_preprocessor(walks.skeleton)
        Z = preprocessor.fit_transform(walks.data[train], sequence_ids=ids[train])
        Z_test = preprocessor.transform(walks.data[test], sequence_ids=ids[test])
    return (Z, labels[train], ids[train]), (Z_test, labels[test], ids[test])


def fitted(train, n_iter, seed):
    X, y, ids = train
    model = FactoredCRBM(n_iter=n_iter, random_state=seed)
    fit_seconds = time_both(lambda: model.fit(X, y, sequence_ids=ids))[0]
    return model, fit_seconds


def measure(model, test):
    X, y, ids = test
    fresh = copy.deepcopy(model)  # no posterior kept for these frames
    alone_wall, alone_cpu = time_both(lambda: fresh.predict_proba(X, sequence_ids=ids))
    result = {}

    def both():
        result["predicted"] = model.predict(X, sequence_ids=ids)
        result["proba"] = model.predict_proba(X, sequence_ids=ids)

    wall, cpu = time_both(both)
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    correct = result["predicted"][starts] == y[starts]
    agree = np.array_equal(
        model.classes_[result["proba"].argmax(axis=1)], result["predicted"]
    )
    return {
        "wall": wall,
        "cpu": cpu,
        "proba_alone": alone_wall,
        "proba_alone_cpu": alone_cpu,
        "recognised": float(correct.mean()),
        "predict_agrees_with_proba": agree,
    }


def main():
    p = parser(__doc__, seeds=(0, 1, 2))
    p.add_argument("--n-iter", type=int, default=20, help="training epochs")
    p.add_argument("--frames", type=int, default=120, help="frames of each take 006")
    args = p.parse_args()
    announce()
    train, test = held_out_split(args.data_home, args.frames)
    n_styles = len(np.unique(test[1]))
    print(
        f"{len(train[0])} training frames, {len(test[0])} recognised frames of "
        f"{n_styles} styles, {train[0].shape[1]} channels; FactoredCRBM of the "
        f"default size, {args.n_iter} epochs"
    )
    per_seed = []
    for seed in args.seeds:
        model, fit_seconds = fitted(train, args.n_iter, seed)
        per_seed.append({"seed": seed, "fit_s": fit_seconds, **measure(model, test)})
        print(per_seed[-1], flush=True)
    rows = []
    for key, name in (
        ("wall", "predict + predict_proba, wall s"),
        ("cpu", "predict + predict_proba, CPU s"),
        ("proba_alone", "predict_proba alone, wall s"),
        ("proba_alone_cpu", "predict_proba alone, CPU s"),
        ("recognised", "takes recognised"),
    ):
        mean, low, high = bootstrap_mean([r[key] for r in per_seed])
        rows.append(
            {"measure": name, "mean": mean, "interval": f"[{low:.2f}, {high:.2f}]"}
        )
    print_table(
        rows,
        ["measure", ("mean", "mean", ".2f"), ("interval", "95% interval", "")],
        title=f"\nrecognition of {len(test[0])} frames of {n_styles} styles, "
        f"seeds {args.seeds}",
    )
    write_json(
        "recognition",
        args.output,
        n_iter=args.n_iter,
        n_frames=len(test[0]),
        n_styles=n_styles,
        per_seed=per_seed,
        table=rows,
    )


if __name__ == "__main__":
    main()
