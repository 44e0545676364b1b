"""Build the accuracy report: ``reports/out/index.html`` and ``results.json``.

The page is self-contained: inline CSS, charts as inline SVG, no scripts
fetched, no network. Each area contributes a section from
``refsim.report.sections.<area>``; an area whose section module does not exist
yet is shown as a plain "not measured yet" section. The claims table collects
the verdicts the sections return; a claim without one says so.

Every measurement is made through the plan (:mod:`refsim.report.plan`),
which also chooses the oracle engines; a section asks it for records and
verdicts and arranges them. results.json lists the paths of its timings
(``timing_paths``: lists of keys, ``"*"`` for every item of a list), the
only values that may differ between two runs besides the items marked
``"timing": true``.

Both files are rendered in memory first and then written atomically
(:mod:`refsim.storage.writing`), so a failed run never leaves a half-written page.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import os
import platform
import subprocess
from dataclasses import asdict, dataclass
from importlib import metadata
from pathlib import Path

from refsim.bundled import templates_dir
from refsim.claims import CLAIMS, TERMINOLOGY
from refsim.report.plan import PARALLEL_ENTRIES, SWEEP_ENTRIES
from refsim.report.progress import Progress
from refsim.report.run import REPORT_SEED, Run
from refsim.report.section import Section, to_json
from refsim.storage.writing import write_text_atomic

# (key, title, what the section will measure once its work lands)
AREAS: tuple[tuple[str, str, str], ...] = (
    ("models", "Models", ""),
    ("bounds", "Bounding boxes and the world cube",
     "Linear against incremental AABB update (S2) against trimesh's bounds, cost "
     "against mesh size (C1), the incremental box on non-convex meshes (C2), and the "
     "world cube test (S3)."),
    ("collision", "Body-body collision",
     "The four levels of accuracy (S4) against python-fcl and trimesh: false positives "
     "and time per level (C3), near-parallel triangles (C4), and the hierarchy's speed "
     "against FCL."),
    ("solvers", "ODE solvers and the particle system",
     "Observed orders against scipy's DOP853 (C10), stability regions and limits, "
     "work-precision with scipy's adaptive methods, jitter in resting contact (C6, C7), "
     "drag models (C5), the particle system (C8, C9)."),
    ("dynamics", "Rigid-body dynamics",
     "Wall bounces against pybullet and the analytic answer, the seed's rotation model "
     "against the corrected one (C12), body-body interpenetration (C11)."),
    ("conformance", "Engines side by side: the conformance kit",
     "The shipped engines (refsim's seed and corrected models, python-fcl, coal, "
     "trimesh, pybullet, MuJoCo, Drake with point and with hydroelastic contact) through "
     "the same checks against exact answers."),
    ("textbook", "Textbook mechanics",
     "Problems with closed-form answers (drops, oblique impacts with friction, a spin "
     "stopped by friction, torque-free rotation, an off-centre strike, resting stacks) "
     "on every rigid-body engine, and refsim's error as the step shrinks."),
    ("advisor", "Model no more than a scene needs: the fidelity advisor",
     "The cheapest solver, step, collision level and box update within TOL of a reference "
     "run, for each bundled scene, and how the answer moves with TOL."),
)

# The page's cross-cutting parts: figures and tables (by id prefix) that are
# shown together there rather than in their area's section (speed against
# accuracy as charts; stability, predicted and measured).
PARTS: tuple[tuple[str, str, str, tuple[str, ...]], ...] = (
    ("speed-accuracy", "Speed against accuracy",
     "What each method buys for its cost, measured on this machine: error or false "
     "positives against time or work. Timings are medians of repeated runs on a shared "
     "two-core machine; read ratios, not absolute values.",
     ("solvers-wp-", "collision-levels-tradeoff", "collision-speed", "bounds-cost-",
      "dynamics-error-cost", "dynamics-step-cost", "advisor-tolerance")),
    ("stability", "Stability: where each method fails",
     "Predicted limits (from the amplification factor R(z) of each solver, from exact "
     "predicates for the triangle test) next to what the simulations and the oracles "
     "measure.",
     ("solvers-stability", "solvers-energy", "solvers-jitter", "collision-c4")),
)

#: Verdicts that make a claim an entry of the divergence catalogue; the seed's
#: own "Existing Problems" (C11, C12) are listed when confirmed.
DIVERGENT_VERDICTS = ("refuted", "partly")
SEED_ISSUES = ("C11", "C12")

PACKAGES = ("numpy", "scipy", "trimesh", "python-fcl", "pybullet", "matplotlib", "jinja2",
            "numba", "hypothesis")


@dataclass(frozen=True)
class ReportContext:
    quick: bool
    seed: int
    progress: Progress
    run: Run            # the plan's run: every section's records and verdicts


def build_report(out_dir: Path, *, quick: bool = False, stream=None,
                 workers: int | None = None) -> Path:
    """Measure, render and write the report; return the path of index.html.

    ``workers``: run the plan's sweep entries (the conformance matrix, the
    replays, the advisor: :data:`refsim.report.plan.SWEEP_ENTRIES`) and its
    untimed studies (:data:`~refsim.report.plan.PARALLEL_ENTRIES`) on this
    many local processes, started at once; the timed studies run here after
    them (:meth:`Run.prefetch`). The results are the same as without
    workers, timings aside. The engines' conformance pages and the replays
    are written into ``out_dir`` beside the page, each whole."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)  # fail before the long work, not after
    sections: list[Section] = []
    with Progress(len(AREAS) + 1, stream=stream) as progress:
        run = Run(quick=quick, seed=REPORT_SEED, announce=progress.announce, out_dir=out_dir,
                  workers=workers)
        run.prefetch(PARALLEL_ENTRIES + SWEEP_ENTRIES)   # with workers: on them, at once
        ctx = ReportContext(quick=quick, seed=REPORT_SEED, progress=progress, run=run)
        try:
            for key, title, pending in AREAS:
                progress.announce(title)
                sections.append(_build_section(key, title, pending, ctx))
                progress.step(title)
        except BaseException:
            run.cancel()            # Ctrl-C, SIGTERM or an error: stop the workers now
            raise
        environment = collect_environment()
        html = render(sections, environment, quick=quick)
        timings: set[tuple] = set()
        results = {
            "quick": quick,
            "seed": REPORT_SEED,
            "environment": environment,
            "claims": claim_rows(sections),
            "agreements": agreement_rows(sections),
            "divergences": divergence_rows(sections),
            "sections": {s.key: section_json(s, timings) for s in sections},
        }
        results["timing_paths"] = [list(p) for p in sorted(timings)]
        payload = json.dumps(results, indent=2, sort_keys=True, allow_nan=False)
        write_text_atomic(out_dir / "results.json", payload + "\n")
        write_text_atomic(out_dir / "index.html", html)
        progress.step("written")
    return out_dir / "index.html"


def _build_section(key: str, title: str, pending: str, ctx: ReportContext) -> Section:
    module_name = f"refsim.report.sections.{key}"
    if importlib.util.find_spec(module_name) is None:
        return Section(key=key, title=title, status="pending",
                       pending=f"Not measured yet. This section will show: {pending}")
    return importlib.import_module(module_name).build(ctx)


def claim_rows(sections: list[Section]) -> list[dict]:
    """One row per claim C1..C12: the seed's words, the measurement, the verdict."""
    verdicts = {v.claim: v for s in sections for v in s.verdicts}
    rows = []
    for claim, (area, text) in CLAIMS.items():
        v = verdicts.get(claim)
        rows.append({
            "claim": claim, "area": area, "text": text,
            "summary": v.summary if v else "",
            "measured": v.measured if v else "",
            "verdict": v.verdict if v else "not measured yet",
            "evidence": v.evidence if v else "",
            "command": v.command if v else "",
            "timing": v.timing if v else False,
            "replays": [r.id for s in sections for r in s.replays if r.claim == claim],
        })
    return rows


def part_of(item_id: str) -> str:
    """The cross-cutting part an item is shown in, or "" for its own section."""
    for key, _, _, prefixes in PARTS:
        if any(item_id.startswith(prefix) for prefix in prefixes):
            return key
    return ""


def divergence_rows(sections: list[Section]) -> list[dict]:
    """The divergence catalogue: the seed's claims that refsim does not
    confirm, the seed's own listed issues, and every class of oracle
    disagreement the sections measured."""
    rows = []
    for claim in claim_rows(sections):
        seed_issue = claim["claim"] in SEED_ISSUES and claim["verdict"] == "confirmed"
        if claim["verdict"] in DIVERGENT_VERDICTS or seed_issue:
            rows.append({"section": claim["area"], "title": f"{claim['claim']}: {claim['text']}",
                         "kind": ("a problem the seed lists itself, confirmed" if seed_issue
                                  else f"seed claim {claim['verdict']}"),
                         "finding": claim["summary"] or claim["measured"],
                         "details": claim["measured"] if claim["summary"] else "",
                         "evidence": claim["evidence"],
                         "timing": claim["timing"]})
    for s in sections:
        rows += [{"section": s.key, "details": "", **asdict(d)} for d in s.divergences]
    return rows


def agreement_rows(sections: list[Section]) -> list[dict]:
    """The summary at the top of the page: every section's oracle agreements."""
    return [{"section": s.key, **asdict(a)} for s in sections for a in s.agreements]


def section_json(section: Section, timings: set | None = None) -> dict:
    """A section as results.json records it: its measured numbers, and every
    table and chart exactly as the page shows them (cells as displayed).
    ``timings`` receives the paths of the timings among the numbers."""
    return {
        "status": section.status,
        "results": to_json(section.results, ("sections", section.key, "results"), timings),
        "tables": [{"id": t.id, "title": t.title, "columns": list(t.columns),
                    "rows": [[str(cell) for cell in row] for row in t.rows],
                    "column_links": list(t.column_links), "empty": t.empty,
                    "timing": t.timing, "part": part_of(t.id)}
                   for t in section.tables],
        "figures": [{"id": f.id, "title": f.title, "part": part_of(f.id)}
                    for f in section.figures],
        "replays": [{"id": r.id, "title": r.title, "file": r.file, "claim": r.claim,
                     "missing": r.missing} for r in section.replays],
    }


def collect_environment() -> dict:
    versions = {"python": platform.python_version()}
    for package in PACKAGES:
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = "not installed"
    return {
        "versions": versions,
        "machine": {
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "cpus": os.cpu_count(),
        },
        "commit": _git_commit(),
        "seed": REPORT_SEED,
    }


#: The top of refsim's source tree when it runs from a git checkout (an
#: editable install); an installed wheel has no ``.git`` beside its package.
_SOURCE = Path(__file__).resolve().parents[2]


def _git_commit() -> str:
    if not (_SOURCE / ".git").exists():
        return "unknown (an installed refsim, not a git checkout)"
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=_SOURCE, text=True,
                                capture_output=True, check=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=_SOURCE, text=True, capture_output=True,
                               timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown (not a git checkout)"
    return commit + (" (with uncommitted changes)" if dirty else "")


def render(sections: list[Section], environment: dict, *, quick: bool) -> str:
    import jinja2

    env = jinja2.Environment(loader=jinja2.FileSystemLoader(templates_dir()),
                             autoescape=True, undefined=jinja2.StrictUndefined,
                             keep_trailing_newline=True)
    template = env.get_template("index.html.j2")
    css = (templates_dir() / "style.css").read_text()
    parts = [{"key": key, "title": title, "intro": intro,
              "groups": [(s, [t for t in s.tables if part_of(t.id) == key],
                          [f for f in s.figures if part_of(f.id) == key]) for s in sections]}
             for key, title, intro, _ in PARTS]
    replays = {r.id: r for s in sections for r in s.replays}
    return template.render(sections=sections, claims=claim_rows(sections), replays=replays,
                           agreements=agreement_rows(sections), parts=parts,
                           divergences=divergence_rows(sections), part_of=part_of,
                           part_titles={key: title for key, title, _, _ in PARTS},
                           terminology=TERMINOLOGY, environment=environment,
                           quick=quick, css=css)

