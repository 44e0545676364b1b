"""The fuzz harness itself: seeded mutators, rebuildable cases, the judge's
laws and the reproducer scripts (no refsim process is run here)."""

from __future__ import annotations

import itertools
import signal

import pytest

from tests.fuzz import corpus, mutate
from tests.fuzz.cases import (
    RANDOM_FAMILIES,
    Case,
    Special,
    case_from_id,
    family_mutators,
    fixed_cases,
    make_case,
    schedule,
)
from tests.fuzz.execute import Record
from tests.fuzz.judge import exception_type, innermost_frame, judge, normalize
from tests.fuzz.reproduce import shell_word, write_reproducer
from tests.fuzz.runner import Outcome

PLACES = {"{in}": "/tmp/case/in", "{out}": "/tmp/case/out"}
MODEL = "{in}/m.ac"


def _inputs():
    """(format, bytes) of every corpus file."""
    yield from (("ac", data) for data in corpus.models().values())
    yield from (("toml", data) for data in corpus.scenes().values())
    yield from corpus.exports().items()


# -- mutators ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(mutate.MUTATORS))
def test_a_mutator_is_a_function_of_its_input_and_seed(name):
    fmt, data = next((f, d) for f, d in _inputs() if f in mutate.MUTATORS[name].formats)
    first = [mutate.mutate(name, data, fmt, seed) for seed in range(4)]
    again = [mutate.mutate(name, data, fmt, seed) for seed in range(4)]
    assert first == again
    assert any(mutant != data for mutant in first)


def test_every_mutator_has_a_corpus_file_of_its_format():
    formats = {fmt for fmt, _ in _inputs()}
    assert {name for name, m in mutate.MUTATORS.items() if not m.formats & formats} == set()


def test_scale_by_multiplies_every_ac3d_vertex_and_nothing_else():
    cube = corpus.models()["cube.ac"]
    scaled = mutate.scale_by(cube, "ac", 2.0).decode().split("\n")
    original = cube.decode().split("\n")
    changed = [(a, b) for a, b in zip(original, scaled, strict=True) if a != b]
    assert len(changed) == 8                                    # numvert 8
    assert ("-0.5 -0.5 -0.5", "-1.0 -1.0 -1.0") in changed


def test_huge_count_sets_the_binary_stl_facet_count():
    data = corpus.exports()["stl-binary"]
    mutant = mutate.mutate("huge_count", data, "stl-binary", 3)
    assert len(mutant) == len(data) and mutant[:80] == data[:80]
    assert int.from_bytes(mutant[80:84], "little") in (0, 1, 0xFFFFFFFF, 0x7FFFFFFF,
                                                       1_000_000_000)


# -- cases ------------------------------------------------------------------------------


def test_a_case_id_rebuilds_the_same_case():
    for family in RANDOM_FAMILIES:
        case = make_case(family, family_mutators(family)[0], "7", 11)
        assert case_from_id(case.id) == case


def test_fixed_case_ids_are_unique_and_rebuild():
    cases = fixed_cases()
    assert len({c.id for c in cases}) == len(cases)
    assert case_from_id(cases[-1].id) == cases[-1]


def test_a_schedule_round_holds_every_mutator_of_every_family_once():
    size = sum(len(family_mutators(f)) for f in RANDOM_FAMILIES)
    first_round = list(itertools.islice(schedule("3"), size))
    assert sorted(first_round) == sorted((f, m) for f in RANDOM_FAMILIES
                                         for m in family_mutators(f))
    assert list(itertools.islice(schedule("3"), size)) == first_round
    assert list(itertools.islice(schedule("4"), size)) != first_round


# -- the judge --------------------------------------------------------------------------


def _signatures(stderr: str, returncode: int = 2, names=((MODEL, "line"),), **fields):
    case = Case("t", "model", "m", "s", ("info", MODEL), names=names, **fields)
    outcome = Outcome(returncode, False, False, "", stderr, 0.1)
    return [f.signature for f in judge(case, Record("t", outcome, PLACES)).failures]


@pytest.mark.parametrize(("stderr", "names"), [
    ("refsim: error: /tmp/case/in/m.ac:3: unknown token\n", ((MODEL, "line"),)),
    ("refsim: error: /tmp/case/in/m.ac: the file has no polygon surfaces (no triangles)\n",
     ((MODEL, "line"),)),
    ("refsim: error: /tmp/case/in/s.toml: body[1].position[2]: must be finite\n",
     (("{in}/s.toml", "key"),)),
    ("refsim: error: /tmp/case/in/s.toml: invalid TOML: Invalid value (at line 3, column 9)\n",
     (("{in}/s.toml", "key"),)),
])
def test_one_line_naming_the_file_and_line_or_key_is_a_good_refusal(stderr, names):
    assert _signatures(stderr, names=names) == []


def test_a_refusal_without_the_line_is_a_bad_message():
    assert _signatures("refsim: error: /tmp/case/in/m.ac: bad\n") == [
        "names no file with line or key: <path>: bad"]


def test_a_model_of_unknown_format_in_a_scene_must_name_the_scene_key():
    names = (("{in}/s.toml", "key"), ("{in}/m.txt", "model"))
    assert _signatures("refsim: error: /tmp/case/in/m.txt: unknown model format '.txt'\n",
                       names=names) == [
        "names no file with line or key: <path>: unknown model format '…'"]


def test_argparse_usage_lines_and_numpy_warnings_are_bad_messages():
    assert _signatures("usage: refsim run\nrefsim run: error: bad\n") == [
        "refusal prints more than one line: argparse usage and error"]
    assert _signatures("refsim: warning: overflow encountered in multiply\n", 0) == [
        "numpy RuntimeWarning shown as a refsim warning"]
    two = ("refsim: warning: invalid value encountered in divide\n"
           "refsim: error: /tmp/case/in/m.ac:2: bad\n")
    assert _signatures(two) == [
        "refusal prints more than one line: refsim: warning: <numpy warning>"]


def test_a_divergence_naming_its_body_twice_is_a_bad_message():
    stderr = "refsim: error: diverged at step 1, t = 0.001, body 'a', body 'a', boom\n"
    assert _signatures(stderr, 3) == ["divergence names the body twice"]
    assert _signatures(stderr.replace("body 'a', body 'a'", "body 'a'"), 3) == []


TRACEBACK = '''Traceback (most recent call last):
  File "/x/refsim/cli/app.py", line 220, in main
  File "/x/refsim/scenes/loader.py", line 51, in load_scene
  File "/usr/lib/python3.11/tomllib/_parser.py", line 144, in loads
RecursionError: maximum recursion depth exceeded
'''

DUMP = '''Fatal Python error: Segmentation fault

Current thread 0x0001 (most recent call first):
  File "/x/site-packages/scipy/spatial/_qhull.py", line 9 in __init__
  File "/x/refsim/models/mesh.py", line 290 in is_convex
  File "/x/refsim/cli/run.py", line 39 in info_command
'''


def test_the_root_cause_is_the_exception_and_the_innermost_refsim_frame():
    assert exception_type(TRACEBACK) == "RecursionError"
    assert innermost_frame(TRACEBACK, dump=False) == "refsim/scenes/loader.py:load_scene"
    assert innermost_frame(DUMP, dump=True) == "refsim/models/mesh.py:is_convex"
    assert _signatures(TRACEBACK, 1) == ["RecursionError in refsim/scenes/loader.py:load_scene"]


def test_a_signal_refsim_was_sent_is_no_crash_but_a_left_temp_file_is_a_failure():
    case = Case("t", "signal", "SIGTERM", "s", ("run",),
                interrupt=(signal.SIGTERM, ".out.npz.*.tmp", 0.03))
    outcome = Outcome(-signal.SIGTERM, False, True, "", "", 0.2)
    record = Record("t", outcome, PLACES, left=(".out.npz.abc.tmp",))
    assert [(f.column, f.signature) for f in judge(case, record).failures] == [
        ("files left", "temporary file left after SIGTERM")]


def test_normalize_blanks_files_paths_numbers_and_names():
    assert normalize("/tmp/case/in/m.ac:12: vertex 'x' at 1e+308", PLACES) == \
        "<path>:N: vertex '…' at N"
    assert normalize("model 'm.ac' not found (looked in /tmp/case/in/m.ac, /work/models/m.ac)",
                     PLACES) == "model '…' not found (looked in <path>, <path>)"
    assert normalize("can't decode byte 0xe9 in position 3: invalid start byte", PLACES) == \
        normalize("can't decode byte 0xff in position 9: invalid continuation byte", PLACES)


# -- reproducers ------------------------------------------------------------------------


def test_shell_word_quotes_text_and_expands_the_case_directories():
    assert shell_word("{in}/a b.ac") == '"$work/in"\'/a b.ac\''
    assert shell_word("--every") == "--every"


def test_a_reproducer_holds_the_mutant_and_runs_the_same_command(tmp_path):
    case = Case("special:x", "special", "x", "s", ("info", "{in}/x.ac"),
                files=(("{in}/m.ac", b"AC3Db\n"),),
                specials=(Special("fifo", "{in}/x.ac"),), cpu_limit=7.0)
    script = write_reproducer(case, tmp_path / "r").read_text()
    assert (tmp_path / "r" / "in" / "m.ac").read_bytes() == b"AC3Db\n"
    assert 'mkfifo "$work/in"/x.ac' in script
    assert ('(ulimit -S -t 7; exec timeout -s KILL 70 "${REFSIM:-refsim}" info '
            '"$work/in"/x.ac)') in script
