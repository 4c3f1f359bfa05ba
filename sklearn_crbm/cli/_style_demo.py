"""The command line's styles command: many styles from one factored CRBM.

Train a :class:`~sklearn_crbm.FactoredCRBM` on the Bandai Namco walks (or
a labelled folder of the user's), generate every style, a blend and a
transition from real frames of one style, write them as BVH files and
figures, and print how a :class:`~sklearn_crbm.metrics.StyleJudge` trained
on the real takes sees them, its liveliness judged on the joints that move
most in the real takes (the legs of a walk, the arm of a wave).  The
library does the work (:class:`~sklearn_crbm.preprocessing.MotionPipeline`
trains, generates and writes, the judge judges, the plotting
functions draw); this module chooses what to generate and prints.
"""

import time

import numpy as np
import sklearn

from ..metrics import StyleJudge, most_moving_channels
from ..metrics._style import _nanmedian
from ..plotting import plot_motion_strip, plot_style_probabilities
from ..plotting._base import check_matplotlib
from ..preprocessing import make_motion_pipeline
from ._demo import GIF_FRAMES, GIF_STEP, _save, save_gif

__all__ = ["run_styles", "style_requests"]

# The judge's liveliness: the amplitude and frequency of the joint angles
# that move most within the real takes, ranked in radians (as the
# benchmarks judge generated motion): the legs of a walk, the arm of a wave.
N_MOVING = 12
ANGLE_SUFFIXES = ("_ex", "_ey", "_ez")
# Judged windows start here or later: the first frames still move like the
# seed's style.
JUDGED_FROM = 100
# Each style's strip: every 4th of its last 60 frames (2 s), as Fig. 3 of
# the 2006 paper draws a walk.
STRIP_FRAMES, STRIP_STEP = 60, 4


def style_requests(classes, n_frames, *, blend, transition):
    """The label weights of every sequence the command generates.

    Returns ``{name: weights}``, weights of shape ``(n_frames,
    len(classes))``: one style throughout for each of ``classes`` (named
    after it), a 50/50 ``blend`` of two styles (``"blend_A_B"``) and a
    ``transition`` from one style to another at ``n_frames // 2``
    (``"transition_A_B"``).
    """
    classes = list(classes)
    one_hot = np.eye(len(classes))
    requests = {
        style: np.tile(one_hot[k], (n_frames, 1)) for k, style in enumerate(classes)
    }
    first, second = (classes.index(style) for style in blend)
    requests["blend_{}_{}".format(*blend)] = np.tile(
        (one_hot[first] + one_hot[second]) / 2, (n_frames, 1)
    )
    first, second = (classes.index(style) for style in transition)
    switch = n_frames // 2
    weights = np.tile(one_hot[first], (n_frames, 1))
    weights[switch:] = one_hot[second]
    requests["transition_{}_{}".format(*transition)] = weights
    return requests


# The styles the options default to on the Bandai walks; a folder without
# them starts from its first style and blends or switches its first two.
BANDAI_DEFAULTS = dict(
    seed_style="normal", blend=["elderly", "youthful"], transition=["active", "elderly"]
)


def default_styles(args, styles):
    """Fill the style options left out, from the data's ``styles``."""
    for option, default in BANDAI_DEFAULTS.items():
        if getattr(args, option) is not None:
            continue
        wanted = [default] if isinstance(default, str) else default
        if not set(wanted) <= set(styles):
            wanted = list(styles[: len(wanted)])
        setattr(args, option, wanted[0] if isinstance(default, str) else wanted)


def check_style_arguments(args, styles, noun="take"):
    """Fail before training when an option names a style the data lack."""
    if len(styles) < 2:
        raise ValueError(
            f"the styles command needs takes of at least two styles; the labels "
            f"give one ({', '.join(styles)})."
        )
    default_styles(args, styles)
    for option, names in (
        ("--seed-style", [args.seed_style]),
        ("--blend", args.blend),
        ("--transition", args.transition),
    ):
        for name in names:
            if name not in styles:
                raise ValueError(
                    f"{option}: the {noun}s have no style {name!r}; their styles "
                    f"are {', '.join(map(str, styles))}."
                )
    if args.blend[0] == args.blend[1] or args.transition[0] == args.transition[1]:
        raise ValueError("--blend and --transition each need two different styles.")
    if args.n_frames < 2 * StyleJudge().window:
        raise ValueError(
            f"--n-frames must be at least {2 * StyleJudge().window}, so that the "
            "judge's 2-s windows fit on both sides of the transition; got "
            f"{args.n_frames}."
        )
    if args.n_sequences < 1:
        raise ValueError(f"--n-sequences must be at least 1, got {args.n_sequences}.")


def run_styles(args, walks, model):
    """Train ``model`` on ``walks``, generate, judge, print and write files.

    ``walks.name`` says what the takes are and where they come from,
    ``walks.noun`` what one take is ("walk", "wave-left-hand", "take").
    """
    start = time.perf_counter()
    labels = walks.target_names[walks.target]
    styles = sorted(set(labels.tolist()))  # the model's classes_
    check_style_arguments(args, styles, walks.noun)
    print(
        f"{walks.name}: {len(walks.data)} frames in "
        f"{len(walks.sequence_names)} takes at {walks.frame_rate:g} frames/s, "
        f"styles {', '.join(styles)}"
    )
    print(f"figures and generated motion go to {args.output} (--output to change)")
    print(f"\ntraining {model!r}")
    with sklearn.config_context(enable_metadata_routing=True):
        pipeline = make_motion_pipeline(walks.skeleton, model)
        pipeline.fit(walks.data, labels, sequence_ids=walks.sequence_ids)
        generated = _generate(pipeline, walks, labels, args)
        judge, real = _fit_judge(pipeline, walks, labels)
        judged = {
            name: (pipeline[:-1].transform(raw, sequence_ids=ids), ids)
            for name, (raw, ids) in generated.items()
        }
    joints = _joint_names(pipeline, judge.legs)
    _print_table(judge, judged, walks.frame_rate, args, walks.noun, joints, real)
    args.output.mkdir(parents=True, exist_ok=True)
    written = _write_motion(pipeline, generated, walks.frame_rate, args.output)
    if not args.no_figures:
        written += _draw(walks, generated, judge, judged, args)
    print(f"\nwrote to {args.output}: " + ", ".join(p.name for p in written))
    print(f"done in {time.perf_counter() - start:.0f} s")
    return 0


def _generate(pipeline, walks, labels, args):
    """``{name: (raw frames, sequence_ids)}`` of every request, as raw channels."""
    seeds = pipeline.style_windows(
        walks.data,
        labels,
        sequence_ids=walks.sequence_ids,
        n_windows=args.n_sequences,
        random_state=args.seed,
    )[args.seed_style]
    requests = style_requests(
        pipeline[-1].classes_,
        args.n_frames,
        blend=args.blend,
        transition=args.transition,
    )
    ids = np.repeat(np.arange(args.n_sequences), args.n_frames)
    generated = {}
    for name, weights in requests.items():
        raw = pipeline.sample(
            args.n_frames,
            history=seeds,
            style=weights,
            n_sequences=args.n_sequences,
            random_state=args.seed,
        )
        generated[name] = (raw, ids)
    return generated


def _fit_judge(pipeline, walks, labels):
    """A StyleJudge of 2-s windows, trained on every real take, whose
    liveliness is that of the joints that move most in them, and its verdict
    on the real takes."""
    ids = walks.sequence_ids
    Z = pipeline[:-1].transform(walks.data, sequence_ids=ids)
    moving = moving_joint_channels(pipeline[:-1], Z, ids)
    judge = StyleJudge(legs=moving).fit(Z, labels, sequence_ids=ids)
    verdict = judge.verdict(Z, labels, sequence_ids=ids)
    # the middle halves of the takes: their cycle, which generation continues
    length = np.bincount(ids)[verdict.sequence_ids]
    cycle = (verdict.starts >= length // 4) & (
        verdict.starts + judge.window <= 3 * length // 4
    )
    if not cycle.any():  # takes too short for a window in their middle
        cycle[:] = True
    return judge, (verdict.correct[cycle].mean(), verdict.alive[cycle].mean())


def moving_joint_channels(preprocessor, Z, sequence_ids, n_channels=N_MOVING):
    """Columns of ``Z``: the joint angles that move most within the real takes.

    :func:`~sklearn_crbm.metrics.most_moving_channels` of the exponential
    maps in radians, before the preprocessor's last step (the scaler) made
    every channel's spread alike: the legs of a walk, the arm of a wave.
    Every channel of ``Z`` when it has no joint angles.
    """
    names = preprocessor.get_feature_names_out()
    angles = [j for j, name in enumerate(names) if name.endswith(ANGLE_SUFFIXES)]
    scaler = preprocessor[-1]
    unscaled = scaler.inverse_transform(Z)
    if unscaled.shape[1] != Z.shape[1]:  # the scaler put back constant channels
        unscaled = unscaled[:, ~scaler.constant_mask_]
    return most_moving_channels(
        unscaled,
        sequence_ids=sequence_ids,
        n_channels=n_channels,
        features=angles or None,
    )


def _joint_names(pipeline, columns):
    """The joints of the channels ``columns``, most moving first, once each."""
    names = pipeline[:-1].get_feature_names_out()[columns]
    return list(dict.fromkeys(name.rsplit("_", 1)[0] for name in names))


def _print_table(judge, judged, frame_rate, args, noun, joints, real_takes):
    first = min(JUDGED_FROM, args.n_frames - judge.window)
    print(
        f"\ngenerated from real frames of {args.seed_style} {noun}: "
        f"{args.n_sequences} sequence{'s' * (args.n_sequences != 1)} of "
        f"{args.n_frames} frames per style, their {judge.window}-frame windows "
        f"from frame {first} on judged by a StyleJudge trained on the real takes\n"
        f"  moving       the {len(judge.legs)} joint angles that move most in the "
        f"real takes, of {', '.join(joints)}\n"
        "  judged       share of windows judged as the style asked for\n"
        "  alive        share of windows whose moving joints' amplitude and "
        f"cycle frequency are within {judge.amplitude_tolerance:.0%} and "
        f"{judge.frequency_tolerance:.0%} of the style's real windows\n"
        "  amplitude    the moving joints' amplitude over that of the style's "
        "median real window\n"
        "  cycles/s     their dominant frequency (the steps of one leg, the "
        "swings of an arm), generated (real); - for joints that do not move"
    )
    print(f"{'style':<12}{'judged':>7}{'alive':>7}{'amplitude':>11}   cycles/s")
    for k, style in enumerate(judge.classes_):
        Z, ids = judged[style]
        verdict = judge.verdict(Z, style, sequence_ids=ids)
        kept = verdict.starts >= first
        real = judge.reference_frequency_[k] * frame_rate
        frequency = _nanmedian(verdict.frequency_ratio[kept]) * real
        frequency = "-" if np.isnan(frequency) else f"{frequency:.2f}"
        print(
            f"{style:<12}{verdict.correct[kept].mean():7.0%}"
            f"{verdict.alive[kept].mean():7.0%}"
            f"{np.median(verdict.amplitude_ratio[kept]):11.2f}   "
            f"{frequency} ({real:.2f})"
        )
    _print_real(real_takes)
    _print_blend(judge, judged, first, args)
    _print_transition(judge, judged, first, args)


def _print_real(real):
    """The judge on the real takes' middle halves (their cycle), beside its
    figures for the generated motion: how far they can be trusted."""
    judged, alive = real
    print(
        f"{'real takes':<12}{judged:7.0%}{alive:7.0%}   (the judge on the "
        "middle halves of the training takes)"
    )


def _print_blend(judge, judged, first, args):
    a, b = args.blend
    Z, ids = judged[f"blend_{a}_{b}"]
    verdict = judge.verdict(Z, sequence_ids=ids)
    kept = verdict.starts >= first
    predicted = verdict.predicted[kept]
    shares = {style: np.mean(predicted == style) for style in (a, b)}
    alive = np.mean(verdict.alive[kept])  # against the style each is judged as
    print(
        f"blend {a} + {b}: {sum(shares.values()):.0%} of the windows judged as "
        f"one of the two ({a} {shares[a]:.0%}, {b} {shares[b]:.0%}); alive "
        f"{alive:.0%}"
    )


def _print_transition(judge, judged, first, args):
    a, b = args.transition
    Z, ids = judged[f"transition_{a}_{b}"]
    switch = args.n_frames // 2
    requested = np.where(np.arange(args.n_frames) < switch, a, b)
    verdict = judge.verdict(Z, np.tile(requested, args.n_sequences), sequence_ids=ids)
    before = (verdict.starts >= first) & (verdict.starts + judge.window <= switch)
    after = verdict.starts >= switch
    before, after = (
        f"{verdict.correct[windows].mean():.0%} (alive "
        f"{verdict.alive[windows].mean():.0%})"
        if windows.any()
        else "no window"
        for windows in (before, after)
    )
    print(
        f"transition {a} -> {b} at frame {switch}: windows before it judged as "
        f"{a}: {before}; windows after it judged as {b}: {after}"
    )


def _write_motion(pipeline, generated, frame_rate, output):
    """The first generated sequence of every request, as a BVH file."""
    written = []
    for name, (raw, ids) in generated.items():
        path = output / f"{name}.bvh"
        pipeline.write_motion(path, raw[ids == 0], frame_rate=frame_rate)
        written.append(path)
    return written


def _draw(walks, generated, judge, judged, args):
    """A strip of every style and the blend; the transition with the judge's view."""
    try:
        plt = check_matplotlib()
    except ImportError as exc:
        print(f"\nno figures: {exc}")
        return []
    plt.switch_backend("Agg")  # files only, never a window
    written = _gifs(walks, generated, judge, judged, args)
    for name, (raw, ids) in generated.items():
        first = raw[ids == 0]
        if name.startswith("transition_"):
            fig = _draw_transition(walks, first, judge, judged[name], args)
        else:
            fig, ax = plt.subplots(figsize=(12, 2.6))
            last = first[-STRIP_FRAMES:]
            plot_motion_strip(
                walks.skeleton, last, step=STRIP_STEP, view=args.view, ax=ax
            )
            ax.set_title(
                f"{name.replace('_', ' ')}: every {STRIP_STEP}th of the last "
                f"{len(last)} of {len(first)} generated frames"
            )
        written.append(_save(fig, args.output / f"{name}.png"))
    return written


def _gifs(walks, generated, judge, judged, args):
    """Every style moving side by side; the transition over the judge's view."""
    styles = list(judge.classes_)
    last = [
        generated[style][0][generated[style][1] == 0][-GIF_FRAMES:] for style in styles
    ]
    common = dict(frame_rate=walks.frame_rate, step=GIF_STEP, view=args.view)
    written = [
        save_gif(
            args.output / "styles.gif",
            walks.skeleton,
            last,
            titles=[str(style) for style in styles],
            **common,
        )
    ]
    a, b = args.transition
    name = f"transition_{a}_{b}"
    raw, ids = generated[name]
    written.append(
        save_gif(
            args.output / f"{name}.gif",
            walks.skeleton,
            [raw[ids == 0]],
            titles=[f"{a}, then {b} from frame {args.n_frames // 2}"],
            proba=_first_sequence_proba(judge, judged[name]),
            classes=judge.classes_,
            **common,
        )
    )
    return written


def _draw_transition(walks, raw, judge, generated, args):
    """The transition as a strip over the judge's probabilities of the styles."""
    plt = check_matplotlib()
    a, b = args.transition
    switch = args.n_frames // 2
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(12, 6))
    plot_motion_strip(walks.skeleton, raw, view=args.view, ax=top)
    top.set_title(f"{a}, then {b} from frame {switch}: the whole sequence")
    plot_style_probabilities(
        _first_sequence_proba(judge, generated),
        classes=judge.classes_,
        frame_rate=walks.frame_rate,
        ax=bottom,
    )
    bottom.axvline(switch / walks.frame_rate, color="0.3", linestyle="--")
    bottom.set_title("the style judge's probability of each style")
    fig.tight_layout()
    return fig


def _first_sequence_proba(judge, judged):
    """The judge's probability of each style at every frame of the first sequence."""
    Z, ids = judged
    return judge.predict_proba(Z[ids == 0], per="frame")
