"""Training with the default BLAS environment against one BLAS thread.

numpy and scipy each load their own OpenBLAS, which by default starts one
thread per core.  The package picks its own thread count for its loops
(``sklearn_crbm.set_config(blas_threads="auto")``, one thread at batch 100);
this script checks that a user who changes nothing gets one-thread speed.

It trains two models, each run in a fresh Python process:

- ``crbm``: ``ConditionalRBM(random_state=0)`` on CMU subject 35 (the
  package's preprocessing) for ``--epochs`` epochs: products of 5e6
  multiply-adds, where one thread is right;
- ``factored``: ``FactoredCRBM(1000, n_factors=200, batch_size=1000)`` on
  synthetic oscillations (2 x 520 frames, 100 channels, a style per
  sequence) for ``--factored-epochs`` epochs: products of 2e8 multiply-adds,
  where the package should pick more than one thread;

in three environments:

- ``default``: no ``*_NUM_THREADS`` variable set, the package's defaults;
- ``one thread``: ``OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1``, the speed to
  match;
- ``all threads``: the default environment with
  ``sklearn_crbm.set_config(blas_threads=<cores>)``, what every call did
  before the package chose (``--old-epochs`` epochs: it can be very slow).

Each is run ``--repeats`` times, alternating, on the quiet machine and again
while a busy process of this script's own spins on one core ("loaded").
Reports milliseconds per epoch (median of the repeats; a warm-up epoch is
not timed), the BLAS threads the package chose for training, and the ratio
of default to one thread; done when it is at most 1.2 for ``crbm`` both quiet
and loaded.

Run from the repository root (about four minutes)::

    python benchmarks/bench_threads.py
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from functools import partial

from _common import (
    announce,
    child_json,
    load_training_data,
    print_table,
    seconds,
    write_json,
)
from _common import parser as make_parser

THREAD_VARIABLES = (
    "OPENBLAS_NUM_THREADS OMP_NUM_THREADS MKL_NUM_THREADS BLIS_NUM_THREADS "
    "VECLIB_MAXIMUM_THREADS NUMEXPR_NUM_THREADS"
).split()
TARGET = 1.2


def environments():
    """``name -> (environment variables, package blas_threads setting)``."""
    default = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
    one = {**default, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    return {
        "default": (default, None),
        "one thread": (one, None),
        "all threads": (default, os.cpu_count()),
    }


MODELS = ("crbm", "factored")


def training_problem(model_name, data_home, epochs):
    """``(model, X, y, sequence_ids)`` of one benchmarked training run."""
    from sklearn_crbm import ConditionalRBM, FactoredCRBM
    from sklearn_crbm.datasets import make_oscillations

    if model_name == "crbm":
        Z, ids, _ = load_training_data("cmu35", data_home)
        return ConditionalRBM(n_iter=epochs, random_state=0), Z, None, ids
    X, ids = make_oscillations(
        n_sequences=2, n_frames=520, n_features=100, random_state=0
    )
    model = FactoredCRBM(
        1000,
        n_factors=200,
        n_style_features=2,
        order=2,
        batch_size=1000,
        n_iter=epochs,
        random_state=0,
    )
    return model, X, ids, ids


def train_in_child(model_name, data_home, epochs, blas_threads):
    """Child process: ms per epoch, and the BLAS threads training ran with."""
    import sklearn_crbm
    from sklearn_crbm.utils._threads import (
        _blas_controller,
        _chosen_threads,
        _product_size,
        batch_rows,
    )

    if blas_threads is not None:
        sklearn_crbm.set_config(blas_threads=blas_threads)
    model, X, y, ids = training_problem(model_name, data_home, 1)
    model.fit(X, y, sequence_ids=ids)  # warm up
    model, X, y, ids = training_problem(model_name, data_home, epochs)
    threads = _chosen_threads(
        _blas_controller(), lambda: _product_size(batch_rows, model, (X, y), {})
    )
    elapsed = seconds(partial(model.fit, X, y, sequence_ids=ids))
    print(json.dumps({"ms_per_epoch": 1000 * elapsed / epochs, "threads": threads}))


def epochs_of(model_name, environment, args):
    if model_name == "factored":
        return args.factored_epochs
    return args.old_epochs if environment == "all threads" else args.epochs


def measure(load, model_name, args):
    """Per environment: the median ms per epoch, every run's, and the threads."""
    busy = None
    if load == "loaded":
        busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        time.sleep(1.0)
    try:
        times = {name: [] for name in environments()}
        threads = {}
        for _ in range(args.repeats):
            for name, (env, blas_threads) in environments().items():
                child = [__file__, "--child", "--data-home", str(args.data_home)]
                child += ["--epochs", str(epochs_of(model_name, name, args))]
                child += ["--child-model", model_name]
                if blas_threads is not None:
                    child += ["--child-blas-threads", str(blas_threads)]
                result = child_json(child, env)
                times[name].append(result["ms_per_epoch"])
                threads[name] = result["threads"]
    finally:
        if busy is not None:
            busy.terminate()
            busy.wait()
    medians = {name: statistics.median(values) for name, values in times.items()}
    return medians, times, threads


def main():
    parser = make_parser(__doc__, seeds=None)
    parser.add_argument("--epochs", type=int, default=100, help="timed epochs")
    parser.add_argument(
        "--old-epochs", type=int, default=10, help="timed epochs of 'all threads'"
    )
    parser.add_argument(
        "--factored-epochs", type=int, default=3, help="timed epochs of 'factored'"
    )
    parser.add_argument("--repeats", type=int, default=3, help="runs per row")
    parser.add_argument(
        "--models", nargs="+", choices=MODELS, default=list(MODELS), help="models"
    )
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--child-model", choices=MODELS, help=argparse.SUPPRESS)
    parser.add_argument("--child-blas-threads", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        train_in_child(
            args.child_model, args.data_home, args.epochs, args.child_blas_threads
        )
        return

    announce()
    rows, raw, ratios = [], {}, {}
    for model_name in args.models:
        for load in ("quiet", "loaded"):
            medians, runs, threads = measure(load, model_name, args)
            raw[f"{model_name} {load}"] = runs
            ratios[model_name, load] = medians["default"] / medians["one thread"]
            for name, ms in medians.items():
                rows.append(
                    dict(
                        model=model_name,
                        load=load,
                        environment=name,
                        threads=threads[name],
                        ms=ms,
                        ratio=ms / medians["one thread"],
                    )
                )
    print_table(
        rows,
        [
            ("model", "model", "s"),
            ("load", "machine", "s"),
            ("environment", "environment", "s"),
            ("threads", "package's threads", "d"),
            ("ms", "ms per epoch", ".1f"),
            ("ratio", "x one thread", ".2f"),
        ],
        title=f"Training, {os.cpu_count()} cores, median of {args.repeats} runs "
        f"(crbm: {args.epochs} epochs, 'all threads' {args.old_epochs}; "
        f"factored: {args.factored_epochs})",
    )
    crbm = [ratio for (name, _), ratio in ratios.items() if name == "crbm"]
    met = all(r <= TARGET for r in crbm)
    for (name, load), ratio in ratios.items():
        print(f"{name}, {load}: default / one thread {ratio:.2f}")
    if crbm:
        print(f"crbm target <= {TARGET}: {'met' if met else 'NOT met'}")
    payload = dict(rows=rows, runs_ms_per_epoch=raw, target=TARGET, met=met)
    write_json("bench_threads", args.output, **payload)


if __name__ == "__main__":
    main()
