"""What the commands share: the exit statuses, one-line messages, the
checks of an output file or directory before any work, and the options
every command that simulates a scene takes."""

from __future__ import annotations

from pathlib import Path

from refsim.errors import OutputError, RefsimError, SceneError

#: The exit statuses: a user's mistake (one line naming the file, line or
#: key), a run that diverged (its frames before the divergence written).
EXIT_USER_ERROR = 2
EXIT_DIVERGED = 3

#: The status of a command whose reader went away (``refsim info X | head -1``):
#: not a success, since the output was cut short, yet nothing to report.
EXIT_BROKEN_PIPE = 1

#: The status of ``refsim conform`` when a check failed (or ``--all`` left an
#: engine out).
EXIT_CHECK_FAILED = 1

#: The suffixes of the files refsim's commands write. An output directory
#: named with one of them is a file name given where a directory is meant
#: (``refsim report -o report.html``), refused rather than made a directory.
FILE_SUFFIXES = (".npz", ".html", ".htm", ".json", ".svg", ".toml", ".txt")


def output_file(path, suffixes: tuple[str, ...], command: str) -> Path:
    """``path`` as a Path when it can be written (:func:`refsim.storage.writing.output_target`:
    not a directory, device or FIFO, in a directory that exists) and its
    suffix is one of ``suffixes`` (in any case): the command writes that
    format whatever the name says, so another suffix is refused
    (OutputError naming the path) before any work."""
    from refsim.storage.writing import output_error, output_target

    out = Path(path)
    output_target(out)
    if out.suffix.lower() not in suffixes:
        raise output_error(out, f"refsim {command} writes {' or '.join(suffixes)} files; "
                                f"name the output with the suffix {suffixes[0]}")
    return out


def output_directory(path, command: str, writes: str) -> Path:
    """``path`` as a Path for a command that writes a directory (``writes``
    says what goes in it); a name with a file's suffix (FILE_SUFFIXES) that
    is not already a directory is refused before any work."""
    from refsim.storage.writing import output_error

    out = Path(path)
    if out.suffix.lower() in FILE_SUFFIXES and not out.is_dir():
        raise output_error(out, f"refsim {command} writes a directory ({writes}), not a "
                                f"{out.suffix} file; name a directory")
    return out


def max_steps_option(args) -> int:
    """``--max-steps``, checked, or the scenes' default limit."""
    from refsim.errors import check_count
    from refsim.limits import DEFAULT_MAX_STEPS, MAX_STEPS

    if args.max_steps is None:
        return DEFAULT_MAX_STEPS
    return check_count("--max-steps", args.max_steps, 1, MAX_STEPS)


def with_duration(scene, duration: float, max_steps: int | None = None):
    """``scene`` simulated for ``duration`` seconds instead of its own, in
    at most ``max_steps`` steps (default: the scenes' limit)."""
    from dataclasses import replace

    from refsim.errors import StateError
    from refsim.limits import DEFAULT_MAX_STEPS
    from refsim.scenes.loader import steps_limit_hint
    from refsim.solvers.integrate import whole_steps

    max_steps = DEFAULT_MAX_STEPS if max_steps is None else max_steps
    try:
        whole_steps(duration, scene.integration.step, max_steps)
    except StateError as exc:
        if not 0.0 < duration < scene.integration.step:   # the option's own fault
            hint = steps_limit_hint(duration, scene.integration.step, max_steps)
            raise RefsimError(f"--duration {duration!r}: {exc}{hint}") from None
        # no whole step fits: the option against the scene's step, both named
        raise SceneError(f"the step {scene.integration.step:g} is longer than --duration "
                         f"{duration!r}: no whole step fits", scene.path,
                         "integration.step") from None
    return replace(scene, integration=replace(scene.integration, duration=duration))


def write_output(out: Path, save) -> None:
    """``save(out)``; an ``OSError`` (a full disk, a refused target) becomes
    an :class:`OutputError` naming ``out`` (refsim.storage.writing leaves no file)."""
    from refsim.storage.writing import output_error

    try:
        save(out)
    except OutputError:
        raise
    except OSError as exc:
        raise output_error(out, exc.strerror or str(exc)) from exc



def add_max_steps(command) -> None:
    """``--max-steps N`` of the commands that simulate a scene as it is given."""
    from refsim.limits import DEFAULT_MAX_STEPS, MAX_STEPS

    command.add_argument("--max-steps", type=int, metavar="N",
                         help=f"refuse a scene of more than N steps (duration over step; "
                              f"default {DEFAULT_MAX_STEPS}, at most {MAX_STEPS})")


def one_line(text) -> str:
    """``text`` on one line: control characters (a newline in a file name,
    say) written as escapes, as ``repr`` writes them, so a message is always
    exactly one line of the terminal."""
    return "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in str(text))
