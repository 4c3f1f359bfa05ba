"""Fill-in speed of CRBMImputer (paper §4.4) on CMU subject 35.

A 200-hidden-unit CRBM of order 3 is trained briefly on the paper's 31
training trials (speed does not depend on how well it is trained);
``CRBMImputer`` at its defaults (20 particles per draw) then fills the left
leg or the upper body of the two test trials, erased in every frame, on-line,
30 Gibbs steps per frame, for ``--n-draws`` averaged draws, in float64 and
float32 with one BLAS thread.  "x real time" is against 30 frames per second.

Run from the repository root (under a minute)::

    python benchmarks/bench_fillin.py
    python benchmarks/bench_fillin.py --n-draws 1 10 --repeats 5
"""

from functools import partial

import numpy as np
from _common import (
    PAPER,
    REAL_TIME_FPS,
    Split,
    announce,
    print_table,
    seconds,
    speed_parser,
    summary,
    threadpool_limits,
    write_json,
)

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.impute import CRBMImputer
from sklearn_crbm.model_selection import erasure_mask, paper_body_parts


def main(argv=None):
    p = speed_parser(__doc__, threads=(1,))
    p.set_defaults(repeats=3)
    p.add_argument("--n-draws", type=int, nargs="+", default=[1, 10])
    args = p.parse_args(argv)
    announce()
    split = Split(args.data_home, "paper")
    names = split.preprocessor.get_feature_names_out()
    masks = {
        part: erasure_mask(
            split.X_test, bones=bones, feature_names=names, start=0, strict=False
        )
        for part, bones in paper_body_parts(split.cmu.skeleton).items()
    }
    rows = []
    for dtype in args.dtypes:
        model = ConditionalRBM(PAPER["n_components"], order=PAPER["order"], n_iter=20)
        for threads, n_draws in ((t, n) for t in args.threads for n in args.n_draws):
            imputer = CRBMImputer(model, n_draws=n_draws, random_state=0)
            imputer.fit(split.X_train.astype(dtype), sequence_ids=split.train_ids)
            for part, mask in masks.items():
                X = np.where(mask, np.nan, split.X_test).astype(dtype)
                ids = split.test_ids
                fill = partial(imputer.transform, X, sequence_ids=ids)
                with threadpool_limits(threads):
                    imputer.transform(X[:20], sequence_ids=ids[:20])  # warm up
                    times = [seconds(fill) for _ in range(args.repeats)]
                rows.append(
                    dict(
                        dtype=dtype,
                        threads=threads,
                        missing=part,
                        channels=int(mask.any(axis=0).sum()),
                        n_draws=n_draws,
                        frames=len(X),
                        seconds=min(times),
                        frames_per_s=len(X) / min(times),
                        x_real_time=len(X) / min(times) / REAL_TIME_FPS,
                        times=summary(times),
                    )
                )
    table = print_table(
        rows,
        [
            *("dtype", "threads", "missing", "channels"),
            ("n_draws", "draws", "d"),
            "frames",
            ("seconds", "seconds (best)", ".3f"),
            ("frames_per_s", "frames/s", ",.0f"),
            ("x_real_time", "x real time", ",.1f"),
        ],
        title="\nFill-in with CRBMImputer's defaults, 62-200 order 3",
    )
    write_json("bench_fillin", args.output, args=vars(args), rows=rows, table=table)


if __name__ == "__main__":
    main()
