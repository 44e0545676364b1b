"""The README's worked example of ``refsim conform``, run as a user runs it:
the module taken from the README itself, in the current directory, a fresh
interpreter; the table it prints is the README's table."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def _example() -> tuple[str, str]:
    """(myengine.py, the printed table) as the README shows them."""
    text = README.read_text()
    section = text.split("## Checking your own engine", 1)[1]
    module = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    printed = re.search(r"```\n\$ refsim conform myengine:make_engine -o out\n(.*?)```",
                        section, re.S).group(1)
    return module, printed


def _conform(directory: Path):
    return subprocess.run([sys.executable, "-m", "refsim.cli", "conform",
                           "myengine:make_engine", "-o", "out"],
                          cwd=directory, capture_output=True, text=True, timeout=300)


def test_the_readme_example_prints_the_readme_table(tmp_path):
    module, printed = _example()
    (tmp_path / "myengine.py").write_text(module)
    result = _conform(tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout == printed
    assert (tmp_path / "out" / "conformance.json").is_file()


def test_the_readme_example_declaring_order_3_fails_as_the_readme_says(tmp_path):
    module, _ = _example()
    (tmp_path / "myengine.py").write_text(module.replace("ode_order = 2", "ode_order = 3"))
    result = _conform(tmp_path)
    assert result.returncode == 1
    rows = {line.split()[0]: line.split()[1:] for line in result.stdout.splitlines()[2:7]}
    assert rows["ode.order"] == ["5", "0", "5", "bug", "5", "failed"]
    assert rows["ode.evaluations"] == ["5", "0", "5", "bug", "5", "failed"]
    assert rows["aabb.encloses"][-1] == "passed"
