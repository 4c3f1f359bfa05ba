"""The documentation builds without warnings, and its code runs.

``test_docs_build`` runs ``sphinx-build -W --keep-going -b html`` (warnings
are errors) without executing the gallery examples, as CI and a contributor
do after ``pip install -e ".[docs]"``, and checks the key pages.  It builds a
copy of ``doc`` in a temporary folder, so the files a build generates among
the sources (``api.rst``, ``generated/``, ``auto_examples/``...) never land in
the checkout.
``test_user_guide_code`` runs the ``>>>`` examples of the hand-written pages
(getting started, user guide) as doctests, so the guide cannot fall behind the
code.
"""

import ast
import doctest
import io
import os
import re
import shutil
import subprocess
import sys
from contextlib import redirect_stdout
from pathlib import Path

import pytest
import sklearn

REPO_ROOT = Path(__file__).resolve().parents[1]
DOC_DIR = REPO_ROOT / "doc"

# Hand-written pages whose >>> examples are doctests.
CODE_PAGES = sorted(
    path.relative_to(DOC_DIR).as_posix()
    for path in [*DOC_DIR.glob("*.rst"), *DOC_DIR.glob("user_guide/*.rst")]
    if ">>>" in path.read_text(encoding="utf-8")
)


def _tree(folder):
    """Every file and folder below ``folder``, ignored ones included."""
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


@pytest.fixture(scope="module")
def docs_build(tmp_path_factory, data_home):
    """Build the HTML documentation once from a copy of ``doc``.

    Returns ``(source, html, doc_tree_before)``: the copied source folder (it
    holds what the build generated), the output folder, and the checkout's
    ``doc`` tree before the build.
    """
    before = _tree(DOC_DIR)
    # the copy keeps the layout the docs expect: the package and benchmarks
    # beside the doc folder
    repo = tmp_path_factory.mktemp("docs") / "repo"
    shutil.copytree(DOC_DIR, repo / "doc", ignore=shutil.ignore_patterns(*GENERATED))
    for name in ("sklearn_crbm", "benchmarks"):
        (repo / name).symlink_to(REPO_ROOT / name, target_is_directory=True)
    out = repo.parent / "html"
    env = dict(os.environ)
    env["SKLEARN_CRBM_DOCS_RUN_EXAMPLES"] = "0"  # gallery shown, not executed
    env["SKLEARN_CRBM_DATA"] = str(data_home)
    env.setdefault("MPLBACKEND", "Agg")
    command = [
        sys.executable,
        "-m",
        "sphinx",
        "-W",
        "--keep-going",
        "-q",
        "-b",
        "html",
        "-d",
        str(repo.parent / "doctrees"),
        str(repo / "doc"),
        str(out),
    ]
    result = subprocess.run(
        command,
        cwd=REPO_ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    if result.returncode != 0:
        if "No module named sphinx" in result.stderr:
            pytest.fail(
                'Sphinx is not installed: pip install -e ".[docs]" (the docs '
                "build is part of the test suite)."
            )
        pytest.fail(
            "sphinx-build -W failed (warnings are errors):\n"
            + result.stdout[-5000:]
            + result.stderr[-10000:]
        )
    return repo / "doc", out, before


# What a build writes among the sources (doc/.gitignore), left out of the copy.
GENERATED = ("_build", "api.rst", "generated", "auto_examples", "gen_modules")


@pytest.fixture(scope="module")
def html_dir(docs_build):
    return docs_build[1]


def test_docs_build(html_dir):
    for page in [
        "index.html",
        "getting_started.html",
        "glossary.html",
        "api.html",
        "benchmarks.html",
        "what_we_tried.html",
        "auto_examples/index.html",
        "generated/sklearn_crbm.ConditionalRBM.html",
        "generated/sklearn_crbm.FactoredCRBM.html",
        "generated/sklearn_crbm.LabelledCRBM.html",
        "generated/sklearn_crbm.metrics.StyleJudge.html",
        "generated/sklearn_crbm.datasets.load_bandai_walks.html",
        "generated/sklearn_crbm.datasets.fetch_bandai_walks.html",
        "generated/sklearn_crbm.plotting.plot_style_probabilities.html",
    ]:
        assert (html_dir / page).is_file(), page
    for page in [
        "data_model",
        "preprocessing",
        "own_data",
        "training",
        "generation",
        "filling_in",
        "stacking",
        "model_selection",
        "saving",
        "scaling",
        "labelled_motion",
        "styles",
        "control",
    ]:
        assert (html_dir / "user_guide" / f"{page}.html").is_file(), page

    rbm = (html_dir / "generated" / "sklearn_crbm.ConditionalRBM.html").read_text(
        encoding="utf-8"
    )
    for method in ["fit", "partial_fit", "transform", "score", "sample"]:
        assert f'id="sklearn_crbm.ConditionalRBM.{method}"' in rbm, method


def test_docs_build_leaves_the_checkout_untouched(docs_build):
    source, _, before = docs_build
    assert _tree(DOC_DIR) == before
    assert (source / "api.rst").is_file()  # generated in the copy instead


def test_api_reference_covers_every_public_name(docs_build):
    """Every name in a public module's ``__all__`` has its page."""
    source, html_dir, _ = docs_build
    api = (source / "api.rst").read_text(encoding="utf-8")
    modules = re.findall(r"^\.\. currentmodule:: (\S+)$", api, flags=re.M)
    assert "sklearn_crbm" in modules
    documented = {p.stem for p in (html_dir / "generated").glob("*.html")}
    for module_name in modules:
        module = __import__(module_name, fromlist=["__all__"])
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if name.startswith("_") or not callable(obj):
                continue
            qualified = f"{module_name}.{name}"
            # A re-export is documented once, under the module that defines it.
            assert qualified in documented or any(
                page.endswith(f".{name}") for page in documented
            ), qualified


def test_root_figure_is_drawn(html_dir):
    """The preprocessing page has its picture of the root representation."""
    page = (html_dir / "user_guide" / "preprocessing.html").read_text(encoding="utf-8")
    images = re.findall(r'<img [^>]*src="([^"]+plot_doc_root[^"]*\.png)"', page)
    assert images, "the root figure is missing from user_guide/preprocessing.html"
    assert (html_dir / "user_guide" / images[0]).resolve().is_file()


@pytest.mark.parametrize("page", CODE_PAGES)
def test_user_guide_code(page, data_home, monkeypatch):
    # Pages on real data load it from the default data folder, as a user's
    # script would once the data are fetched.
    monkeypatch.setenv("SKLEARN_CRBM_DATA", str(data_home))
    output = io.StringIO()
    # Pages switch metadata routing on; config_context puts it back.
    with sklearn.config_context(), redirect_stdout(output):
        failed, attempted = doctest.testfile(
            str(DOC_DIR / page),
            module_relative=False,
            optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
            report=True,
        )
    assert attempted > 0
    assert failed == 0, output.getvalue()


# Calls whose value (a matplotlib artist) sphinx-gallery would print as a
# stray line such as ``Text(0.5, 1.0, '...')`` when a cell ends with one.
_ARTIST_CALLS = re.compile(
    r"\.(set_\w+|plot|scatter|errorbar|annotate|legend|imshow|text|bar|hist)$"
)


def _gallery_problems(source):
    """What keeps a gallery page from showing each figure whole and alone.

    sphinx-gallery captures the figures at the end of each cell (``# %%``):
    a later cell drawing on a figure of an earlier one draws on a figure the
    page has already shown (the earlier cell's panels stay empty), and a cell
    ending with an artist-returning call prints its ``repr``.
    """
    problems, figures = [], {}
    for k, cell in enumerate(re.split(r"^# %%.*$", source, flags=re.M)):
        tree = ast.parse(cell)
        bound = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
                if ast.unparse(node.value.func) in ("plt.subplots", "plt.figure"):
                    for target in node.targets:
                        bound |= {
                            n.id for n in ast.walk(target) if isinstance(n, ast.Name)
                        }
        used = {
            n.id
            for n in ast.walk(tree)
            if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
        }
        for name in sorted((used & set(figures)) - bound):
            problems.append(f"cell {k} draws on {name!r} of cell {figures[name]}")
        figures.update(dict.fromkeys(bound, k))
        last = tree.body[-1] if tree.body else None
        if isinstance(last, ast.Expr) and isinstance(last.value, ast.Call):
            function = ast.unparse(last.value.func)
            if _ARTIST_CALLS.search(function):
                problems.append(f"cell {k} ends with {function}(...)")
    return problems


@pytest.mark.parametrize(
    "example", sorted(p.name for p in (DOC_DIR / "examples").glob("plot_*.py"))
)
def test_gallery_cells_draw_each_figure_whole(example):
    source = (DOC_DIR / "examples" / example).read_text(encoding="utf-8")
    assert _gallery_problems(source) == []


def test_gallery_check_finds_a_figure_drawn_across_cells():
    source = (
        "fig, ax = plt.subplots(1, 2)\nax[0].plot(x)\nax[0].set_title('a')\n"
        "# %%\nax[1].plot(y)\nfig.savefig(path)\n"
    )
    assert _gallery_problems(source) == [
        "cell 0 ends with ax[0].set_title(...)",
        "cell 1 draws on 'ax' of cell 0",
        "cell 1 draws on 'fig' of cell 0",
    ]
