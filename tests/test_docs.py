"""The documentation builds without warnings, and its code runs.

``test_docs_build`` runs ``sphinx-build -W --keep-going -b html doc <tmp>``
(warnings are errors) without executing the gallery examples, as CI and a
contributor do after ``pip install -e ".[docs]"``, and checks the key pages.
``test_user_guide_code`` runs the ``>>>`` examples of the hand-written pages
(getting started, user guide) as doctests, so the guide cannot fall behind the
code.
"""

import doctest
import io
import os
import re
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


@pytest.fixture(scope="module")
def html_dir(tmp_path_factory):
    """Build the HTML documentation once; return the output folder."""
    out = tmp_path_factory.mktemp("docs") / "html"
    env = dict(os.environ)
    env["SKLEARN_CRBM_DOCS_RUN_EXAMPLES"] = "0"  # gallery shown, not executed
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
        str(out.parent / "doctrees"),
        str(DOC_DIR),
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
    return out


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
    ]:
        assert (html_dir / "user_guide" / f"{page}.html").is_file(), page

    rbm = (html_dir / "generated" / "sklearn_crbm.ConditionalRBM.html").read_text(
        encoding="utf-8"
    )
    for method in ["fit", "partial_fit", "transform", "score", "sample"]:
        assert f'id="sklearn_crbm.ConditionalRBM.{method}"' in rbm, method


def test_api_reference_covers_every_public_name(html_dir):
    """Every name in a public module's ``__all__`` has its page."""
    api = (DOC_DIR / "api.rst").read_text(encoding="utf-8")
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
def test_user_guide_code(page):
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
