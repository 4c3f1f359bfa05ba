"""Command line: ``python -m sklearn_crbm {demo,fetch,fit,sample,styles}``.

Argument parsing and printing only: the commands' arguments are listed in
:mod:`._options`, the demo lives in :mod:`._demo`, the styles command in
:mod:`._style_demo`, and everything measured or generated is done by the
library.
"""

import argparse
import re
import shutil
import sys
import warnings
from pathlib import Path

import joblib
import numpy as np
import sklearn
from sklearn.utils import Bunch

from ..datasets import (
    fetch_bandai_dataset2,
    fetch_bandai_walks,
    fetch_cmu35,
    fetch_mit_walk,
    get_data_home,
    load_bandai_walks,
    load_cmu35,
    read_amc_folder,
    read_bvh_folder,
    resample_frames,
)
from ..datasets._labels import file_labels
from ..exceptions import GenerationWarning
from ..metrics._liveliness import (
    DEAD_FRACTION,
    generated_liveliness,
    lifeless_message,
)
from ..models._crbm import ConditionalRBM
from ..models._factored import FactoredCRBM
from ..models._labelled import LabelledCRBM
from ..preprocessing import MotionContext, MotionPipeline, make_motion_pipeline
from ._demo import liveliness_text, save_gif
from ._demo import run_demo as _run_demo
from ._labels import (
    label_keys,
    label_request,
    label_text,
    seed_windows_for,
)
from ._options import COMMANDS, MAX_DEFAULT_RATE, progress_verbosity
from ._seed_file import seed_from_file
from ._style_demo import run_styles as _run_styles

__all__ = ["main"]

# Seed windows of each style that ``fit`` saves with the model, for ``sample``.
N_STYLE_WINDOWS = 50


def main(argv=None):
    """Run the command line; returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    if getattr(args, "output", None) is not None:
        args.output = args.output.absolute()  # printed: say where it is
    try:
        with sklearn.config_context(enable_metadata_routing=True):
            with warnings.catch_warnings():
                warnings.showwarning = _show_warning
                return args.run(args)
    except (ImportError, OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """A warning as the command's own line, ``warning: ...`` on stderr.

    (Python's own format names the first frame outside the package, which
    for ``python -m`` is ``<frozen runpy>:88``.)
    """
    print(f"warning: {message}", file=sys.stderr)


def _parser():
    parser = argparse.ArgumentParser(
        prog="python -m sklearn_crbm",
        description="Conditional RBMs for human motion (Taylor, Hinton & Roweis 2006).",
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (summary, description, options) in COMMANDS.items():
        command = commands.add_parser(
            name, help=summary, description=description, formatter_class=_HelpFormatter
        )
        command.set_defaults(run=_RUNS[name])
        for flags, settings in options:
            command.add_argument(*flags, **settings)
    return parser


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Ends every option's help with its default, where it has one to show."""

    def _get_help_string(self, action):
        no_default = action.default is None or action.default is False
        if no_default or "default" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def _model_from_args(args, labelled=False):
    """The ConditionalRBM that ``demo`` and ``fit`` train, from the model
    options; a LabelledCRBM of the same options for ``fit --labels`` with
    several keys."""
    model_class = LabelledCRBM if labelled else ConditionalRBM
    return model_class(
        args.n_components,
        order=args.order,
        n_iter=args.n_iter,
        history_noise=args.history_noise,
        history_noise_fraction=args.history_noise_fraction,
        average_fraction=args.average_fraction,
        n_mean_field=args.n_mean_field,
        hidden_drift=args.hidden_drift,
        random_state=args.seed,
        verbose=progress_verbosity(model_class, args.n_iter),
    )


def _load(load, data_home, what, fetch_options="", **kwargs):
    """``load(data_home, **kwargs)``, or an error saying how to fetch ``what``."""
    try:
        return load(data_home, **kwargs)
    except FileNotFoundError as exc:
        home = get_data_home(data_home)
        raise FileNotFoundError(
            f"{exc}\n{what} not in {home}. Download it with\n"
            f"    python -m sklearn_crbm fetch{fetch_options} --data-home {home}\n"
            "or point --data-home (or $SKLEARN_CRBM_DATA) at a folder that holds it."
        ) from None


def _load_cmu35(data_home, subset):
    return _load(load_cmu35, data_home, "The CMU subject 35 data is", subset=subset)


def run_demo(args):
    if args.full:
        args.n_iter, args.n_repeats = 4000, 100
    train = _load_cmu35(args.data_home, "train")
    test = _load_cmu35(args.data_home, "test")
    return _run_demo(args, train, test, _model_from_args(args))


def run_fetch(args):
    home = get_data_home(args.data_home)
    existed = home.exists()
    fetchers = {
        "cmu35": fetch_cmu35,
        "mit": fetch_mit_walk,
        "bandai": fetch_bandai_walks,
        "bandai-dataset2": fetch_bandai_dataset2,
    }
    print(f"downloading into {home}")
    try:
        for name in dict.fromkeys(args.dataset or ["cmu35", "mit"]):
            fetchers[name](home)
    except BaseException:
        if not existed:  # everything in it is this command's partial download
            shutil.rmtree(home, ignore_errors=True)
        raise
    print("done")
    return 0


def run_fit(args):
    data, styles = _training_data(args)
    several = styles is not None and styles.ndim == 2
    n = len(data.sequence_names)
    print(
        f"training on {len(data.data)} frames of {n} sequence{'s' * (n != 1)} "
        f"at {data.frame_rate:g} frames/s"
        + (f", labels {_labels_summary(data, styles)}" if args.labels else "")
    )
    if several and args.speed_context:
        raise ValueError(
            "--speed-context trains with speed as the model's context, several "
            "--labels with the labels: give one of the two."
        )
    _check_order(args.order, data)
    pipeline = make_motion_pipeline(
        data.skeleton, _model_from_args(args, labelled=several)
    )
    speed = _speed_context(data, styles) if args.speed_context else {}
    context = {"context": speed.pop("speeds")} if speed else {}
    if several:  # one model of every label: a factor per key
        pipeline.fit(data.data, styles, sequence_ids=data.sequence_ids)
    else:
        pipeline.fit(data.data, sequence_ids=data.sequence_ids, **context)
    windows = {}
    if styles is not None:
        windows = pipeline.style_windows(
            data.data,
            styles,
            sequence_ids=data.sequence_ids,
            n_windows=N_STYLE_WINDOWS,
            random_state=args.seed,
        )
    keys = {"label_keys": data.label_keys} if several else {}
    saved = Bunch(
        pipeline=pipeline,
        seed_windows=windows,
        frame_rate=data.frame_rate,
        **keys,
        **speed,
    )
    joblib.dump(dict(saved), args.output)
    print(f"saved the fitted pipeline to {args.output}")
    return 0


def _labels_summary(data, labels):
    """``"fast, slow"``, or for several keys ``"content: run, walk; style:
    elderly, normal (3 of their 4 combinations)"``."""
    if labels.ndim == 1:
        return ", ".join(dict.fromkeys(labels))
    names = [
        f"{key}: {', '.join(map(str, known))}"
        for key, known in zip(data.label_keys, data.target_names, strict=True)
    ]
    seen = len({tuple(row) for row in labels.tolist()})
    possible = int(np.prod([len(known) for known in data.target_names]))
    return f"{'; '.join(names)} ({seen} of their {possible} combinations)"


def _speed_context(data, styles):
    """``fit --speed-context``: the fitted speed measure and the speeds.

    Prints the range of the training speeds (and each style's mean), the
    speeds ``sample --speed`` can ask for with confidence.
    """
    speed = MotionContext(
        data.skeleton, signals=["forward_speed"], frame_rate=data.frame_rate
    )
    speeds = speed.fit_transform(data.data, sequence_ids=data.sequence_ids)
    means = ""
    if styles is not None:
        means = ", ".join(
            f"{style} {speeds[styles == style].mean():.1f}"
            for style in dict.fromkeys(styles)
        )
        means = f" (mean: {means})"
    print(
        f"forward speed as context: {speeds.min():.1f} to {speeds.max():.1f} "
        f"length units per second{means}"
    )
    return dict(speed=speed, speeds=speeds)


def _training_data(args):
    """The training motion, and each frame's style where it is known."""
    if args.folder is None:
        if args.labels is not None:
            raise ValueError(
                "--labels labels the files of a folder: give the folder too."
            )
        train = _load_cmu35(args.data_home, "train")
        return train, np.asarray(train.motion, dtype=object)[train.sequence_ids]
    data = _read_motion_folder(args.folder, args.frame_rate, args.labels)
    if args.labels is None:
        return data, None
    if "label_keys" in data:  # several: the names themselves
        return data, data.target
    return data, data.target_names[data.target]


def _read_motion_folder(folder, frame_rate=None, labels=None):
    """A folder of BVH files, or of AMC files with their ASF skeleton.

    ``frame_rate`` None: the files' own rate, brought down to
    ``MAX_DEFAULT_RATE`` when faster.  ``labels``: see ``fit --labels``; the
    label names are text, as typed after ``--style`` (also labels that are
    numbers).  With several keys, ``target`` holds every frame's names,
    one column per key, ``target_names`` the names of each key and
    ``label_keys`` the keys.
    """
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder} is not a folder.")
    if any(folder.glob("*.bvh")):
        read = read_bvh_folder
    elif any(folder.glob("*.amc")):
        read = read_amc_folder
    else:
        raise FileNotFoundError(
            f"{folder} holds no *.bvh or *.amc file: the command reads a folder "
            "of BVH files, or of AMC files with their ASF skeleton."
        )
    keys = label_keys(labels)
    several = keys is not None and len(keys) > 1
    labels = keys if several else _label_source(labels)
    try:
        data = read(folder, frame_rate=frame_rate, labels=labels)
    except ValueError as exc:
        if "by dropping frames" not in str(exc):  # not about the frame rates
            raise
        if frame_rate is None:  # the files disagree: say the option to pass
            raise ValueError(str(exc).replace("frame_rate=", "--frame-rate ")) from None
        raise ValueError(
            f"--frame-rate {frame_rate:g}: {exc} On the command line, --frame-rate "
            "sets the rate to train at: at most the slowest file's (leave it out to "
            "train at the files' own rate)."
        ) from None
    if several:
        data.target_names = [names.astype(str) for names in data.target_names]
        data.label_keys = keys
        _check_label_names(data)
    if frame_rate is None and data.frame_rate > MAX_DEFAULT_RATE:
        keep = resample_frames(
            np.arange(len(data.data)),
            frame_rate=data.frame_rate,
            target_rate=MAX_DEFAULT_RATE,
            sequence_ids=data.sequence_ids,
        )
        for key in ("data", "sequence_ids", "target"):
            if key in data:
                data[key] = data[key][keep]
        data.frame_rate = MAX_DEFAULT_RATE
    if labels is not None and not several:
        data.target_names = np.array([str(name) for name in data.target_names])
    return data


def _check_label_names(data):
    """Names that ``sample --label`` can give back: no comma in any."""
    for key, names in zip(data.label_keys, data.target_names, strict=True):
        odd = [str(name) for name in names if "," in name]
        if odd:
            raise ValueError(
                f"the {key} label {odd[0]!r} holds a comma, which separates the "
                "labels of 'sample --label'; rename the labels in the label "
                "files."
            )


def _label_source(labels):
    """``--labels`` as the folder readers take it: a pattern with a group, or a key."""
    if labels is None or "(" not in labels:
        return labels
    try:
        pattern = re.compile(labels)
    except re.error as exc:
        raise ValueError(
            f"--labels {labels!r} is not a regular expression: {exc}."
        ) from None
    if pattern.groups != 1:
        raise ValueError(
            f"--labels {labels!r} must have one group, the label: e.g. "
            "'walk_([a-z]+)_'."
        )
    return pattern


def _check_order(order, data):
    """Say in the command's terms when no training sequence is long enough."""
    longest = int(np.bincount(data.sequence_ids).max())
    if longest <= order:
        raise ValueError(
            f"--order {order} needs sequences of more than {order} frames, but "
            f"the longest training sequence has {longest} frames at "
            f"{data.frame_rate:g} frames/s: lower --order, or train on longer "
            "(or faster, with --frame-rate) takes."
        )


def _load_model(path):
    """What ``fit`` saved, as a Bunch; a clear error for anything else."""
    try:
        saved = joblib.load(path)
    except FileNotFoundError:
        raise
    except Exception as exc:  # joblib/pickle raise many types on foreign files
        raise ValueError(
            f"{path} is not a model saved by 'python -m sklearn_crbm fit' "
            f"({type(exc).__name__}: {exc})."
        ) from None
    if not isinstance(saved, dict) or not isinstance(
        saved.get("pipeline"), MotionPipeline
    ):
        raise ValueError(
            f"{path} holds a {type(saved).__name__}, not what 'python -m "
            "sklearn_crbm fit' saves (a dict with a fitted MotionPipeline); fit "
            "the model again with this version."
        )
    return Bunch(**saved)


def run_sample(args):
    saved = _load_model(args.model)
    pipeline = saved.pipeline
    request = _label_request(saved, args)
    history, seeded = _seeds(saved, args, request)
    with warnings.catch_warnings():
        # every sequence's verdict is printed beside its file, once
        warnings.simplefilter("ignore", GenerationWarning)
        raw = pipeline.sample(
            args.n_frames,
            history=history,
            n_sequences=args.n_sequences,
            hidden_noise=args.hidden_noise,
            random_state=args.seed,
            **({} if request is None else {"y": request}),
            **_sampler_request(args),
            **_speed_request(saved, args),
        )
    suffixes = [".bvh"] + [".amc"] * (pipeline.skeleton.convention == "acclaim")
    verdicts, failed = _verdicts(pipeline, raw, args.n_frames)
    sequences = np.split(raw, args.n_sequences)
    args.output.mkdir(parents=True, exist_ok=True)
    print(f"generated motion goes to {args.output} (--output to change)")
    for k, sequence in enumerate(sequences):
        measured = _speed_text(saved, sequence)
        for suffix in suffixes:
            path = args.output / f"generated_{k}{suffix}"
            pipeline.write_motion(path, sequence, frame_rate=saved.frame_rate)
            print(f"wrote {path.name} ({seeded}; {verdicts[k]}{measured})")
    if failed:
        print(
            "  to keep generated motion moving, seed it with real frames of the "
            "motion wanted (--style, or --seed-file PATH --seed-frame N), or fit "
            "for longer (fit --n-iter) or on more takes"
        )
    if args.animate:
        path = save_gif(
            args.output / "generated.gif",
            pipeline.skeleton,
            sequences,
            titles=[f"generated_{k}" for k in range(len(sequences))],
            frame_rate=saved.frame_rate,
            view=args.view,
        )
        print(f"wrote {path.name}")
    return 0


def _label_request(saved, args):
    """``sample --label``: one label per key of a model fitted on several
    (``fit --labels content,style``), checked; None for any other model."""
    keys = saved.get("label_keys")
    if keys is None:
        if args.label is not None:
            raise ValueError(
                f"--label asks for labels of a model fitted on several (fit "
                f"--labels content,style); {args.model} was not: seed it with "
                "real frames of a label with --style."
            )
        return None
    if args.style is not None:
        raise ValueError(
            f"{args.model} was fitted on the labels {', '.join(keys)}: ask for "
            f"them with --label (such as --label {_a_label(saved)}), "
            "not --style."
        )
    if args.label is None:
        raise ValueError(
            f"{args.model} was fitted on the labels {', '.join(keys)}: say which "
            f"to generate with --label, one of each (such as --label "
            f"{_a_label(saved)})."
        )
    return label_request(args.label, keys, saved.pipeline[-1].classes_)


def _a_label(saved):
    """The labels of the first seed windows a model of several labels keeps,
    as ``sample --label`` takes them."""
    return label_text(next(iter(saved.seed_windows)))


def _sampler_request(args):
    """``sample``'s ``--n-mean-field`` and ``--hidden-drift`` where given
    (left out, the saved model's own parameters)."""
    asked = dict(n_mean_field=args.n_mean_field, hidden_drift=args.hidden_drift)
    return {name: value for name, value in asked.items() if value is not None}


def _speed_request(saved, args):
    """``sample``'s context for ``--speed``: ``{}`` for a model without one."""
    if "speed" not in saved:
        if args.speed is not None:
            raise ValueError(
                f"{args.model} was fitted without speed as context: fit it with "
                "--speed-context to generate at a --speed."
            )
        return {}
    if args.speed is None:
        raise ValueError(
            f"{args.model} was fitted with speed as context: give --speed (its "
            "training frames move at "
            f"{saved.pipeline[-1].context_mean_[0]:.1f} length units per "
            "second on average)."
        )
    requested = np.linspace(*args.speed, args.n_frames)[:, None]
    return {"context": requested}


def _speed_text(saved, sequence):
    """``", forward speed 40.2"`` for a model fitted with speed; else ``""``."""
    if "speed" not in saved:
        return ""
    return f", forward speed {saved.speed.transform(sequence).mean():.1f}"


def _verdicts(pipeline, raw, n_frames):
    """Each generated sequence's verdict, and whether any failed.

    ``"lively 0.93"``, ``"lively 0.00: came to rest"`` (below
    ``DEAD_FRACTION``) or ``"blew up"``, judged as the model's
    :class:`GenerationWarning` judges them (``lively -`` for a model saved
    by a version that kept no statistics).
    """
    n_sequences = len(raw) // n_frames
    statistics = getattr(pipeline[-1], "generation_statistics_", None)
    if statistics is None:
        return [liveliness_text(np.nan)] * n_sequences, False
    ids = np.repeat(np.arange(n_sequences), n_frames)
    Z = pipeline[:-1].transform(raw, sequence_ids=ids)
    lively = generated_liveliness(Z, n_frames, statistics)
    verdicts = []
    for k in range(n_sequences):
        blown = "blew up" in lifeless_message(Z[ids == k], n_frames, statistics)
        verdicts.append("blew up" if blown else liveliness_text(lively[k]))
    failed = any(v == "blew up" for v in verdicts) or bool(
        np.any(lively < DEAD_FRACTION)
    )
    return verdicts, failed


def _seeds(saved, args, request=None):
    """``sample``'s history and what it is: saved windows of the chosen
    style or labels (``request``), frames of ``--seed-file``, or None (the
    model's own windows)."""
    asked = "" if request is None else f"{label_text(request)}, "
    if args.seed_frame is not None and args.seed_file is None:
        raise ValueError("--seed-frame N picks a frame of --seed-file PATH: give both.")
    if args.seed_file is not None:
        if args.style is not None:
            raise ValueError(
                "--style and --seed-file both choose the seed frames: give one."
            )
        seed = seed_from_file(
            saved.pipeline, saved.frame_rate, args.seed_file, args.seed_frame
        )
        history = np.repeat(seed.window[None], args.n_sequences, axis=0)
        return history, f"{asked}seeded with {seed.text}"
    rng = np.random.default_rng(args.seed)
    if request is not None:
        windows, name = seed_windows_for(saved.seed_windows, request)
        if windows is None:
            return None, f"{asked}seeded with training frames"
        chosen = windows[rng.integers(len(windows), size=args.n_sequences)]
        return chosen, f"{asked}seeded with {name} frames"
    if args.style is None:
        return None, "seeded with training frames"
    if args.style not in saved.seed_windows:
        known = ", ".join(saved.seed_windows) or "none"
        raise ValueError(
            f"{args.model} keeps no seed frames of style {args.style!r} (its "
            f"styles: {known}); leave --style out to seed from every training "
            "sequence, or seed from a take of your own with --seed-file."
        )
    windows = saved.seed_windows[args.style]
    chosen = windows[rng.integers(len(windows), size=args.n_sequences)]
    return chosen, f"seeded with {args.style} frames"


def run_styles(args):
    keys = label_keys(args.labels)
    if args.folder is not None and len(keys) > 1:
        raise ValueError(
            f"--labels {args.labels}: the styles command models one label (a "
            "style); to model several, train with 'fit FOLDER --labels "
            f"{args.labels}' and generate with 'sample MODEL --label ...'."
        )
    if args.folder is not None:
        walks = _read_motion_folder(args.folder, args.frame_rate, args.labels)
        walks.noun = _content_noun(args.folder, walks)
        kind = "" if walks.noun == "take" else f"{walks.noun} "
        walks.name = f"the {kind}takes in {args.folder}"
    else:
        walks = _load(
            load_bandai_walks,
            args.data_home,
            "The Bandai Namco walks are",
            " --dataset bandai",
        )
        walks.name = "Bandai Namco walks"
        walks.noun = "walk"
    model = FactoredCRBM(
        args.n_components,
        n_factors=args.n_factors,
        n_style_features=args.n_style_features,
        order=args.order,
        n_iter=args.n_iter,
        n_gibbs=args.n_gibbs,
        n_mean_field=args.n_mean_field,
        hidden_drift=args.hidden_drift,
        random_state=args.seed,
        verbose=progress_verbosity(FactoredCRBM, args.n_iter),
    )
    _check_order(args.order, walks)
    return _run_styles(args, walks, model)


def _content_noun(folder, data):
    """What the takes of a folder are: the one content of their JSON labels
    (``"wave-left-hand"``, as the Bandai Namco files name it), else "take"."""
    paths = [Path(name) for name in data.filenames]
    try:
        codes, names = file_labels(folder, paths, "content")
    except (OSError, ValueError, TypeError):  # no content labels
        return "take"
    contents = set(names[codes].tolist())
    return contents.pop() if len(contents) == 1 else "take"


_RUNS = {
    "demo": run_demo,
    "fetch": run_fetch,
    "fit": run_fit,
    "sample": run_sample,
    "styles": run_styles,
}
