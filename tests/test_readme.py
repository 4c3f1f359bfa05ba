"""README and user guide: the quick start, the example and every snippet run.

"As written" means: from the repository root, after the quick start's
commands, in a fresh process whose home folder holds no data (so nothing
relies on ``~/sklearn_crbm_data``), with the data where the quick start's
``export`` says.  The one change is fewer training epochs (``n_iter``), so
that the suite stays fast.  The ``>>>`` examples of the guide run as doctests
in ``test_docs.py``; here the ``.. code-block:: python`` snippets run, each
page's in order after its doctests and snippets above it, as a reader who
types them one after the other would.
"""

import doctest
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import sklearn

REPO_ROOT = Path(__file__).resolve().parents[1]
README = REPO_ROOT / "README.md"
CI_RUN = REPO_ROOT / ".ci" / "run"
DOC_DIR = REPO_ROOT / "doc"
FEW_EPOCHS = 2

CODE_BLOCK = re.compile(
    r"^( *)\.\. code-block:: python\n((?:\1 +.*\n|[ \t]*\n)*)", re.M
)
GUIDE_PAGES = [
    DOC_DIR / "index.rst",
    DOC_DIR / "getting_started.rst",
    *sorted((DOC_DIR / "user_guide").glob("*.rst")),
]
SNIPPET_PAGES = [p for p in GUIDE_PAGES if CODE_BLOCK.search(p.read_text())]


def markdown_block(heading, language):
    text = README.read_text(encoding="utf-8")
    section = text.split(f"## {heading}\n", 1)[1].split("\n## ", 1)[0]
    return re.search(rf"```{language}\n(.*?)```", section, re.S).group(1)


def quick_start():
    """``(environment, commands)`` of README's quick start."""
    env, commands = {}, []
    for line in markdown_block("Quick start", "bash").splitlines():
        line = line.split("#", 1)[0].strip()
        if line.startswith("export "):
            name, value = line[len("export ") :].split("=", 1)
            env[name] = value.replace("$PWD", str(REPO_ROOT))
        elif line:
            commands.append(line)
    return env, commands


def fewer_epochs(code):
    return re.sub(r"\bn_iter=\d+", f"n_iter={FEW_EPOCHS}", code)


@pytest.fixture
def after_quick_start(tmp_path, monkeypatch):
    """The quick start's environment, and a home folder without data."""
    env, _ = quick_start()
    data = Path(env["SKLEARN_CRBM_DATA"])
    assert (data / "cmu_subject35").is_dir(), (
        f"README's quick start says the data is in {data}, but it is not there"
    )
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.chdir(REPO_ROOT)
    return dict(os.environ)


def test_quick_start_is_what_ci_runs():
    _, commands = quick_start()
    assert len(commands) == 2, "two commands: the demo, then the tests"
    demo, test = commands
    # both run in the virtual environment that the first makes, so that a
    # system Python refusing `pip install` outside one (PEP 668) runs them
    make_venv, *demo_steps = demo.split(" && ")
    assert make_venv.startswith("(python3 -m venv .venv ||")
    for step in [*demo_steps, *test.split(" && ")]:
        assert step.startswith(".venv/bin/python -m "), step
    assert test.endswith(".venv/bin/python -m pytest")
    assert "--upgrade" in test  # a reused environment gets what a new one gets
    # .ci/run runs exactly the README's test command, parsed from README
    printed = {
        which: subprocess.run(
            [sys.executable, str(CI_RUN.parent / "readme_command.py"), which],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        for which in ("venv", "test")
    }
    assert printed == {"venv": make_venv, "test": test}
    ci = CI_RUN.read_text()
    assert 'exec bash -c "$test"' in ci and 'bash -c "$venv"' in ci


def test_fill_in_claim_says_what_the_results_table_shows():
    """The introduction's claim about filling in matches the results below."""
    text = README.read_text(encoding="utf-8")
    intro = " ".join(text.split("## Quick start", 1)[0].split())
    claim = re.search(r"fills in [^.]*?\(", intro).group(0)
    results = text.split("## Results\n", 1)[1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| (.+?) \| .+? \| (.+?) \| .+? \|$", results, re.M)
    verdicts = dict(rows[1:])  # below the heading row
    assert verdicts.pop("all cells") == "better"
    assert "on average" in claim  # what the all-cells row shows
    if any(verdict != "better" for verdict in verdicts.values()):
        assert "not in every case" in claim
    else:
        assert "not in every case" not in claim


def _run(code, env):
    result = subprocess.run(
        [sys.executable, "-c", fewer_epochs(code)],
        env=env,
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    return result.stdout.splitlines()


def test_readme_example_runs_as_written(after_quick_start):
    code = markdown_block("Example", "python")
    assert code.count("n_iter=") == 1, "the README example changed: update this test"
    printed = dict(line.split() for line in _run(code, after_quick_start)[-3:])
    assert set(printed) == {"CRBMImputer", "KNNImputer", "AutoregressiveImputer"}
    assert all(float(error) > 0 for error in printed.values())


def test_readme_styles_snippet_runs_as_written(after_quick_start, tmp_path):
    code = markdown_block("Many styles in one model", "python")
    assert code.count("n_iter=") == 1, "the README snippet changed: update this test"
    env = dict(after_quick_start)
    # the snippet writes elderly.bvh where it runs: a scratch folder
    code = f"import os; os.chdir({str(tmp_path)!r})\n" + code
    (style,) = _run(code, env)[-1:]
    styles = {"active", "elderly", "exhausted", "feminine", "masculine", "normal"}
    assert style in styles | {"youthful"}
    assert (tmp_path / "elderly.bvh").stat().st_size > 0


def test_every_readme_snippet_is_tested():
    sections = README.read_text(encoding="utf-8").split("\n## ")[1:]
    with_python = [s.split("\n", 1)[0] for s in sections if "```python" in s]
    assert with_python == ["Example", "Many styles in one model"]


def page_code(page):
    """``(code, first line or None, raises)`` of the page's doctests and python
    snippets, in page order; ``raises``: the doctest shows an exception."""
    parts = []
    for piece in doctest.DocTestParser().parse(page.read_text(encoding="utf-8")):
        if isinstance(piece, str):
            for match in CODE_BLOCK.finditer(piece):
                snippet = textwrap.dedent(match.group(2))
                first_line = snippet.strip().splitlines()[0]
                parts.append((fewer_epochs(snippet), first_line, False))
        else:
            parts.append((piece.source, None, piece.exc_msg is not None))
    return parts


@pytest.mark.parametrize("page", SNIPPET_PAGES, ids=lambda p: p.stem)
def test_guide_snippets_run_as_written(
    page, after_quick_start, capsys, tmp_path, monkeypatch
):
    monkeypatch.chdir(tmp_path)  # what the snippets write lands here
    namespace = {}
    with sklearn.config_context():  # pages switch metadata routing on
        for code, first_line, raises in page_code(page):
            try:
                exec(compile(code, str(page), "exec"), namespace)
            except Exception as exc:
                if raises:
                    continue
                where = f"the snippet starting {first_line!r}" if first_line else code
                raise AssertionError(f"{page.name}: {where} fails") from exc
    import matplotlib.pyplot as plt

    plt.close("all")
