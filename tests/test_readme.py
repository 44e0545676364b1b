"""The README's Python examples run as written, in an empty directory: they
name bundled models and scenes by bare file names. (.ci/readme-from-empty-dir
runs them, and the README's commands, against an installed wheel.)"""

from __future__ import annotations

import re
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]


def test_readme_python_examples_run(capsys, tmp_path, monkeypatch):
    text = (REPO_ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)       # nothing of the checkout in the current directory
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "1002 2000 True" in out


def _extras_table(text: str) -> dict[str, list[str]]:
    """The README's extras table: extra -> the packages it says it brings."""
    block = text.split("| extra | brings | for |", 1)[1].split("\n\n", 1)[0]
    rows = [line.split("|")[1:3] for line in block.strip().splitlines()[1:]]
    return {name.strip().strip("`"): [p.strip() for p in brings.split(",")]
            for name, brings in rows}


def test_readme_extras_table_is_pyprojects():
    """Every extra of pyproject.toml is in the README's table with exactly
    its packages (``all``: every other extra), and nothing else is."""
    import tomllib

    extras = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())[
        "project"]["optional-dependencies"]
    table = _extras_table((REPO_ROOT / "README.md").read_text())
    assert set(table) == set(extras)
    for name, requirements in extras.items():
        if name == "all":
            assert table[name] == ["all of the above"]
            (union,) = requirements
            assert set(re.findall(r"\[(.*)\]", union)[0].split(",")) == set(extras) - {"all"}
            continue
        packages = [re.split(r"[<>=!~\[ ]", r, maxsplit=1)[0] for r in requirements]
        assert table[name] == packages, name
