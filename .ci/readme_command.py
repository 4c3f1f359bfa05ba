"""Print a command of README.md's Quick start, so that CI runs it as written.

    python .ci/readme_command.py export # the environment it sets (export lines)
    python .ci/readme_command.py demo   # the first command: install, run the demo
    python .ci/readme_command.py test   # the second command: install, run the tests
    python .ci/readme_command.py venv   # the first command's virtual environment step
"""

import re
import sys
from pathlib import Path


def quick_start(readme):
    """``(exports, commands)``: the lines of the Quick start's ``bash`` block."""
    section = readme.split("## Quick start", 1)[1]
    block = re.search(r"```bash\n(.*?)```", section, re.DOTALL).group(1)
    lines = [line for line in block.splitlines() if line and not line.startswith("#")]
    exports = [line for line in lines if line.startswith("export ")]
    return exports, [line for line in lines if not line.startswith("export ")]


def main(which):
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    exports, (demo, test) = quick_start(readme)
    commands = {
        "export": "\n".join(exports),
        "demo": demo,
        "test": test,
        "venv": demo.split(" && ")[0],
    }
    print(commands[which])


if __name__ == "__main__":
    main(sys.argv[1])
