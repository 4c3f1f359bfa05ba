"""Command line: ``python -m sklearn_crbm {demo,fetch,fit,sample}``.

``demo`` is the package's main job: the paper's experiments on CMU subject
35 in a few minutes (train, fill in against nearest neighbour, generate
walking and jogging, draw figures).
"""

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

import joblib
import numpy as np
import sklearn
from sklearn.pipeline import Pipeline

from ._crbm import ConditionalRBM
from .datasets import (
    fetch_cmu35,
    fetch_mit_walk,
    get_data_home,
    load_cmu35,
    write_amc,
)
from .impute import CRBMImputer, NearestNeighborImputer
from .metrics import gait_statistics, nearest_style
from .model_selection import make_fillin_cases
from .preprocessing import make_motion_preprocessor
from .utils import random_windows

__all__ = ["main"]

# The demo writes here unless --output says otherwise: never into the current
# folder, which in a checkout is the repository.
DEMO_OUTPUT = Path(tempfile.gettempdir()) / "sklearn_crbm_demo"
# Stick figures in the demo's strip of a generated sequence.
STRIP_FIGURES = 30
# The model options default to the estimator's own defaults.
_DEFAULTS = ConditionalRBM()
# Seed windows of each style that ``fit`` saves with the model, for ``sample``.
N_STYLE_WINDOWS = 50

PAPER_FILLIN = {
    ("walk", "left leg"): (8.78, 11.68),
    ("walk", "upper body"): (20.52, 22.20),
}


def main(argv=None):
    """Run the command line; returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        with sklearn.config_context(enable_metadata_routing=True):
            return args.run(args)
    except (OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1


def _parser():
    parser = argparse.ArgumentParser(
        prog="python -m sklearn_crbm",
        description="Conditional RBMs for human motion (Taylor, Hinton & Roweis 2006).",
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")

    demo = commands.add_parser(
        "demo",
        help="the paper's demo on CMU 35: train, fill in, generate, draw",
        description="Train a CRBM on CMU subject 35, print the fill-in table "
        "against nearest neighbour, generate walking and jogging, and write "
        "figures. The defaults take about a minute on 2 cores; --full runs the "
        "paper's 4000 epochs and 100 fill-in repeats.",
    )
    _add_data_home(demo)
    _add_model_options(demo, n_iter=1000)
    demo.add_argument(
        "--output",
        type=Path,
        default=DEMO_OUTPUT,
        help="folder for the figures and the generated motion (AMC files)",
    )
    demo.add_argument(
        "--n-repeats",
        type=int,
        default=20,
        help="single-draw fills averaged per case (the paper: 100)",
    )
    demo.add_argument(
        "--n-particles",
        type=int,
        default=20,
        help="weighted particles per fill-in chain (1: the original scheme)",
    )
    demo.add_argument(
        "--n-frames", type=int, default=300, help="frames generated per sequence"
    )
    demo.add_argument(
        "--full",
        action="store_true",
        help="the paper's full size: 4000 epochs, 100 fill-in repeats",
    )
    demo.add_argument(
        "--no-figures",
        action="store_true",
        help="skip the figures (the AMC files are still written)",
    )
    demo.set_defaults(run=run_demo)

    fetch = commands.add_parser(
        "fetch", help="download CMU 35 and the MIT walking data"
    )
    _add_data_home(fetch)
    fetch.set_defaults(run=run_fetch)

    fit = commands.add_parser(
        "fit", help="train preprocessing + CRBM on CMU 35 and save it with joblib"
    )
    _add_data_home(fit)
    _add_model_options(fit, n_iter=1000)
    fit.add_argument(
        "--output",
        type=Path,
        default=Path("crbm_cmu35.joblib"),
        help="file the fitted pipeline (preprocessing + CRBM) is saved to",
    )
    fit.set_defaults(run=run_fit)

    sample = commands.add_parser(
        "sample",
        help="generate motion from a saved model and write AMC files",
        description="Generate motion from a model saved by the fit command and "
        "write one AMC file per sequence. The seed frames are saved with the "
        "model: no data is read.",
    )
    sample.add_argument("model", type=Path, help="a file written by the fit command")
    sample.add_argument(
        "--style",
        choices=("walk", "jog", "any"),
        default="walk",
        help="seed each sequence with real frames of this style ('any': the "
        "model's own seed windows, from every training trial)",
    )
    sample.add_argument(
        "--n-frames", type=int, default=300, help="frames generated per sequence"
    )
    sample.add_argument(
        "--n-sequences", type=int, default=1, help="sequences generated"
    )
    sample.add_argument(
        "--hidden-noise",
        type=float,
        default=0.0,
        help="noise on the hidden biases (the paper's style transitions: about 1)",
    )
    sample.add_argument(
        "--seed", type=int, default=0, help="random seed of the seeds and sampling"
    )
    sample.add_argument(
        "--output",
        type=Path,
        default=Path("generated"),
        help="prefix of the AMC files written (PREFIX_0.amc, PREFIX_1.amc, ...)",
    )
    sample.set_defaults(run=run_sample)
    for command in (demo, fetch, fit, sample):
        command.formatter_class = _HelpFormatter
    return parser


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Ends every option's help with its default, where it has one to show."""

    def _get_help_string(self, action):
        no_default = action.default is None or action.default is False
        if no_default or "default" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def _add_data_home(parser):
    parser.add_argument(
        "--data-home",
        type=Path,
        default=None,
        help="data folder (default: $SKLEARN_CRBM_DATA, else ~/sklearn_crbm_data)",
    )


def _add_model_options(parser, n_iter):
    parser.add_argument(
        "--n-components", type=int, default=200, help="hidden units of the CRBM"
    )
    parser.add_argument(
        "--order", type=int, default=3, help="past frames each frame depends on"
    )
    parser.add_argument(
        "--history-noise",
        type=float,
        default=_DEFAULTS.history_noise,
        help="noise on the history during training (0 is the paper's schedule, "
        "whose fill-ins and generated styles drift for some seeds)",
    )
    parser.add_argument(
        "--history-noise-fraction",
        type=float,
        default=_DEFAULTS.history_noise_fraction,
        help="share of each training frame's channels whose history gets the noise",
    )
    parser.add_argument(
        "--average-fraction",
        type=float,
        default=_DEFAULTS.average_fraction,
        help="final share of the epochs whose parameters are averaged (0: keep "
        "the last epoch's, the paper's schedule)",
    )
    parser.add_argument(
        "--n-iter", type=int, default=n_iter, help="training epochs (the paper: 4000)"
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="random seed of training and sampling"
    )


def _model_from_args(args):
    """The ConditionalRBM that ``demo`` and ``fit`` train, from the model options."""
    return ConditionalRBM(
        args.n_components,
        order=args.order,
        n_iter=args.n_iter,
        history_noise=args.history_noise,
        history_noise_fraction=args.history_noise_fraction,
        average_fraction=args.average_fraction,
        random_state=args.seed,
        verbose=max(1, args.n_iter // 10),
    )


def _load_cmu35(data_home, subset):
    try:
        return load_cmu35(data_home, subset=subset)
    except FileNotFoundError as exc:
        home = get_data_home(data_home)
        raise FileNotFoundError(
            f"{exc}\nThe CMU subject 35 data is not in {home}. Download it with\n"
            f"    python -m sklearn_crbm fetch --data-home {home}\n"
            "or point --data-home (or $SKLEARN_CRBM_DATA) at a folder that holds it."
        ) from None


# ----------------------------------------------------------------- demo
def run_demo(args):
    if args.full:
        args.n_iter, args.n_repeats = 4000, 100
    start = time.perf_counter()
    train = _load_cmu35(args.data_home, "train")
    test = _load_cmu35(args.data_home, "test")
    print(
        f"CMU subject 35: {len(train.data)} training frames in "
        f"{len(train.sequence_names)} trials, test trials "
        f"{', '.join(test.sequence_names)}"
    )

    # the paper's encoding: joint rotations from the rest pose, Taylor's roll
    preprocessor = make_motion_preprocessor(
        train.skeleton, reference="rest", roll="taylor"
    )
    Z = preprocessor.fit_transform(train.data, sequence_ids=train.sequence_ids)
    names = preprocessor.get_feature_names_out()
    print(
        f"preprocessed to {Z.shape[1]} dimensions "
        "(exp maps, body-centred root, z-scores; the paper's encoding)"
    )

    print(f"figures and generated motion go to {args.output} (--output to change)")
    model = _model_from_args(args)
    print(f"\ntraining {model!r}")
    imputer = CRBMImputer(model, n_particles=args.n_particles, random_state=args.seed)
    imputer.fit(Z, sequence_ids=train.sequence_ids)
    model = imputer.estimator_

    cases = make_fillin_cases(test, preprocessor)
    table = _fillin_table(imputer, Z, cases, args.n_repeats, args.seed)
    generated = _generate_styles(model, preprocessor, Z, train, names, args)
    args.output.mkdir(parents=True, exist_ok=True)
    written = _write_generated(args.output, preprocessor, train, generated)
    if not args.no_figures:
        written += _draw(
            args.output, model, preprocessor, train, cases, table, generated
        )
    print(f"\nwrote to {args.output}: " + ", ".join(p.name for p in written))
    print(f"done in {time.perf_counter() - start:.0f} s")
    return 0


def _fillin_table(imputer, Z_train, cases, n_repeats, seed):
    nearest = NearestNeighborImputer().fit(Z_train)
    print(
        "\nfilling in: a body part of each held-out trial is erased from "
        "half-way to the end and filled in on-line, frame by frame\n"
        "  CRBM, NN     the paper's error (per erased frame, the mean squared "
        "error over the erased channels in standard deviations, summed over "
        "the erased frames; lower is better) of the CRBM (mean of "
        f"{n_repeats} single draws) and of nearest neighbour\n"
        "  ratio        CRBM / NN: below 1, the CRBM fills in better\n"
        "  CRBM°, NN°   root mean squared error of the erased joint angles, "
        "in degrees\n"
        "  paper        the paper's CRBM / NN errors (walk only)"
    )
    print(
        f"{'sequence':<14}{'erased':<12}{'CRBM':>8}{'NN':>8}{'ratio':>7}"
        f"{'CRBM°':>8}{'NN°':>8}   paper (CRBM / NN)"
    )
    table = {}
    for (motion, part), case in cases.items():
        draws = imputer.sample(case.X_missing, n_samples=n_repeats, random_state=seed)
        crbm = np.mean([case.errors(d) for d in draws], axis=0)
        nn_fill = nearest.transform(case.X_missing)
        nn = case.errors(nn_fill)
        paper = PAPER_FILLIN.get((motion, part))
        paper_text = f"{paper[0]:.2f} / {paper[1]:.2f}" if paper else "-"
        print(
            f"{motion + ' ' + case.trial:<14}{part:<12}{crbm[0]:8.2f}{nn[0]:8.2f}"
            f"{crbm[0] / nn[0]:7.2f}{crbm[1]:8.2f}{nn[1]:8.2f}   {paper_text}"
        )
        table[motion, part] = dict(crbm=crbm, nn=nn, draw=draws[0], nn_fill=nn_fill)
    return table


def _generate_styles(model, preprocessor, Z, train, names, args):
    """Seed with walk frames and with jog frames; classify what comes out."""
    ids = train.sequence_ids
    reference = gait_statistics(Z, sequence_ids=ids, feature_names=names)
    reference_styles = np.asarray(train.motion)
    print(
        f"\ngenerating {args.n_frames} frames per sequence, 3 sequences seeded "
        "with real walking and 3 with jogging; each is classified by the nearest "
        "training style\n"
        "  speed        mean forward displacement of the body per frame, in "
        "the skeleton's length units (CMU: 1/0.45 inch)\n"
        "  step Hz      gait frequency (steps of one leg per second, at 30 "
        "frames/s)"
    )
    print(f"{'seeded with':<12}{'speed':>8}{'step Hz':>9}   classified as")
    generated = {}
    rng = np.random.default_rng(args.seed)
    for style in ("walk", "jog"):
        seeds = random_windows(
            Z,
            sequence_ids=ids,
            width=max(model.history_length, 1),
            n_windows=3,
            sequences=np.flatnonzero(reference_styles == style),
            random_state=rng,
        )
        frames = model.sample(args.n_frames, history=seeds, random_state=args.seed)
        gen_ids = np.repeat(np.arange(3), args.n_frames)
        stats = gait_statistics(frames, sequence_ids=gen_ids, feature_names=names)
        labels = nearest_style(stats, reference, reference_styles)
        speeds = _speed_in_length_units(preprocessor, frames, stats[:, 0])
        for row, speed, label in zip(stats, speeds, labels, strict=True):
            print(f"{style:<12}{speed:8.3f}{row[1]:9.2f}   {label}")
        generated[style] = (frames, gen_ids)
    speeds = _speed_in_length_units(preprocessor, Z, reference[:, 0])
    for style in ("walk", "jog"):
        real = reference_styles == style
        print(
            f"{'real ' + style:<12}{speeds[real].mean():8.3f}"
            f"{np.nanmean(reference[real, 1]):9.2f}"
            "   (training mean)"
        )
    return generated


def _speed_in_length_units(preprocessor, Z, speed):
    """Speeds measured on standardised frames, in the encoder's units again."""
    scaler = preprocessor[-1]
    names = list(preprocessor[:-1].get_feature_names_out())
    column = names.index("root_dforward")
    return speed * scaler.scale_[column] + scaler.mean_[column]


def _write_generated(output, preprocessor, train, generated):
    """The first generated sequence of each style, as an AMC file."""
    written = []
    for style, (frames, gen_ids) in generated.items():
        raw = preprocessor.inverse_transform(frames, sequence_ids=gen_ids)
        path = output / f"generated_{style}.amc"
        write_amc(
            path, raw[gen_ids == 0], train.skeleton, feature_names=train.feature_names
        )
        written.append(path)
    return written


def _draw(output, model, preprocessor, train, cases, table, generated):
    from .plotting import (
        plot_filled_channels,
        plot_hidden_activations,
        plot_motion_strip,
    )

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(
            "\nmatplotlib is not installed: no figures "
            "(pip install 'sklearn_crbm[plot]')"
        )
        return []
    written = []
    for style, (frames, gen_ids) in generated.items():
        raw = preprocessor.inverse_transform(frames, sequence_ids=gen_ids)
        first = raw[gen_ids == 0]
        step = -(-len(first) // STRIP_FIGURES)
        fig, ax = plt.subplots(figsize=(14, 3))
        plot_motion_strip(
            train.skeleton, first, feature_names=train.feature_names, step=step, ax=ax
        )
        ax.set_title(
            f"generated from a {style} seed: all {len(first)} frames, one "
            f"figure every {step} frames"
        )
        written.append(_save(fig, output / f"generated_{style}.png"))
    case, result = cases["walk", "left leg"], table["walk", "left leg"]
    names = preprocessor.get_feature_names_out()
    axes = plot_filled_channels(
        case.X,
        result["draw"],
        result["nn_fill"],
        features=["lfemur_ex", "lfemur_ey", "lfemur_ez"],
        feature_names=names,
        missing_from=case.first_missing,
    )
    fig = np.ravel(axes)[0].figure
    written.append(_save(fig, output / "fillin_left_hip.png"))
    walk_seq = np.flatnonzero(np.asarray(train.motion) == "walk")[0]
    jog_seq = np.flatnonzero(np.asarray(train.motion) == "jog")[0]
    keep = np.isin(train.sequence_ids, [walk_seq, jog_seq])
    Z = preprocessor.transform(train.data[keep], sequence_ids=train.sequence_ids[keep])
    fig, ax = plt.subplots(figsize=(10, 4))
    plot_hidden_activations(
        model.transform(Z, sequence_ids=train.sequence_ids[keep]), ax=ax
    )
    ax.set_title("hidden units on a walk then a jog")
    written.append(_save(fig, output / "hidden_activations.png"))
    return written


def _save(fig, path):
    fig.savefig(path, dpi=100, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path


# ---------------------------------------------------------- other commands
def run_fetch(args):
    home = get_data_home(args.data_home)
    existed = home.exists()
    print(f"downloading into {home}")
    try:
        fetch_cmu35(home)
        fetch_mit_walk(home)
    except BaseException:
        if not existed:  # everything in it is this command's partial download
            shutil.rmtree(home, ignore_errors=True)
        raise
    print("done")
    return 0


def run_fit(args):
    train = _load_cmu35(args.data_home, "train")
    pipeline = Pipeline(
        make_motion_preprocessor(train.skeleton).steps
        + [("crbm", _model_from_args(args))]
    )
    pipeline.fit(train.data, sequence_ids=train.sequence_ids)
    pipeline.style_windows_ = _style_windows(pipeline, train, args.seed)
    joblib.dump(pipeline, args.output)
    print(f"saved the fitted pipeline to {args.output}")
    return 0


def _style_windows(pipeline, train, seed):
    """Windows of real walking and jogging (preprocessed) that seed ``sample``.

    Saved with the model, so that ``sample`` needs no data on disk.
    """
    Z = pipeline[:-1].transform(train.data, sequence_ids=train.sequence_ids)
    styles = np.asarray(train.motion)
    return {
        style: random_windows(
            Z,
            sequence_ids=train.sequence_ids,
            width=max(pipeline[-1].history_length, 1),
            n_windows=N_STYLE_WINDOWS,
            sequences=np.flatnonzero(styles == style),
            random_state=seed,
        )
        for style in ("walk", "jog")
    }


def _load_model(path):
    """The pipeline written by ``fit``; a clear error for anything else."""
    try:
        model = joblib.load(path)
    except FileNotFoundError:
        raise
    except Exception as exc:  # joblib/pickle raise many types on foreign files
        raise ValueError(
            f"{path} is not a model saved by 'python -m sklearn_crbm fit' "
            f"({type(exc).__name__}: {exc})."
        ) from None
    if not isinstance(model, Pipeline) or not isinstance(model[-1], ConditionalRBM):
        raise ValueError(
            f"{path} holds a {type(model).__name__}, not the pipeline (motion "
            "preprocessor + ConditionalRBM) that 'python -m sklearn_crbm fit' saves."
        )
    return model


def run_sample(args):
    pipeline = _load_model(args.model)
    crbm, preprocessor = pipeline[-1], pipeline[:-1]
    frames = crbm.sample(
        args.n_frames,
        history=_seeds(pipeline, args),
        n_sequences=args.n_sequences,
        hidden_noise=args.hidden_noise,
        random_state=args.seed,
    )
    gen_ids = np.repeat(np.arange(args.n_sequences), args.n_frames)
    raw = preprocessor.inverse_transform(frames, sequence_ids=gen_ids)
    skeleton = preprocessor[0].skeleton
    for k in range(args.n_sequences):
        path = Path(f"{args.output}_{k}.amc")
        write_amc(path, raw[gen_ids == k], skeleton)
        print(f"wrote {path}")
    return 0


def _seeds(pipeline, args):
    """``sample``'s history: saved windows of the chosen style (None: any)."""
    if args.style == "any":
        return None
    windows = getattr(pipeline, "style_windows_", None)
    if windows is None:
        raise ValueError(
            f"{args.model} keeps no walking or jogging seed frames (it was saved "
            "by an older version): fit it again with 'python -m sklearn_crbm "
            "fit', or pass --style any."
        )
    windows = windows[args.style]
    rng = np.random.default_rng(args.seed)
    return windows[rng.integers(len(windows), size=args.n_sequences)]
