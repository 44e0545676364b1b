"""The project's documents: what they cite exists in the repository.

Modules cite the design page by section (``docs/design.md, Errors``); a
reader must find that section, and no file may send a reader to a document
the repository does not hold.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "docs" / "design.md"


def tracked_text_files() -> list[Path]:
    names = subprocess.run(["git", "ls-files", "*.py", "*.md", "*.toml", "*.txt"], cwd=ROOT,
                           capture_output=True, text=True, check=True).stdout.split()
    return [ROOT / n for n in names if (ROOT / n).is_file()]


def test_no_file_cites_a_design_document_outside_the_repository():
    pattern = re.compile(r"(?<![/\w])DESIGN\.md")
    citing = [str(p.relative_to(ROOT)) for p in tracked_text_files()
              if pattern.search(p.read_text(encoding="utf-8", errors="replace"))]
    assert citing == []


def test_every_cited_section_of_the_design_page_exists():
    headings = {line.lstrip("#").strip() for line in DESIGN.read_text().splitlines()
                if line.startswith("## ")}
    cited = set()
    for path in tracked_text_files():
        text = " ".join(path.read_text(encoding="utf-8", errors="replace").split())
        text = text.replace("# ", " ").replace("#: ", " ")
        cited |= {(m.group(1), str(path.relative_to(ROOT))) for m in
                  re.finditer(r"docs/design\.md(?:'s|,|:)? ([A-Z][a-z]+(?: [A-Z][a-z]+)?)", text)}
    missing = sorted((section, where) for section, where in cited
                     if not any(h.startswith(section) or section.startswith(h)
                                for h in headings))
    assert missing == []
    assert {"Architecture", "Errors", "Conventions", "Public API", "Scene files",
            "Speed"} <= headings


def test_the_design_pages_key_table_is_each_engines_honoured_keys():
    """docs/design.md, "Which engines pose which keys": every cell is the
    engine's ``honoured_keys`` ("yes" when it holds the key)."""
    import importlib

    from refsim.engines.refsim_engines import corrected, seed
    from refsim.scenes.support import LOAD_KEYS

    oracles = {}
    for title, module, cls in (("pybullet", "refsim.oracles.pybullet_adapter", "PybulletOracle"),
                               ("MuJoCo", "refsim.oracles.mujoco_adapter", "MujocoOracle"),
                               ("Drake", "refsim.oracles.drake_adapter", "DrakeEngine")):
        oracles[title] = getattr(importlib.import_module(module), cls).honoured_keys
    engines = {"refsim corrected": corrected().honoured_keys,
               "refsim seed": seed().honoured_keys, **oracles}
    text = DESIGN.read_text()
    table = text[text.index("<!-- honoured-keys -->"):text.index("<!-- /honoured-keys -->")]
    rows = [[c.strip() for c in line.strip("|").split("|")]
            for line in table.splitlines() if line.startswith("|")]
    header, body = rows[0], rows[2:]
    assert header[1:] == list(engines)
    assert [r[0].strip("`") for r in body] == list(LOAD_KEYS)
    for row in body:
        key = row[0].strip("`")
        for title, cell in zip(header[1:], row[1:], strict=True):
            assert cell.split()[0] == ("yes" if key in engines[title] else "no"), (key, title)
