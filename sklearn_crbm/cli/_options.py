"""The command line's commands and their arguments (see :mod:`._main`)."""

import argparse
import math
from pathlib import Path

from ..models._crbm import ConditionalRBM
from ..models._factored import FactoredCRBM
from ..plotting._skeleton import VIEWS

__all__ = ["COMMANDS", "OUTPUT"]

# The commands that write figures and motion write into OUTPUT / command in
# the current folder unless --output says otherwise: one user's runs in one
# place of their own, never shared with other users of the machine.
OUTPUT = Path("sklearn_crbm_output")
# The model options default to the estimators' own defaults.
_DEFAULTS = ConditionalRBM()


def _epochs(text):
    """``--n-iter``: ``auto`` or a whole number of at least 1."""
    return text if text == "auto" else _count(1)(text)


def progress_verbosity(model_class, n_iter):
    """``verbose`` for a fit of ``n_iter`` epochs: a line every tenth of them
    (``"auto"``: of the epochs the class's budget starts from)."""
    epochs = model_class._update_budget.epochs if n_iter == "auto" else n_iter
    return max(1, epochs // 10)


_FACTORED = FactoredCRBM()


def _option(*flags, help, **settings):
    """One argument of a command: its flags and ``add_argument``'s settings."""
    return flags, dict(help=help, **settings)


def _checked(convert, kind, accept, bound):
    """An argparse type: ``convert(text)``, which ``accept`` must hold for.

    argparse names the flag in the errors, e.g. "argument --n-iter: must be
    at least 1, got 0".
    """

    def parse(text):
        try:
            value = convert(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {kind}, got {text!r}") from None
        if not accept(value):
            raise argparse.ArgumentTypeError(f"must be {bound}, got {text}")
        return value

    return parse


def _count(minimum):
    """An argparse type: a whole number of at least ``minimum``."""
    return _checked(
        int, "a whole number", lambda n: n >= minimum, f"at least {minimum}"
    )


_rate = _checked(
    float, "a number of frames per second", lambda r: 0 < r < math.inf, "positive"
)
_non_negative = _checked(float, "a number", lambda x: 0 <= x < math.inf, "at least 0")


def _sampler_options(defaults, what):
    """``--n-mean-field`` and ``--hidden-drift``: parameters that only
    sampling reads, with ``defaults``' values (None: the saved model's)."""
    default = "the saved model's own" if defaults is None else None
    return [
        _option(
            "--n-mean-field",
            type=_count(1),
            default=None if defaults is None else defaults.n_mean_field,
            help=f"mean-field steps that end every generated frame{what}: more "
            "is smoother, fewer lets the sequences drawn from one seed differ"
            + (f" (default: {default})" if default else ""),
        ),
        _option(
            "--hidden-drift",
            type=_non_negative,
            default=None if defaults is None else defaults.hidden_drift,
            help="standard deviation of a smooth random offset of the hidden "
            f"biases that keeps the sequences drawn from one seed apart{what}; "
            "0: none" + (f" (default: {default})" if default else ""),
        ),
    ]


def _speed_request(text):
    """``--speed``: ``SPEED`` or a ramp ``FROM:TO``, as ``(from, to)``."""
    parts = text.split(":")
    try:
        if len(parts) > 2:
            raise ValueError
        start, stop = (float(part) for part in (parts * 2)[:2])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be a speed (40) or a ramp from one speed to another (20:60), "
            f"got {text!r}"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    return start, stop


# A folder's motion is trained at its files' own rate, but at most this many
# frames per second (the paper's 30; CMU's AMC files are 120).
MAX_DEFAULT_RATE = 30.0


_DATA_HOME = _option(
    "--data-home",
    type=Path,
    help="data folder (default: $SKLEARN_CRBM_DATA, else ~/sklearn_crbm_data)",
)
_N_FRAMES = _option(
    "--n-frames", type=_count(1), default=300, help="frames generated per sequence"
)
_SEED = _option(
    "--seed", type=int, default=0, help="random seed of training and sampling"
)
_FRAME_RATE = _option(
    "--frame-rate",
    type=_rate,
    help="frames per second to train at; faster files drop frames (default: "
    f"the files' own rate, at most {MAX_DEFAULT_RATE:g}; AMC files are read as "
    "120 frames/s, CMU's rate)",
)
_VIEW = _option(
    "--view",
    choices=VIEWS,
    default="auto",
    help="where the figures and GIFs look from: auto faces the plane in which "
    "the motion moves most (a walk from the side, a hand wave from the front, "
    "a turn from above); front, side or top",
)


def _output(command, what):
    """``--output DIR`` of a command that writes files."""
    return _option(
        "--output",
        type=Path,
        default=OUTPUT / command,
        help=f"folder for {what}, made if missing",
    )


_MODEL_OPTIONS = [
    _option(
        "--n-components", type=_count(1), default=200, help="hidden units of the CRBM"
    ),
    _option(
        "--order", type=_count(0), default=3, help="past frames each frame depends on"
    ),
    _option(
        "--history-noise",
        type=float,
        default=_DEFAULTS.history_noise,
        help="noise on the history during training (0 is the paper's schedule, "
        "whose fill-ins and generated styles drift for some seeds)",
    ),
    _option(
        "--history-noise-fraction",
        type=float,
        default=_DEFAULTS.history_noise_fraction,
        help="share of each training frame's channels whose history gets the noise",
    ),
    _option(
        "--average-fraction",
        type=float,
        default=_DEFAULTS.average_fraction,
        help="final share of the epochs whose parameters are averaged (0: keep "
        "the last epoch's, the paper's schedule)",
    ),
    _option(
        "--n-iter",
        type=_epochs,
        default=_DEFAULTS.n_iter,
        help="training epochs (the paper: 4000); auto: enough for 25,000 "
        "minibatch updates, at least 1000, at most 100,000 updates",
    ),
    *_sampler_options(_DEFAULTS, ", saved with the model"),
    _SEED,
]
_FACTORED_OPTIONS = [
    _option(
        "--n-components",
        type=_count(1),
        default=_FACTORED.n_components,
        help="hidden units of the factored CRBM",
    ),
    _option(
        "--n-factors",
        type=_count(1),
        default=_FACTORED.n_factors,
        help="factors of each kind (autoregressive, past-to-hidden, undirected)",
    ),
    _option(
        "--n-style-features",
        type=_count(1),
        default=_FACTORED.n_style_features,
        help="real-valued style features the labels map to",
    ),
    _option(
        "--order",
        type=_count(0),
        default=_FACTORED.order,
        help="past frames each frame depends on",
    ),
    _option(
        "--n-iter",
        type=_epochs,
        default=_FACTORED.n_iter,
        help="training epochs (the released code: 200); auto: 200, at most "
        "32,000 minibatch updates",
    ),
    _option(
        "--n-gibbs",
        type=_count(0),
        default=_FACTORED.n_gibbs,
        help="Gibbs iterations per generated frame",
    ),
    *_sampler_options(_FACTORED, ""),
    _SEED,
]


COMMANDS = {
    "demo": (
        "the paper's demo on CMU 35: train, fill in, generate, draw",
        "Train a CRBM on CMU subject 35, print the fill-in table against "
        "nearest neighbour, KNNImputer and the autoregressive imputer, "
        "generate walking and jogging, and write figures, BVH/AMC files and a "
        "GIF of real and generated motion moving side by side. "
        "The defaults take a few minutes on 2 cores; --full runs the paper's "
        "4000 epochs and 100 fill-in repeats.",
        [
            _DATA_HOME,
            *_MODEL_OPTIONS,
            _output("demo", "the figures and the generated motion (BVH and AMC files)"),
            _VIEW,
            _option(
                "--n-repeats",
                type=_count(1),
                default=20,
                help="single-draw fills averaged per case (the paper: 100)",
            ),
            _option(
                "--n-particles",
                type=_count(1),
                default=20,
                help="weighted particles per fill-in chain (1: the original scheme)",
            ),
            _N_FRAMES,
            _option(
                "--full",
                action="store_true",
                help="the paper's full size: 4000 epochs, 100 fill-in repeats",
            ),
            _option(
                "--no-figures",
                action="store_true",
                help="skip the figures and GIFs (the BVH and AMC files are still "
                "written)",
            ),
        ],
    ),
    "fetch": (
        "download CMU 35 and the MIT walking data",
        "Download CMU subject 35 (ASF/AMC, the paper's 33 walking and jogging "
        "trials) and Taylor's MIT walking data into the data folder, or the "
        "data sets named with --dataset, checking every file's SHA-256.",
        [
            _DATA_HOME,
            _option(
                "--dataset",
                action="append",
                choices=["cmu35", "mit", "bandai", "bandai-dataset2"],
                help="download this data set (repeat for several): cmu35, "
                "mit (Taylor's MIT walking data), bandai (the Bandai Namco "
                "walks in seven styles, 15 MB, CC BY-NC 4.0, for the styles "
                "command) or bandai-dataset2 (the Bandai Namco corpus of ten "
                "contents in seven styles, takes 001-012, 840 takes with "
                "content and style labels, 174 MB, CC BY-NC 4.0, for 'fit "
                "--labels content,style'); default: cmu35 and mit",
            ),
        ],
    ),
    "fit": (
        "train preprocessing + CRBM on motion files and save it",
        "Train the motion preprocessing and a ConditionalRBM on a folder of "
        "BVH files or ASF/AMC files (each file one sequence, all of one "
        "skeleton), or on CMU subject 35 when no folder is given, and save "
        "them with joblib for the sample command. The file holds a dict: "
        "'pipeline' (a fitted sklearn_crbm.preprocessing.MotionPipeline), "
        "'seed_windows' (real frames of each style: CMU 35's walk and jog, "
        "or the labels of --labels), "
        "'frame_rate' and, with --speed-context, 'speed' (the fitted "
        "MotionContext whose output is the model's context).",
        [
            _option(
                "folder",
                type=Path,
                nargs="?",
                help="a folder of *.bvh files, or of *.amc files with their *.asf "
                "(default: CMU subject 35's training trials from --data-home)",
            ),
            _DATA_HOME,
            _FRAME_RATE,
            _option(
                "--labels",
                help="label every file, and keep seed frames of each label for "
                "'sample --style': a key of the JSON file beside each motion "
                "file ('style' reads walk_001.json's {\"style\": 2}, named by "
                "style_label.txt when there is one), or a regular expression "
                "with a group, matched against each file's name "
                "('walk_([a-z]+)_' labels walk_proud_01.bvh 'proud'); several "
                "keys separated by commas ('content,style') train one "
                "LabelledCRBM of all of them, one label factor per key, that "
                "'sample --label run,elderly' asks for any combination",
            ),
            _option(
                "--speed-context",
                action="store_true",
                help="train with every frame's forward speed as the model's "
                "context (MotionContext, 1-s window, z-scored), so that "
                "'sample --speed' can ask for a speed",
            ),
            *_MODEL_OPTIONS,
            _option(
                "--output",
                type=Path,
                default=Path("crbm.joblib"),
                help="file the fitted pipeline (preprocessing + CRBM) is saved to",
            ),
        ],
    ),
    "sample": (
        "generate motion from a saved model and write BVH (and AMC) files",
        "Generate motion from a model saved by the fit command and write one "
        "BVH file per sequence, and an AMC file beside it when the model was "
        "trained on ASF/AMC files. The seed frames are saved with the model, "
        "or come from a take of your own (--seed-file).",
        [
            _option("model", type=Path, help="a file written by the fit command"),
            _option(
                "--style",
                help="seed each sequence with real frames of this style ('walk' "
                "or 'jog' for CMU 35); default: the model's own seed windows, "
                "from every training sequence",
            ),
            _option(
                "--label",
                metavar="LABEL,LABEL",
                help="for a model fitted on several labels ('fit --labels "
                "content,style'): the labels of the generated motion, one per "
                "key in their order, such as run,elderly; any combination, "
                "also one the training takes lack (seeded then with frames "
                "of the nearest labels)",
            ),
            _option(
                "--seed-file",
                type=Path,
                metavar="PATH",
                help="seed every sequence with real frames of this take of your "
                "own (a BVH file of the model's skeleton, or an AMC file for a "
                "model fitted on ASF/AMC): the generated motion continues it "
                "after --seed-frame",
            ),
            _option(
                "--seed-frame",
                type=_count(0),
                metavar="N",
                help="with --seed-file: the last real frame, counted from 0 at "
                "the file's own rate (default: the take's middle frame)",
            ),
            _option(
                "--speed",
                type=_speed_request,
                help="forward speed to generate at, in the training data's length "
                "units per second: SPEED for every frame, or FROM:TO for a "
                "steady change over the frames (20:60 speeds a CMU 35 walk up "
                "into a jog); for a model fitted with --speed-context",
            ),
            _N_FRAMES,
            _option(
                "--n-sequences", type=_count(1), default=1, help="sequences generated"
            ),
            _option(
                "--hidden-noise",
                type=float,
                default=0.0,
                help="standard deviation of Gaussian noise on the hidden biases "
                "at every frame: 0 follows the model's own dynamics, more noise "
                "lets the motion switch styles (paper §4.3)",
            ),
            *_sampler_options(None, ""),
            _option(
                "--seed",
                type=int,
                default=0,
                help="random seed of the seeds and sampling",
            ),
            _output(
                "sample",
                "the generated motion (generated_0.bvh, generated_1.bvh, ... and "
                "generated.gif)",
            ),
            _option(
                "--animate",
                action="store_true",
                help="also write generated.gif: the generated sequences moving side "
                "by side (needs matplotlib and pillow)",
            ),
            _VIEW,
        ],
    ),
    "styles": (
        "many styles from one factored CRBM: BVH files, strips, a judge",
        "Train a FactoredCRBM (Taylor & Hinton, ICML 2009) on the Bandai "
        "Namco walks in seven styles (or on a labelled folder of your own, "
        "--folder and --labels), generate every style, a "
        "50/50 blend of two styles and a transition from one style to "
        "another half-way, all seeded with real frames of one style, "
        "and write them as BVH files with a skeleton strip of each, a "
        "plot of the style judge's probabilities over the transition, and "
        "GIFs of every style moving side by side and of the transition over "
        "the judge's probabilities. "
        "Prints a table of how a StyleJudge trained on the real takes sees "
        "every style: the share of 2-s windows judged as the style asked "
        "for, and the amplitude and frequency of the joints that move most "
        "in the real takes (the legs of a walk, the arm of a wave) against "
        "theirs, beside the judge's verdict on the real takes. The defaults "
        "train for several minutes; fetch the data first with 'fetch "
        "--dataset bandai'.",
        [
            _DATA_HOME,
            _option(
                "--folder",
                type=Path,
                help="train on this labelled folder of BVH files instead of the "
                "Bandai walks (labels from --labels)",
            ),
            _option(
                "--labels",
                default="style",
                help="with --folder: where each file's style comes from, as for "
                "'fit --labels' (a JSON key, or a regular expression with a "
                "group matched against the file names)",
            ),
            _FRAME_RATE,
            *_FACTORED_OPTIONS,
            _output("styles", "the BVH files and the figures"),
            _VIEW,
            _option(
                "--n-frames",
                type=_count(1),
                default=600,
                help="frames generated per sequence (at least 120)",
            ),
            _option(
                "--n-sequences",
                type=_count(1),
                default=3,
                help="sequences generated per style, blend and transition: the "
                "table judges them all, the first is written",
            ),
            _option(
                "--seed-style",
                help="every sequence starts from real frames of this style "
                "(default: normal, or the first style of a folder without it)",
            ),
            _option(
                "--blend",
                nargs=2,
                metavar="STYLE",
                help="the two styles blended 50/50 (default: elderly youthful, "
                "or a folder's first two styles)",
            ),
            _option(
                "--transition",
                nargs=2,
                metavar="STYLE",
                help="the style at the start and the style from half-way on "
                "(default: active elderly, or a folder's first two styles)",
            ),
            _option(
                "--no-figures",
                action="store_true",
                help="skip the figures and GIFs (the BVH files are still written)",
            ),
        ],
    ),
}
