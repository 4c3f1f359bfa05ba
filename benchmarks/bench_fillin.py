"""Fill-in speed of CRBMImputer (paper §4.4) on CMU subject 35.

A 200-hidden-unit CRBM of order 3 is trained briefly on the 31 training
trials (speed does not depend on how well it is trained); CRBMImputer then
fills the left leg (lfemur, ltibia, lfoot, ltoes) or the upper body
(lowerback and every bone above it) of the two test trials, erased in every
frame, on-line: frame by frame, 30 Gibbs steps each.  The table gives
filled frames per second for single draws (``n_draws=1``, the paper's
setting) and for the average of several draws, in float64 and float32 with
one BLAS thread.  Real time is 30 frames/s.

Run from the repository root::

    python benchmarks/bench_fillin.py                  # under a minute
    python benchmarks/bench_fillin.py --n-draws 1 10 100 --repeats 5

Prints a table and writes ``benchmarks/results/bench_fillin.json``.
"""

import argparse
import time

import numpy as np
import sklearn
from _common import (
    PAPER,
    add_common_arguments,
    print_table,
    summary,
    threadpool_limits,
    write_json,
)

from sklearn_crbm import ConditionalRBM

REAL_TIME_FPS = 30.0


def load(data_home):
    from sklearn_crbm.datasets import bone_columns, load_cmu35
    from sklearn_crbm.model_selection import paper_body_parts
    from sklearn_crbm.preprocessing import make_motion_preprocessor

    train = load_cmu35(data_home, subset="train")
    test = load_cmu35(data_home, subset="test")
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(train.skeleton)
        Z_train = pre.fit_transform(train.data, sequence_ids=train.sequence_ids)
        Z_test = pre.transform(test.data, sequence_ids=test.sequence_ids)
    names = pre.get_feature_names_out()
    parts = {
        part: bone_columns(names, bones, strict=False)
        for part, bones in paper_body_parts(train.skeleton).items()
    }
    return Z_train, train.sequence_ids, Z_test, test.sequence_ids, parts


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_common_arguments(parser)
    parser.set_defaults(threads=[1], repeats=3)
    parser.add_argument("--n-iter", type=int, default=20, help="training epochs")
    parser.add_argument("--n-draws", type=int, nargs="+", default=[1, 10])
    parser.add_argument("--n-gibbs", type=int, default=30)
    args = parser.parse_args(argv)

    from sklearn_crbm.impute import CRBMImputer

    Z_train, ids_train, Z_test, ids_test, parts = load(args.data_home)
    rows = []
    for dtype in args.dtypes:
        model = ConditionalRBM(
            PAPER["n_components"],
            order=PAPER["order"],
            n_iter=args.n_iter,
            random_state=0,
        )
        for threads in args.threads:
            with threadpool_limits(threads):
                for n_draws in args.n_draws:
                    imputer = CRBMImputer(
                        model, n_gibbs=args.n_gibbs, n_draws=n_draws, random_state=0
                    ).fit(Z_train.astype(dtype), sequence_ids=ids_train)
                    for part, columns in parts.items():
                        X = Z_test.astype(dtype)
                        X[:, columns] = np.nan
                        imputer.transform(X[:20], sequence_ids=ids_test[:20])  # warm up
                        times = []
                        for _ in range(args.repeats):
                            start = time.perf_counter()
                            imputer.transform(X, sequence_ids=ids_test)
                            times.append(time.perf_counter() - start)
                        best = min(times)
                        rows.append(
                            {
                                "dtype": dtype,
                                "threads": threads,
                                "missing": part,
                                "n_missing_channels": len(columns),
                                "n_draws": n_draws,
                                "frames": len(X),
                                "seconds": best,
                                "frames_per_s": len(X) / best,
                                "x_real_time": len(X) / best / REAL_TIME_FPS,
                                "times": summary(times),
                            }
                        )
    columns = [
        ("dtype", "dtype", "s"),
        ("threads", "threads", "d"),
        ("missing", "missing", "s"),
        ("n_missing_channels", "channels", "d"),
        ("n_draws", "draws", "d"),
        ("frames", "frames", "d"),
        ("seconds", "seconds (best)", ".3f"),
        ("frames_per_s", "frames/s", ",.0f"),
        ("x_real_time", "x real time", ",.1f"),
    ]
    print(
        f"CMU 35 test trials 35_18 and 35_29 ({len(Z_test)} frames), {args.n_gibbs} Gibbs steps"
    )
    table = print_table(rows, columns, title="Fill-in with CRBMImputer, 62-200 order 3")
    write_json(
        "bench_fillin", {"args": vars(args), "rows": rows, "table": table}, args.output
    )


if __name__ == "__main__":
    main()
