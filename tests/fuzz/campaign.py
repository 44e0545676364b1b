"""The fuzz campaign: mutants and API probes for N minutes, a table, the failures.

    python -m tests.fuzz.campaign --minutes 10 --seed 1 --out fuzz-out
    python -m tests.fuzz.campaign --cases 2000 --probes 300 --seed 1 --out fuzz-out
    python -m tests.fuzz.campaign --replay scene:set_key:1:42 --out fuzz-out

Run it from the repository root (``tests`` is a namespace package found from
the working directory). Phases:

1. mutants: the signal cases alone, then every other fixed case (special
   files, ``-o`` targets, arguments, the manual campaign's findings), then
   random cases in the order of
   :func:`tests.fuzz.cases.schedule`, on ``--workers`` fork servers (one
   thread each), until ``(1 - api_share)`` of the time or ``--cases``;
2. API probes: the manual campaign's findings
   (``tests.fuzz.api_worker.KNOWN_PROBES``), then for each public function
   in turn, Hypothesis (profile
   ``fuzz``, seeded from ``--seed``, the round and the function) draws
   probes from ``properties/fuzz/strategies.py``; distinct probes run in one
   worker until the time or ``--probes`` is used up;
3. confirmation: the first case of each distinct failure is run again in a
   fresh ``refsim`` process (ExecRunner), the first probe in a fresh worker;
   the table of distinct failures says whether each was seen again.

Output in ``--out``: ``results.json`` (the table, the distinct failures with
their counts and reproducers, every failure), ``table.txt``, and
``repro/<case>/`` (the mutant files and ``repro.sh``) for the first
:data:`REPRODUCERS_PER_SIGNATURE` cases of each distinct failure. The same
seed and the same counts (``--cases``, ``--probes``, one worker) give the same
cases and probes; a time-bounded run stops at a point that depends on the
machine.
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import sys
import tempfile
import threading
import time
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

from tests.fuzz.api_worker import KNOWN_PROBES, Probe, ProbeOutcome, ProbeRunner, judge_probe
from tests.fuzz.cases import Case, case_from_id, fixed_cases, make_case, schedule
from tests.fuzz.execute import Record, execute
from tests.fuzz.judge import COLUMNS, Failure, Verdict, judge
from tests.fuzz.reproduce import write_reproducer
from tests.fuzz.runner import ExecRunner, ForkServer

#: Reproducer directories kept per distinct failure (every failure can be
#: rebuilt from its id with --replay; these are the ones written out).
REPRODUCERS_PER_SIGNATURE = 3

#: Seconds of CPU time a probe may use in the campaign before it counts as
#: over its CPU limit (its wall-clock backstop: runner.WALL_FACTOR times that).
CAMPAIGN_PROBE_CPU_LIMIT = 6.0

#: Runs of a signal case whose command ended before its signal arrived
#: (a loaded machine can delay the poll that sends it) before it counts as
#: inconclusive.
SIGNAL_TRIES = 3

#: Probes Hypothesis draws per function per round (rounds repeat until the
#: time or the probe count is used up).
PROBES_PER_ROUND = 10


@dataclass(frozen=True)
class CaseResult:
    case: Case
    record: Record
    verdict: Verdict


@dataclass(frozen=True)
class ProbeResult:
    probe: Probe
    outcome: ProbeOutcome
    failures: tuple[Failure, ...]

    @property
    def accepted(self) -> bool:
        return self.outcome.facts.get("status") == "ok"

    @property
    def refused_ok(self) -> bool:
        return self.outcome.facts.get("status") == "raised" and not self.failures


# -- phase 1: mutants ----------------------------------------------------------------------


def case_stream(seed, fixed: bool = True):
    """Every fixed case, then the random cases of ``seed`` forever."""
    if fixed:
        yield from fixed_cases()
    for index, (family, mutator) in enumerate(schedule(seed)):
        yield make_case(family, mutator, seed, index)


def run_mutants(seed, deadline: float, max_cases: int | None, workers: int,
                workdir: Path, logs: Path, progress=None) -> list[CaseResult]:
    """Run cases from :func:`case_stream` on ``workers`` fork servers until
    ``deadline`` (monotonic seconds) or ``max_cases``; results in case order.
    The servers' own stderr goes to ``logs``.

    The signal cases run first, one at a time: their signal must arrive while
    the output is being written, and a poll starved by a busy second thread
    can see the temporary file too late.
    """
    lock = threading.Lock()
    results: dict[int, CaseResult] = {}
    busy = [0]                                         # cases handed out, not yet done
    servers = [ForkServer(log=logs / f"zygote-{n}.log") for n in range(workers)]
    stream = ((i, c) for i, c in enumerate(case_stream(seed)) if c.family != "signal")
    for index, case in enumerate(fixed_cases()):
        if case.family == "signal" and (max_cases is None or len(results) < max_cases):
            for _ in range(SIGNAL_TRIES):
                record = execute(case, servers[0], workdir)
                results[index] = CaseResult(case, record, judge(case, record))
                if not results[index].verdict.inconclusive:
                    break

    def next_case():
        with lock:
            if time.monotonic() >= deadline:
                return None
            if max_cases is not None and len(results) + busy[0] >= max_cases:
                return None
            busy[0] += 1
            return next(stream)

    def work(server):
        try:
            while (item := next_case()) is not None:
                index, case = item
                record = execute(case, server, workdir)
                result = CaseResult(case, record, judge(case, record))
                with lock:
                    results[index] = result
                    busy[0] -= 1
                    if progress and len(results) % 100 == 0:
                        progress(f"{len(results)} cases")
        finally:
            server.close()

    threads = [threading.Thread(target=work, args=(server,), daemon=True)
               for server in servers]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return [results[i] for i in sorted(results)]


# -- phase 2: API probes -------------------------------------------------------------------


def run_probes(seed, deadline: float, max_probes: int | None, logs: Path,
               progress=None) -> list[ProbeResult]:
    """Distinct Hypothesis-drawn probes of every public function, round after
    round, until ``deadline`` or ``max_probes`` (module docstring)."""
    from hypothesis import given, settings
    from hypothesis import seed as hypothesis_seed

    import properties.conftest  # noqa: F401  (registers the "fuzz" profile)
    from properties.fuzz.strategies import API_FUNCTIONS, api_probes

    runner = ProbeRunner(cpu_limit=CAMPAIGN_PROBE_CPU_LIMIT, log=logs / "api-worker.log")
    results: list[ProbeResult] = []
    seen: set[str] = set()

    def done() -> bool:
        return time.monotonic() >= deadline or (max_probes is not None
                                                and len(results) >= max_probes)

    per_round = PROBES_PER_ROUND if max_probes is None else max(
        1, min(PROBES_PER_ROUND, -(-max_probes // len(API_FUNCTIONS))))   # a fair share each
    try:
        for probe in KNOWN_PROBES.values():              # the manual campaign's findings
            if not done():
                seen.add(probe.code)
                outcome = runner.run(probe)
                results.append(ProbeResult(probe, outcome, tuple(judge_probe(probe, outcome))))
        round_ = 0
        while not done():
            before = len(results)
            for function in API_FUNCTIONS:
                key = random.Random(f"api/{seed}/{function}/{round_}").getrandbits(64)

                @settings(settings.get_profile("fuzz"), max_examples=per_round)
                @hypothesis_seed(key)
                @given(probe=api_probes(function))
                def explore(probe):
                    if done() or probe.code in seen:
                        return
                    seen.add(probe.code)
                    outcome = runner.run(probe)
                    results.append(ProbeResult(probe, outcome,
                                               tuple(judge_probe(probe, outcome))))

                explore()
            round_ += 1
            if progress:
                progress(f"{len(results)} probes (round {round_})")
            if len(results) == before:          # every strategy exhausted
                break
    finally:
        runner.close()
    return results


# -- phase 3: confirmation -------------------------------------------------------------------


def first_by_signature(case_results, probe_results) -> dict[str, object]:
    firsts: dict[str, object] = {}
    for result in case_results:
        for failure in result.verdict.failures:
            firsts.setdefault(failure.signature, result)
    for result in probe_results:
        for failure in result.failures:
            firsts.setdefault(failure.signature, result)
    return firsts


def confirm(firsts: dict, workdir: Path, logs: Path, progress=None) -> dict[str, bool]:
    """Whether the first case (fresh ``refsim`` process) or probe (fresh
    worker) of each signature shows the same signature again."""
    confirmed = {}
    exec_runner = ExecRunner()
    for n, (signature, result) in enumerate(sorted(firsts.items())):
        if isinstance(result, CaseResult):
            record = execute(result.case, exec_runner, workdir)
            found = {f.signature for f in judge(result.case, record).failures}
        else:
            runner = ProbeRunner(cpu_limit=CAMPAIGN_PROBE_CPU_LIMIT,
                                 log=logs / "api-confirm.log")
            try:
                outcome = runner.run(result.probe)
            finally:
                runner.close()
            found = {f.signature for f in judge_probe(result.probe, outcome)}
        confirmed[signature] = signature in found
        if progress and n % 10 == 9:
            progress(f"confirmed {n + 1} of {len(firsts)}")
    return confirmed


# -- the table -----------------------------------------------------------------------------

HEADER = ("cases", "accepted", "refused ok", "tracebacks", "signals", "hangs",
          "cpu overruns", "bad messages", "files left", "files replaced", "bad output")


def row_label(case: Case) -> tuple[str, str]:
    """(group, row) of a case in the table."""
    if case.family in ("model", "scene", "scene+model"):
        return case.family, case.mutator
    if case.family == "special":
        return "special", case.mutator.split("-", 1)[0] + " path"
    return case.family, {"output": "-o targets", "signal": "during the write",
                         "args": "command line", "known": case.mutator}[case.family]


def tabulate(case_results, probe_results) -> list[dict]:
    """The rows of the table: one per (group, row), counts per column."""
    rows: dict[tuple[str, str], Counter] = defaultdict(Counter)
    for result in case_results:
        counts = rows[row_label(result.case)]
        counts["cases"] += 1
        counts["accepted"] += result.verdict.accepted
        counts["refused ok"] += result.verdict.refused_ok
        counts["inconclusive"] += result.verdict.inconclusive
        for column in result.verdict.columns():
            counts[column] += 1
    for result in probe_results:
        counts = rows[("api", result.probe.function)]
        counts["cases"] += 1
        counts["accepted"] += result.accepted
        counts["refused ok"] += result.refused_ok
        for column in {f.column for f in result.failures}:
            counts[column] += 1
    order = {"model": 0, "scene": 1, "scene+model": 2, "special": 3, "output": 4,
             "signal": 5, "args": 6, "known": 7, "api": 8}
    names = {c: h for c, h in zip(("cases", "accepted", "refused ok") + COLUMNS, HEADER,
                                  strict=True)}
    names["inconclusive"] = "inconclusive"
    return [{"group": group, "row": row, **{names[k]: counts[k] for k in names}}
            for (group, row), counts in sorted(rows.items(), key=lambda kv: (
                order[kv[0][0]], kv[0][1]))]


def format_table(rows: list[dict]) -> str:
    """The rows as text, with a subtotal per group and a total."""
    width = max(len(f"{r['group']} / {r['row']}") for r in rows) if rows else 10
    head = f"{'input':<{width}}  " + "  ".join(f"{h:>{max(len(h), 5)}}" for h in HEADER)
    lines = [head, "-" * len(head)]

    def line(label, counts):
        return f"{label:<{width}}  " + "  ".join(f"{counts[h]:>{max(len(h), 5)}}"
                                                 for h in HEADER)

    total = Counter()
    for group in dict.fromkeys(r["group"] for r in rows):
        members = [r for r in rows if r["group"] == group]
        subtotal = Counter()
        for r in members:
            lines.append(line(f"{group} / {r['row']}", r))
            subtotal.update({h: r[h] for h in HEADER})
        lines.append(line(f"{group} (all)", subtotal))
        lines.append("")
        total.update(subtotal)
    lines.append(line("total", total))
    inconclusive = sum(r.get("inconclusive", 0) for r in rows)
    if inconclusive:
        lines.append(f"({inconclusive} signal case(s) inconclusive: the command ended before "
                     "its signal was sent)")
    return "\n".join(lines)


# -- output ---------------------------------------------------------------------------------


def _case_failure(result: CaseResult, failure: Failure, reproducer) -> dict:
    o = result.record.outcome
    return {"kind": "case", "id": result.case.id, "family": result.case.family,
            "mutator": result.case.mutator, "subject": result.case.subject,
            "column": failure.column, "signature": failure.signature,
            "detail": failure.detail, "exit": o.returncode, "timed_out": o.timed_out,
            "cpu_exceeded": o.cpu_exceeded,
            "seconds": round(o.elapsed, 3), "stderr_tail": o.stderr[-600:],
            "replay": f"python -m tests.fuzz.campaign --replay {result.case.id}",
            "reproducer": reproducer}


def _probe_failure(result: ProbeResult, failure: Failure) -> dict:
    return {"kind": "probe", "function": result.probe.function, "code": result.probe.code,
            "column": failure.column, "signature": failure.signature,
            "detail": failure.detail, "seconds": round(result.outcome.seconds, 3),
            "reproducer": result.probe.reproducer()}


def write_outputs(out: Path, args, case_results, probe_results, confirmed, seconds) -> dict:
    """results.json, table.txt and the reproducer directories; the JSON as a dict."""
    out.mkdir(parents=True, exist_ok=True)
    rows = tabulate(case_results, probe_results)
    kept: Counter = Counter()
    failures = []
    for result in case_results:
        for failure in result.verdict.failures:
            reproducer = None
            if kept[failure.signature] < REPRODUCERS_PER_SIGNATURE:
                kept[failure.signature] += 1
                safe = result.case.id.replace(":", "_").replace("/", "_")
                reproducer = str(write_reproducer(result.case, out / "repro" / safe,
                                                  failure.signature))
            failures.append(_case_failure(result, failure, reproducer))
    for result in probe_results:
        failures.extend(_probe_failure(result, failure) for failure in result.failures)
    distinct = {}
    for entry in failures:
        d = distinct.setdefault(entry["signature"], {
            "signature": entry["signature"], "column": entry["column"], "count": 0,
            "where": Counter(), "first": entry,
            "confirmed_in_fresh_process": confirmed.get(entry["signature"])})
        d["count"] += 1
        d["where"][entry.get("family", "api") + " / " + entry.get("mutator",
                                                                   entry.get("function", ""))] += 1
    inconclusive = [{"id": r.case.id, "exit": r.record.outcome.returncode,
                     "signal_sent": r.record.outcome.interrupted,
                     "seconds": round(r.record.outcome.elapsed, 3)}
                    for r in case_results if r.verdict.inconclusive]
    summary = {
        "seed": args.seed, "minutes": args.minutes, "cases_limit": args.cases,
        "probes_limit": args.probes, "workers": args.workers, "seconds": round(seconds, 1),
        "cases": len(case_results), "probes": len(probe_results), "table": rows,
        "distinct": sorted(({**d, "where": dict(d["where"])} for d in distinct.values()),
                           key=lambda d: (COLUMNS.index(d["column"]), -d["count"])),
        "failures": failures,
        "inconclusive": inconclusive,
    }
    (out / "results.json").write_text(json.dumps(summary, indent=1, default=str))
    (out / "table.txt").write_text(format_table(rows) + "\n")
    return summary


def format_distinct(summary: dict) -> str:
    lines = []
    for d in summary["distinct"]:
        seen = {True: "confirmed", False: "NOT seen again", None: "-"}[
            d["confirmed_in_fresh_process"]]
        first = d["first"]
        repro = first.get("reproducer") or first.get("replay")
        lines.append(f"[{d['column']}] x{d['count']} ({seen}) {d['signature']}\n"
                     f"    e.g. {first.get('id') or first.get('code', '')[:160]}\n"
                     f"    reproduce: {repro}")
    return "\n".join(lines)


# -- replay -----------------------------------------------------------------------------------


def replay(case_id: str, out: Path) -> int:
    """Rebuild ``case_id``, write its reproducer, run it in a fresh process, report."""
    case = case_from_id(case_id)
    script = write_reproducer(case, out / "repro" / case_id.replace(":", "_"))
    with tempfile.TemporaryDirectory(prefix="refsim-replay-") as tmp:
        record = execute(case, ExecRunner(), Path(tmp))
    verdict = judge(case, record)
    o = record.outcome
    print(f"case {case.id}: {case.family} {case.mutator} on {case.subject}")
    print(f"command: refsim {' '.join(case.argv)}")
    limit = " (timed out)" if o.timed_out else " (over its CPU limit)" if o.cpu_exceeded else ""
    print(f"exit {o.returncode}{limit} after {o.elapsed:.2f} s")
    print("stderr:\n" + (o.stderr.rstrip() or "(empty)"))
    for failure in verdict.failures:
        print(f"FAILURE [{failure.column}] {failure.signature}\n    {failure.detail}")
    if not verdict.failures:
        print("no failure")
    print(f"reproducer: sh {script}")
    return 0


# -- main ---------------------------------------------------------------------------------------


def parse_args(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz.campaign",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0,
                        help="time budget of the mutant and API phases (default 10)")
    parser.add_argument("--seed", default="1", help="campaign seed (default 1)")
    parser.add_argument("--out", default="fuzz-out", help="output directory (default fuzz-out)")
    parser.add_argument("--cases", type=int, help="stop the mutant phase after this many cases")
    parser.add_argument("--probes", type=int, help="stop the API phase after this many probes")
    parser.add_argument("--workers", type=int, default=2,
                        help="fork servers running cases at once (default 2; the machine "
                             "is shared)")
    parser.add_argument("--api-share", type=float, default=0.2,
                        help="share of the time for API probes (default 0.2)")
    parser.add_argument("--no-confirm", action="store_true",
                        help="skip re-running each distinct failure in a fresh process")
    parser.add_argument("--replay", metavar="CASE_ID",
                        help="rebuild one case, write its reproducer, run it and report")
    return parser.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    out = Path(args.out)
    if args.replay:
        return replay(args.replay, out)

    def progress(message):
        print(f"[{time.monotonic() - start:7.1f} s] {message}", file=sys.stderr, flush=True)

    start = time.monotonic()
    budget = args.minutes * 60.0
    logs = out / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    workdir = Path(tempfile.mkdtemp(prefix="refsim-fuzz-"))
    try:
        progress(f"mutants (cases run in {workdir})")
        case_results = run_mutants(args.seed, start + budget * (1.0 - args.api_share),
                                   args.cases, args.workers, workdir, logs, progress)
        progress(f"{len(case_results)} cases; API probes")
        probe_results = run_probes(args.seed, start + budget, args.probes, logs, progress)
        progress(f"{len(probe_results)} probes")
        confirmed = {}
        if not args.no_confirm:
            firsts = first_by_signature(case_results, probe_results)
            progress(f"confirming {len(firsts)} distinct failures in fresh processes")
            confirmed = confirm(firsts, workdir, logs, progress)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    summary = write_outputs(out, args, case_results, probe_results, confirmed,
                            time.monotonic() - start)
    print(format_table(summary["table"]))
    print()
    print(f"{len(summary['distinct'])} distinct failures "
          f"({len(summary['failures'])} in all), {summary['cases']} cases, "
          f"{summary['probes']} probes, {summary['seconds']:.0f} s; see {out}/results.json")
    print(format_distinct(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
