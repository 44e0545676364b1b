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
