"""``refsim report``, ``refsim study``, ``refsim view`` and ``refsim replay``:
the commands that show what the report and the viewer show."""

from __future__ import annotations

import sys

from refsim.cli.common import add_max_steps, max_steps_option, output_directory, output_file
from refsim.errors import RefsimError


def report_command(args) -> int:
    from refsim.errors import check_count
    from refsim.report import require_report

    require_report()        # before any work: the charts import matplotlib when drawn
    from refsim.report.build import build_report

    out = output_directory(args.output, "report", "index.html, results.json and the pages "
                                                   "they link")
    workers = None if args.workers is None else check_count("--workers", args.workers, 1)
    try:
        page = build_report(out, quick=not args.full, workers=workers)
    except OSError as exc:
        raise RefsimError(f"{out}: cannot write the report: {exc.strerror or exc}") from exc
    print(f"wrote {page}")
    return 0


def view_command(args) -> int:
    from refsim.scenes.loader import load_scene
    from refsim.viewer.live import serve
    from refsim.viewer.server import check_port, require_viser

    require_viser()
    check_port(args.port)
    scene = load_scene(args.scene, max_steps=max_steps_option(args))
    serve(scene, host=args.host, port=args.port)   # until Ctrl-C
    return 0


def replay_command(args) -> int:
    from refsim.viewer.replay import load_runs, write_replay
    from refsim.viewer.server import require_viser

    output_file(args.output, (".html", ".htm"), "replay")
    require_viser()
    runs = load_runs(args.runs, scenes=args.scene or ())
    info = write_replay(runs, args.output, overlay=args.overlay, max_bytes=args.max_bytes,
                        boxes=args.boxes)
    print(info.summary())
    return 0


def study_command(args) -> int:
    """Run one entry of the report's plan and print its records, then the
    verdicts on the seed claims it backs (each with its facts)."""
    from refsim.errors import check_count
    from refsim.oracles import OracleUnavailable
    from refsim.report.plan import STUDIES
    from refsim.report.run import Run
    from refsim.report.text import TIMING_NOTE, format_claim, format_records

    workers = None if args.workers is None else check_count("--workers", args.workers, 1)
    out = None
    if args.output is not None:
        from refsim.conformance.matrix import make_directory

        out = make_directory(output_directory(args.output, "study", "the pages of the "
                                                                     "studies that write them"))
    run = Run(quick=args.quick, seed=args.seed, out_dir=out, workers=workers,
              announce=lambda text: print(f"refsim: measuring {text}", file=sys.stderr))
    try:
        records = run.get(args.name)
    except OracleUnavailable as exc:
        raise RefsimError(f"study {args.name}: {exc}") from None
    print(format_records(records))
    for claim in STUDIES[args.name].claims:
        print()
        print(format_claim(run.claim(claim)))
    print()
    print(TIMING_NOTE)
    for engine, why in run.missing.items():
        print(f"refsim: note: {engine} is missing, its columns are empty: {why}",
              file=sys.stderr)
    return 0


def add_study_command(commands) -> None:
    """``refsim study NAME``: the command each figure of the report names."""
    from refsim.report.plan import STUDIES
    from refsim.report.run import REPORT_SEED

    study = commands.add_parser(
        "study", help="run one of the report's studies and print its records",
        description="Run the study NAME exactly as the report runs it (the same engines "
                    "and sizes; --quick as the quick report) and print its records as "
                    "plain-text tables, then the verdicts on the seed claims it backs. "
                    "Every figure of the report names the command that reproduces it.")
    study.add_argument("name", metavar="NAME", choices=sorted(STUDIES),
                       help="one of: " + ", ".join(sorted(STUDIES)))
    study.add_argument("--quick", action="store_true",
                       help="the quick report's sizes (fewer sizes and repeats)")
    study.add_argument("--seed", type=int, default=REPORT_SEED, metavar="S",
                       help=f"seed of the random choices (default {REPORT_SEED}, the report's)")
    study.add_argument("-o", "--output", metavar="DIR",
                       help="where studies that write pages put them (the conformance "
                            "pages, the replays); created if missing (default: none written)")
    study.add_argument("--workers", type=int, metavar="N",
                       help="run the studies that go through refsim.sweep (conformance-matrix, "
                            "replays, advisor) on N local processes")
    study.set_defaults(run=study_command)


def add_viewer_commands(commands) -> None:
    """``refsim view`` and ``refsim replay`` (refsim.viewer; the ``viewer`` extra)."""
    from refsim.viewer import REPLAY_MAX_BYTES as DEFAULT_MAX_BYTES

    view = commands.add_parser(
        "view", help="show a scene in the browser, with controls that re-run it",
        description="Serve SCENE in the browser (viser): the bodies in the world cube, "
                    "playback, the scene's options as controls that re-run the simulation, "
                    "boxes, contacts, wall hits and energy. Prints the address; Ctrl-C "
                    "stops. Needs the viewer extra: pip install 'refsim[viewer]'.")
    view.add_argument("scene", metavar="SCENE", help="a scene file (TOML)")
    view.add_argument("--port", type=int, default=8080, metavar="N",
                      help="port to serve on (default 8080; 0 for any free port)")
    view.add_argument("--host", default="127.0.0.1", metavar="ADDRESS",
                      help="address to bind (default 127.0.0.1, this machine only)")
    add_max_steps(view)
    view.set_defaults(run=view_command)

    replay = commands.add_parser(
        "replay", help="write recorded runs (.npz) as one standalone replay page",
        description="Write the runs (refsim run SCENE -o RUN.npz) side by side, or "
                    "overlaid, as one HTML file that plays offline (play/pause, scrub, "
                    "speed). Each run's meshes come from its scene file: --scene, or the "
                    "scene the run records. Needs the viewer extra.")
    replay.add_argument("runs", nargs="+", metavar="RUN.npz", help="recorded trajectories")
    replay.add_argument("-o", "--output", required=True, metavar="OUT.html",
                        help="the replay page to write, named .html")
    replay.add_argument("--scene", action="append", metavar="SCENE.toml",
                        help="the scene of the runs (once for all, or once per run in order)")
    replay.add_argument("--overlay", action="store_true",
                        help="draw the runs in one cube, each in its own colour "
                             "(default: side by side along x)")
    replay.add_argument("--max-bytes", type=int, default=DEFAULT_MAX_BYTES, metavar="N",
                        help="size budget of the page; frames are skipped to fit "
                             f"(default {DEFAULT_MAX_BYTES // 10**6} MB)")
    replay.add_argument("--boxes", action="store_true",
                        help="draw each body's box (AABB) too")
    replay.set_defaults(run=replay_command)
