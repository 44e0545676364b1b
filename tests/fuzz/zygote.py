"""A warmed refsim interpreter that forks one child per command line.

Why: a fresh ``refsim`` process spends 0.5 s importing numpy, scipy, trimesh
and numba and up to a second loading the compiled kernels before it reads its
input; a campaign of thousands of mutants would spend most of its time there.
This process pays that once (imports, then one short run of every bundled
scene and one ``refsim info`` per model format), then serves requests: for
each it forks a child that becomes the command line, ``refsim.cli.main(argv)``
with stdin from /dev/null, stdout and stderr to the given files, the given
working directory, address-space limit and CPU-time limit, and, for a permission case, without
root's file-permission override. The child does what the
console script does (``sys.exit(main())``); an exception that escapes is
printed as the interpreter would print it (``Traceback ...``, status 1).

What differs from a fresh process, and why it does not matter for the laws
checked here: modules are already imported and kernels already compiled
(a mutant cannot change either); the warning filters and the "already shown"
registries are reset to the state of a fresh interpreter before ``main``
runs, so a warning the warm-up saw is shown again. Failures found through
this server are confirmed in a fresh process (:class:`runner.ExecRunner`)
before they are reported.

Protocol (JSON lines): a request ``{"argv", "cwd", "stdout", "stderr",
"unprivileged", "memory", "cpu"}`` (``cpu``: ``RLIMIT_CPU``'s soft and hard
limits) on stdin; the replies ``{"pid": n}`` once the child runs
and ``{"status": s}`` (the raw ``waitpid`` status) when it ends.
"""

from __future__ import annotations

import faulthandler
import json
import os
import resource
import signal
import sys
import tempfile
import traceback
import warnings

from tests.fuzz.runner import die_with_parent, drop_file_capabilities, terminal_signals

#: The warning state of a fresh interpreter, saved before anything warns.
_FILTERS = list(warnings.filters)
_SHOWWARNING = warnings.showwarning


def warm_up() -> None:
    """Import what the command line imports and run each bundled scene and a
    model of each format once, so that the children start with everything
    compiled. Output goes to a temporary directory and is discarded."""
    import trimesh

    from refsim.bundled import bundled_models, bundled_scenes
    from refsim.cli import main
    from tests.fuzz.corpus import long_polygon_ac3d

    with tempfile.TemporaryDirectory(prefix="refsim-zygote-") as tmp:
        saved = os.dup(1), os.dup(2)
        sink = os.open(os.devnull, os.O_WRONLY)
        os.dup2(sink, 1)
        os.dup2(sink, 2)
        try:
            for scene in bundled_scenes():
                main(["run", str(scene), "-o", f"{tmp}/warm.npz", "--duration", "0.004"])
            main(["info", str(bundled_models()[0])])
            # a star polygon: the compiled ear clipper (long_polygon mutants)
            with open(f"{tmp}/star.ac", "wb") as star:
                star.write(long_polygon_ac3d(40, star=True))
            main(["info", f"{tmp}/star.ac"])
            mesh = trimesh.creation.icosahedron()
            for suffix in (".obj", ".stl", ".ply", ".off"):
                mesh.export(f"{tmp}/warm{suffix}")
                main(["info", f"{tmp}/warm{suffix}"])
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(sink)
    _reset_warnings()


def _reset_warnings() -> None:
    """The warning machinery as a fresh interpreter has it: the original
    filters and ``showwarning``, and no record of warnings already shown."""
    warnings.filters[:] = _FILTERS
    warnings.showwarning = _SHOWWARNING
    warnings._filters_mutated()  # invalidates every module's __warningregistry__
    for module in list(sys.modules.values()):
        registry = getattr(module, "__warningregistry__", None)
        if isinstance(registry, dict):
            registry.clear()


def _child(request: dict) -> None:
    """Become ``refsim ARGV`` and exit with its status (never returns)."""
    code = 1
    try:
        die_with_parent()                      # the server's death ends a hanging command
        terminal_signals()                     # not the campaign's (nohup, &)
        devnull = os.open(os.devnull, os.O_RDONLY)
        os.dup2(devnull, 0)
        out = os.open(request["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        err = os.open(request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(out, 1)
        os.dup2(err, 2)
        for fd in (devnull, out, err):
            os.close(fd)
        faulthandler.enable(sys.stderr, all_threads=True)
        faulthandler.register(signal.SIGUSR1, file=sys.stderr, all_threads=True)
        # at the CPU-time limit: the stack, then death by SIGXCPU (the runner's cpu_exceeded)
        faulthandler.register(signal.SIGXCPU, file=sys.stderr, all_threads=True, chain=True)
        os.chdir(request["cwd"])
        if request.get("unprivileged"):
            drop_file_capabilities()
        if request.get("memory"):
            resource.setrlimit(resource.RLIMIT_AS, (request["memory"], request["memory"]))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))   # a crash leaves no core file
        if request.get("cpu"):
            resource.setrlimit(resource.RLIMIT_CPU, tuple(request["cpu"]))
        _reset_warnings()
        from refsim.cli import main

        sys.argv = ["refsim", *request["argv"]]
        try:
            code = main(request["argv"])
        except SystemExit as exc:                 # argparse, or sys.exit inside
            code = exc.code
        if code is None:
            code = 0
        elif not isinstance(code, int):
            print(code, file=sys.stderr)
            code = 1
    except KeyboardInterrupt:
        traceback.print_exc()
        sys.stderr.flush()
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
    except BaseException:  # what the interpreter does with an uncaught exception
        traceback.print_exc()
        code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code & 0xFF if isinstance(code, int) else 1)


def serve() -> None:
    """Answer requests on stdin until it closes."""
    for line in sys.stdin:
        request = json.loads(line)
        sys.stdout.flush()
        pid = os.fork()
        if pid == 0:
            _child(request)
        print(json.dumps({"pid": pid}), flush=True)
        _, status = os.waitpid(pid, 0)
        print(json.dumps({"status": status}), flush=True)


if __name__ == "__main__":
    die_with_parent()
    warm_up()
    print(json.dumps({"ready": os.getpid()}), flush=True)
    serve()
