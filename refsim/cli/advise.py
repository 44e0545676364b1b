"""``refsim advise``: the cheapest fidelity settings of a scene within a
tolerance."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

from refsim.cli.common import output_directory, with_duration


def advise_command(args) -> int:
    """``refsim advise``: the cheapest fidelity settings within TOL
    (:func:`refsim.advisor.advice.advise`), shown by :mod:`refsim.advisor.view`."""
    import math

    from refsim.advisor.advice import advise
    from refsim.advisor.view import advice_document, advice_text, svg_available, svg_chart
    from refsim.errors import StateError
    from refsim.scenes.loader import load_scene
    from refsim.storage.writing import output_error, write_text_atomic

    if not (math.isfinite(args.tolerance) and args.tolerance > 0.0):
        raise StateError(f"--tolerance must be a finite number of metres > 0, "
                         f"got {args.tolerance!r}")
    for flag, value in (("--workers", args.workers), ("--repeats", args.repeats),
                        ("--max-reference-steps", args.max_reference_steps)):
        if value is not None and value < 1:
            raise StateError(f"{flag} must be at least 1, got {value}")
    if args.workers is not None and args.scheduler is not None:
        raise StateError("give --workers (local processes) or --scheduler (a Dask "
                         "cluster), not both")
    out = (None if args.output is None
           else output_directory(args.output, "advise", "the advice as TOML and JSON, and "
                                                         "its chart"))
    if out is not None and out.exists() and not out.is_dir():
        raise output_error(out, "it is not a directory")
    if out is not None and not out.parent.is_dir():
        raise output_error(out, f"no directory {out.parent}")
    scene = load_scene(args.scene)
    if args.duration is not None:
        with_duration(scene, args.duration)        # refused here, with the flag's name
    stem = Path(args.scene).stem
    store = args.store
    if store is None and out is not None:
        store = out / f"{stem}-advise-store"
    backend = ("dask" if args.scheduler is not None
               else "processes" if args.workers is not None else "inprocess")
    options = {} if args.repeats is None else {"repeats": args.repeats}
    if args.max_reference_steps is not None:
        options["max_reference_steps"] = args.max_reference_steps
    if out is not None:
        out.mkdir(exist_ok=True)
    advice = advise(scene, args.tolerance, duration=args.duration, backend=backend,
                    workers=args.workers, scheduler=args.scheduler, store=store,
                    progress=not args.json, **options)
    chart_path = None
    if out is not None:
        if svg_available():
            chart_path = write_text_atomic(out / f"{stem}-work-precision.svg", svg_chart(advice))
        else:
            warnings.warn("the SVG chart needs matplotlib (pip install 'refsim[report]'); "
                          "writing it as text", stacklevel=1)
            from refsim.advisor.view import text_chart

            chart_path = write_text_atomic(out / f"{stem}-work-precision.txt",
                                           text_chart(advice) + "\n")
    document = advice_document(advice, None if chart_path is None else str(chart_path))
    text = json.dumps(document, indent=1, allow_nan=False)
    if out is not None:
        from refsim.advisor.view import toml_snippet

        write_text_atomic(out / f"{stem}-advice.json", text + "\n")
        write_text_atomic(out / f"{stem}-advice.toml", toml_snippet(advice))
    if args.json:
        print(text)
    else:
        shown = None if chart_path is None else f"work-precision chart: {chart_path}"
        print(advice_text(advice, shown), end="")
    return 0


def add_advise_command(commands) -> None:
    """``refsim advise`` (refsim.advisor; the chart needs the report extra)."""
    advise = commands.add_parser(
        "advise", help="the cheapest solver, step, collision level and box update within TOL",
        description="Hold SCENE's physics fixed and search its fidelity settings (solver, "
                    "step, collision level, box update) for the cheapest run that stays within "
                    "TOL of a reference run (rk4 at a fine step, level exact, linear boxes, "
                    "checked by halving its step). Prints the recommended [integration] and "
                    "[collision] keys, every run tried (cost: force evaluations x bodies + "
                    "narrow-phase calls, and median wall time; errors against the reference), "
                    "a work-precision chart, and the saving against the scene's own settings. "
                    "A reference that does not converge (a chaotic scene) is reported with the "
                    "horizon up to which positions are predictable.")
    advise.add_argument("scene", metavar="SCENE", help="a rigid-body scene file (TOML)")
    advise.add_argument("--tolerance", type=float, default=0.01, metavar="TOL",
                        help="metres (default 0.01): where the bodies' points are; an event "
                             "time counts by the distance it puts between two runs (|dt| x "
                             "the velocity change of the response); the end energy within "
                             "TOL / half_size of the scene's energy")
    advise.add_argument("--duration", type=float, metavar="SECONDS",
                        help="simulate this long instead of the scene's duration")
    advise.add_argument("--workers", type=int, metavar="N",
                        help="run the simulations on N local processes (default: in this one)")
    advise.add_argument("--scheduler", metavar="ADDRESS",
                        help="run them on a Dask cluster, e.g. tcp://host:8786 "
                             "(pip install 'refsim[sweep]')")
    advise.add_argument("--store", metavar="DIR",
                        help="keep each finished run here, so that an interrupted advise "
                             "resumes (default: DIR/SCENE-advise-store with -o, else none)")
    advise.add_argument("-o", "--output", metavar="DIR",
                        help="write SCENE-advice.toml, SCENE-advice.json and the chart "
                             "SCENE-work-precision.svg here (created if missing)")
    advise.add_argument("--json", action="store_true",
                        help="print one JSON document instead of the text")
    advise.add_argument("--repeats", type=int, metavar="N",
                        help="time each candidate run N times, report the median (default 3)")
    advise.add_argument("--max-reference-steps", type=int, metavar="N",
                        help="the most steps of one reference run (default 2^19)")
    advise.set_defaults(run=advise_command)
