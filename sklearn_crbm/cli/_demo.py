"""The command line's demo: the paper's experiments on CMU subject 35.

Train a CRBM, fill in against the simple baselines, generate walking and
jogging, and draw figures; all measuring is done by the library
(:func:`~sklearn_crbm.model_selection.compare_imputers`,
:func:`~sklearn_crbm.metrics.judge_generated_motion`), this module prints.
"""

import time
import warnings

import numpy as np
from sklearn.impute import KNNImputer

from ..datasets import write_amc, write_bvh
from ..exceptions import GenerationWarning
from ..impute import AutoregressiveImputer, CRBMImputer, NearestNeighborImputer
from ..metrics import judge_generated_motion
from ..metrics._liveliness import DEAD_FRACTION, generated_liveliness
from ..model_selection import compare_imputers, make_fillin_cases
from ..preprocessing import make_motion_preprocessor
from ..utils import random_windows

__all__ = ["run_demo"]

# Stick figures in the demo's strip of a generated sequence.
STRIP_FIGURES = 30
# The paper's encoding, in which its tables (and the demo's) are measured.
ENCODING = dict(reference="rest", roll="taylor")
ENCODING_NOTE = "the paper's encoding"
PAPER_FILLIN = {
    ("walk", "left leg"): (8.78, 11.68),
    ("walk", "upper body"): (20.52, 22.20),
}
# Resolution of the GIFs, and the frames of each sequence they show (every
# other frame: real time at half the frames).
GIF_DPI = 60
GIF_FRAMES, GIF_STEP = 180, 2
# Generated sequences per seed style, and the frames each is judged on.
N_PER_STYLE = 3
JUDGED_FRAMES = 100


def run_demo(args, train, test, model):
    """Print the demo's tables and write its files; ``model`` is untrained."""
    start = time.perf_counter()
    print(
        f"CMU subject 35: {len(train.data)} training frames in "
        f"{len(train.sequence_names)} trials, test trials "
        f"{', '.join(test.sequence_names)}"
    )
    preprocessor = make_motion_preprocessor(train.skeleton, **ENCODING)
    Z = preprocessor.fit_transform(train.data, sequence_ids=train.sequence_ids)
    print(
        f"preprocessed to {Z.shape[1]} dimensions ({ENCODING_NOTE}: joint "
        "rotations from the rest pose as exponential maps, Taylor's root roll, "
        "z-scores; the package's default encoding gives other numbers)"
    )
    print(f"figures and generated motion go to {args.output} (--output to change)")
    print(f"\ntraining {model!r}")
    imputer = CRBMImputer(model, n_particles=args.n_particles, random_state=args.seed)
    imputer.fit(Z, sequence_ids=train.sequence_ids)

    cases = make_fillin_cases(test, preprocessor)
    _fillin_table(imputer, Z, train.sequence_ids, cases, args)
    generated = _generate_styles(imputer.estimator_, preprocessor, Z, train, args)
    args.output.mkdir(parents=True, exist_ok=True)
    written = _write_generated(args.output, preprocessor, train, generated)
    if not args.no_figures:
        written += _draw(args, imputer, preprocessor, Z, train, cases, generated)
    print(f"\nwrote to {args.output}: " + ", ".join(p.name for p in written))
    print(f"done in {time.perf_counter() - start:.0f} s")
    return 0


def _baselines(Z, sequence_ids):
    """The simple imputers the CRBM is compared with, fitted on ``Z``."""
    return {
        "NN": NearestNeighborImputer().fit(Z),
        "KNN(5)": KNNImputer(n_neighbors=5).fit(Z),
        "KNN(10)": KNNImputer(n_neighbors=10).fit(Z),
        "AR": AutoregressiveImputer().fit(Z, sequence_ids=sequence_ids),
    }


def _fillin_table(imputer, Z, sequence_ids, cases, args):
    imputers = {"CRBM": imputer, **_baselines(Z, sequence_ids)}
    scores = compare_imputers(
        imputers, cases, n_repeats=args.n_repeats, random_state=args.seed
    )
    print(
        "\nfilling in: a body part of each held-out trial is erased from "
        "half-way to the end and filled in on-line, frame by frame\n"
        f"  CRBM         the CRBM imputer (mean of {args.n_repeats} single draws)\n"
        "  NN           nearest neighbour on the observed channels (the paper's "
        "baseline)\n"
        "  KNN(k)       scikit-learn's KNNImputer, the mean of k neighbours\n"
        "  AR           AutoregressiveImputer: linear-Gaussian, on-line "
        "conditional mean\n"
        "  ratio        CRBM / the best of the four baselines: below 1, the CRBM "
        "fills in better\n"
        "  paper        the paper's CRBM / NN errors (walk only)"
    )
    for key, title in (
        (
            "error",
            f"the paper's error, in {ENCODING_NOTE} (per erased frame, the mean "
            "squared error over the erased channels in standard deviations, "
            "summed over the erased frames; lower is better)",
        ),
        (
            "angle_rmse",
            "root mean squared error of the erased joint angles in degrees, "
            f"filled in {ENCODING_NOTE}",
        ),
    ):
        print(f"\n{title}")
        print(
            f"{'sequence':<14}{'erased':<12}"
            + "".join(f"{name:>9}" for name in imputers)
            + f"{'ratio':>7}"
            + ("   paper (CRBM / NN)" if key == "error" else "")
        )
        for (motion, part), case in cases.items():
            row = [scores[name][motion, part][key] for name in imputers]
            paper = PAPER_FILLIN.get((motion, part))
            paper_text = f"{paper[0]:.2f} / {paper[1]:.2f}" if paper else "-"
            print(
                f"{motion + ' ' + case.trial:<14}{part:<12}"
                + "".join(f"{value:9.2f}" for value in row)
                + f"{row[0] / min(row[1:]):7.2f}"
                + (f"   {paper_text}" if key == "error" else "")
            )


def _generate_styles(model, preprocessor, Z, train, args):
    """Seed with walk frames and with jog frames; judge what comes out."""
    ids = train.sequence_ids
    styles = np.asarray(train.motion)
    print(
        f"\ngenerating {args.n_frames} frames per sequence, {N_PER_STYLE} sequences "
        f"seeded with real walking and {N_PER_STYLE} with jogging, judged on their "
        f"last {min(JUDGED_FRAMES, args.n_frames)} frames ({ENCODING_NOTE})\n"
        "  speed        mean forward displacement of the body per frame, in "
        "the skeleton's length units (CMU: 1/0.45 inch)\n"
        "  step Hz      gait frequency (steps of one leg per second, at 30 "
        "frames/s)\n"
        "  style        the nearest training style in speed and step frequency\n"
        "  verdict      keeps its style, or died out (legs still), stalled "
        "(walking in place), blew up; lively: how much the last 100 frames move "
        f"against the training sequences (1 = as much; below {DEAD_FRACTION} the "
        "motion came to rest)"
    )
    print(f"{'seeded with':<12}{'speed':>8}{'step Hz':>9}   {'style':<7}verdict")
    rng = np.random.default_rng(args.seed)
    common = dict(
        reference_styles=styles,
        preprocessor=preprocessor,
        reference_sequence_ids=ids,
    )
    generated = {}
    for style in ("walk", "jog"):
        seeds = random_windows(
            Z,
            sequence_ids=ids,
            width=max(model.history_length, 1),
            n_windows=N_PER_STYLE,
            sequences=np.flatnonzero(styles == style),
            random_state=rng,
        )
        with warnings.catch_warnings():
            # the table gives every sequence's verdict, once
            warnings.simplefilter("ignore", GenerationWarning)
            frames = model.sample(args.n_frames, history=seeds, random_state=args.seed)
        gen_ids = np.repeat(np.arange(N_PER_STYLE), args.n_frames)
        verdict = judge_generated_motion(
            frames,
            Z,
            sequence_ids=gen_ids,
            expected_styles=[style] * N_PER_STYLE,
            last_frames=JUDGED_FRAMES,
            **common,
        )
        lively = generated_liveliness(
            frames, args.n_frames, model.generation_statistics_
        )
        for k in range(N_PER_STYLE):
            print(
                f"{style:<12}{verdict.speed[k]:8.3f}{verdict.frequency[k]:9.2f}   "
                f"{str(verdict.style[k]):<7}{_verdict_text(verdict, k)} "
                f"({liveliness_text(lively[k])})"
            )
        generated[style] = (frames, gen_ids)
    real = judge_generated_motion(Z, Z, sequence_ids=ids, **common)
    for style in ("walk", "jog"):
        mine = styles == style
        print(
            f"{'real ' + style:<12}{real.speed[mine].mean():8.3f}"
            f"{np.nanmean(real.frequency[mine]):9.2f}   (training mean)"
        )
    return generated


def liveliness_text(liveliness):
    """``"lively 0.93"``, or with ``": came to rest"`` below DEAD_FRACTION."""
    if not np.isfinite(liveliness):
        return "lively -"
    rest = ": came to rest" if liveliness < DEAD_FRACTION else ""
    return f"lively {liveliness:.2f}{rest}"


def _verdict_text(verdict, k):
    if verdict.keeps[k]:
        return "keeps its style"
    failures = [
        text
        for key, text in (
            ("dead", "died out"),
            ("stalled", "stalled"),
            ("blown", "blew up"),
        )
        if verdict[key][k]
    ]
    return ", ".join(failures) or "changed style"


def _write_generated(output, preprocessor, train, generated):
    """The first generated sequence of each style, as BVH and AMC files."""
    written = []
    for style, (frames, gen_ids) in generated.items():
        raw = preprocessor.inverse_transform(frames, sequence_ids=gen_ids)
        first = raw[gen_ids == 0]
        path = output / f"generated_{style}"
        write_bvh(path.with_suffix(".bvh"), first, train.skeleton, train.frame_rate)
        write_amc(path.with_suffix(".amc"), first, train.skeleton)
        written += [path.with_suffix(".bvh"), path.with_suffix(".amc")]
    return written


def _draw(args, imputer, preprocessor, Z_train, train, cases, generated):
    from ..plotting import (
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
    output = args.output
    written = [
        _real_and_generated_gif(output, preprocessor, train, generated, args.view)
    ]
    for style, (frames, gen_ids) in generated.items():
        raw = preprocessor.inverse_transform(frames, sequence_ids=gen_ids)
        first = raw[gen_ids == 0]
        step = -(-len(first) // STRIP_FIGURES)
        fig, ax = plt.subplots(figsize=(14, 3))
        plot_motion_strip(
            train.skeleton,
            first,
            feature_names=train.feature_names,
            step=step,
            view=args.view,
            ax=ax,
        )
        ax.set_title(
            f"generated from a {style} seed: all {len(first)} frames, one "
            f"figure every {step} frames"
        )
        written.append(_save(fig, output / f"generated_{style}.png"))
    case = cases["walk", "left leg"]
    crbm = imputer.sample(case.X_missing, random_state=args.seed)[0]
    nn = NearestNeighborImputer().fit(Z_train)
    axes = plot_filled_channels(
        case.X,
        crbm,
        nn.transform(case.X_missing),
        features=["lfemur_ex", "lfemur_ey", "lfemur_ez"],
        feature_names=preprocessor.get_feature_names_out(),
        missing_from=case.first_missing,
    )
    written.append(_save(np.ravel(axes)[0].figure, output / "fillin_left_hip.png"))
    walk_seq = np.flatnonzero(np.asarray(train.motion) == "walk")[0]
    jog_seq = np.flatnonzero(np.asarray(train.motion) == "jog")[0]
    keep = np.isin(train.sequence_ids, [walk_seq, jog_seq])
    Z = preprocessor.transform(train.data[keep], sequence_ids=train.sequence_ids[keep])
    fig, ax = plt.subplots(figsize=(10, 4))
    hidden = imputer.estimator_.transform(Z, sequence_ids=train.sequence_ids[keep])
    plot_hidden_activations(hidden, ax=ax)
    ax.set_title("hidden units on a walk then a jog")
    written.append(_save(fig, output / "hidden_activations.png"))
    return written


def _real_and_generated_gif(output, preprocessor, train, generated, view):
    """A real trial of each style beside the first sequence generated from it."""
    motion = np.asarray(train.motion)
    sequences, titles = [], []
    for style, (frames, gen_ids) in generated.items():
        real = train.data[train.sequence_ids == np.flatnonzero(motion == style)[0]]
        raw = preprocessor.inverse_transform(frames, sequence_ids=gen_ids)
        first = raw[gen_ids == 0][:GIF_FRAMES]
        sequences += [real[: len(first)], first]
        titles += [f"real {style}", f"generated from {style}"]
    return save_gif(
        output / "real_and_generated.gif",
        train.skeleton,
        sequences,
        titles=titles,
        frame_rate=train.frame_rate,
        step=GIF_STEP,
        view=view,
    )


def _save(fig, path):
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return path


def save_gif(path, skeleton, sequences, *, frame_rate, step=1, **kwargs):
    """Animate ``sequences`` side by side (``animate_motions``) into a GIF.

    Played in real time: ``frame_rate / step`` frames per second.
    """
    import matplotlib.pyplot as plt

    from ..plotting import animate_motions, save_animation

    height = 3.0 if kwargs.get("proba") is None else 5.0
    figure = plt.figure(figsize=(max(2.6 * len(sequences), 5.0), height))
    animation = animate_motions(
        skeleton, sequences, frame_rate=frame_rate, step=step, figure=figure, **kwargs
    )
    save_animation(animation, path, frame_rate=frame_rate / step, dpi=GIF_DPI)
    plt.close(figure)
    return path
