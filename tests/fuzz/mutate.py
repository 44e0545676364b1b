"""Seeded mutators of model and scene files: bytes in, bytes out.

Each :class:`Mutator` takes the bytes of a file and a ``random.Random`` and
returns a mutant; the same bytes and the same seed give the same mutant. Text
formats are handled as Latin-1 text (one character per byte, so any byte
survives the round trip, and a mutator can insert bytes that are not UTF-8).

The mutators aim at what a reader can get wrong (docs/design.md, Errors; the AC3D
reader's "Strictness" list in ``refsim/models/ac3d.py``; the scene schema):

=================  ==========================================================
truncate           cut the file at a random byte
garbage_token      insert a token that does not belong (a keyword, a bracket)
hostile_number     replace 1-3 numbers by NaN, inf, -0, 1e308, 5e-324, 1e155,
                   huge integers, ...
scale_vertices     multiply every vertex coordinate by 1e155, 1e-300, 0, ...
collapse           put every vertex on one point, one line or one plane
huge_count         a count (numvert, refs, kids, PLY/OFF/STL counts,
                   particles, steps) of 1e9 or beyond 64 bits
binary_junk        insert random bytes (NUL included)
binary_floats      overwrite floats of a binary file with NaN, inf, 3.4e38
non_utf8           insert a byte that is not UTF-8 (in a comment, a name, anywhere)
duplicate_line     repeat a line; remove_line, swap_lines likewise
swap_sections      exchange two sections (AC3D objects/blocks, TOML tables)
long_line          a line of a million characters or 100 000 tokens
deep_nesting       AC3D kids nested 500-50 000 deep; TOML arrays, inline
                   tables and table headers nested 100-5000 deep
hostile_rot        an AC3D ``rot`` of 1e155, zeros, rank one, NaN, a reflection
hostile_loc        an AC3D ``loc`` of 1e308, 1e155, ...
long_polygon       one AC3D polygon of 1000-20 000 corners (ear clipping)
set_key            a TOML key's value replaced by a hostile value of any type
add_key            a hostile key added to a TOML table (scale = 1e155, ...)
model_ref          a body's model replaced by a hostile reference
remove_key         a TOML key removed (``model`` is required)
line_endings       CRLF line endings, a byte-order mark, tabs (all lenient)
=================  ==========================================================
"""

from __future__ import annotations

import math
import random
import re
import struct
from collections.abc import Callable
from dataclasses import dataclass

from tests.fuzz.corpus import long_polygon_ac3d

TEXT_MESH = frozenset({"obj", "stl-ascii", "ply-ascii", "off"})
BINARY_MESH = frozenset({"stl-binary", "ply-binary"})
MODEL_FORMATS = frozenset({"ac"}) | TEXT_MESH | BINARY_MESH
TEXT = frozenset({"ac", "toml"}) | TEXT_MESH
ALL = TEXT | BINARY_MESH

#: A decimal number token (not part of a word such as ``sphere-2k`` or ``0x0``).
NUMBER = re.compile(r"(?<![\w.+\-])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")

#: Numbers that have broken readers and the code behind them: non-finite,
#: signed zero, the largest and smallest doubles, values whose square or cube
#: overflows (1e155, 1e154) or underflows (1e-320), integers beyond int64.
HOSTILE_NUMBERS = ("nan", "NaN", "inf", "-inf", "-0", "-0.0", "1e308",
                   "1.7976931348623157e308", "5e-324", "1e155", "1e154", "-1e155", "1e-320",
                   "1e62", "1e-65", "1e100", "99999999999999999999999", "9223372036854775808",
                   "1000000000", "-1", "0", "1e", ".", "+")

#: TOML spellings (``nan``/``inf`` are TOML floats; the rest test the types).
HOSTILE_TOML_VALUES = ("nan", "+nan", "inf", "-inf", "-0.0", "1e308", "5e-324", "1e155",
                       "1e154", "1e-320", "1e62", "1e-65", "1e100", "-1e100",
                       "99999999999999999999", "9223372036854775807", "1000000000", "-1",
                       "0", "1_000", "0x10", "true", '"1.0"', '""', '"bogus"', "[]",
                       "[1.0, 2.0]", "[nan, 0.0, 0.0]", "[1e308, 1e308, 1e308]",
                       "[[0, 0, 0], [0, 0, 0], [0, 0, 0]]", "{}", "{ a = 1 }",
                       "1979-05-27T07:32:00Z", '"\\u0000"')

#: Keys a scene's tables accept, with hostile values that were accepted or
#: crashed before (singular inertia, overflow of a squared norm, a body out
#: of the cube or far too fast, zero steps).
HOSTILE_SCENE_KEYS = {
    "body": ("scale = 1e155", "scale = 1e154", "scale = 1e62", "scale = 1e-65",
             "scale = 5e-324", "mass = 5e-324", "mass = 1e-320", "mass = 1e308",
             "position = [1e100, 0.0, 0.0]", "position = [1e308, 1e308, 1e308]",
             "velocity = [1e100, 0.0, 0.0]", "velocity = [1e308, -1e308, 0.0]",
             "angular_velocity = [1e155, 0.0, 0.0]",
             "orientation = [[0, 0, 0], [0, 0, 0], [0, 0, 0]]",
             "orientation = [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]",
             "orientation = [[1, 0, 0], [0, 1, 0], [0, 0, 1.0000001]]",
             'name = ""', 'name = "\\n"', "colour = 1"),
    "world": ("half_size = 1e308", "half_size = 5e-324", "half_size = 1e-300",
              "gravity = 1e308", "drag = 1e308", 'drag_model = "quadratic"',
              "restitution = 1.0", "friction = 1.0", "gravity = 1e155"),
    "integration": ("step = 5e-324", "step = 1e-300", "step = 1e308", "step = 0.5",
                    "duration = 1e-9", "duration = 1e308", "duration = 5e-324",
                    'solver = "rk5"', "duration = 1e9"),
    "collision": ('level = "sphere"', 'level = "aabb"', 'level = "triangle-aabb"',
                  'aabb = "incremental"', 'aabb = "linear"', 'level = "EXACT"'),
    "dynamics": ('rotation = "impulse"', 'body_response = "impulse"', 'rotation = "seed"'),
    "particles": ("count = 1000000000", "count = 10000000000", "count = 40000000",
                  "count = 0", "seed = -1", "seed = 99999999999999999999",
                  "speed_max = 1e308", "mass = 5e-324", "box_hi = [1e308, 0, 0]",
                  "walls = 1"),
}

#: Model references a scene might hold by mistake or malice.
HOSTILE_MODEL_REFS = ("", "/", ".", "..", "/dev/null", "/dev/zero", "/proc/self/mem",
                      "missing.ac", "cube", "cube.AC", "CUBE.ac", "scene.toml", "bounce.toml",
                      "../" * 20 + "etc/passwd", "x" * 5000 + ".ac", "cube.ac\\u0000.ac",
                      "models/", "sphere-2k.ac/..", "~/cube.ac", "cube.obj", "cube.stl",
                      "\\u00e9t\\u00e9.ac")

#: Tokens that do not belong where they are put.
GARBAGE_TOKENS = ("@@", "OBJECT", "kids", "numvert", "SURF", "refs", "MATERIAL", "=", "[",
                  "]", "]]", "[[", "{", "}", '"', "'", "#", ",", "0x", "-", "e", "1e",
                  "\\", "\t", "nan", "[[body]]", "[world]", "v", "f", "facet", "endsolid",
                  "element", "end_header", "\x00", "\x7f", "OFF")

#: Bytes that are not UTF-8 on their own: a lone continuation byte, a lead
#: byte without its continuation, a surrogate, an overlong encoding.
NON_UTF8 = (b"\xff", b"\xfe", b"\xe9", b"\x80", b"\xc3", b"\xed\xa0\x80", b"\xc0\xaf",
            b"caf\xe9")


@dataclass(frozen=True)
class Mutator:
    """A named mutation, the formats it applies to, and its function
    ``apply(data, fmt, rng) -> bytes`` (``fmt``: the format of ``data``)."""

    name: str
    formats: frozenset
    apply: Callable[[bytes, str, random.Random], bytes]


MUTATORS: dict[str, Mutator] = {}


def mutator(*formats: frozenset | str):
    """Register the decorated function as the mutator of its name."""
    allowed = frozenset().union(*(f if isinstance(f, frozenset) else {f} for f in formats))

    def register(function):
        MUTATORS[function.__name__] = Mutator(function.__name__, allowed, function)
        return function

    return register


def mutators_for(fmt: str) -> list[Mutator]:
    """The mutators that apply to format ``fmt``, in a fixed order."""
    return [m for m in MUTATORS.values() if fmt in m.formats]


# -- helpers ----------------------------------------------------------------------------


def _text(data: bytes) -> str:
    return data.decode("latin-1")


def _bytes(text: str) -> bytes:
    return text.encode("latin-1", "replace")


def _lines(data: bytes) -> list[str]:
    return _text(data).split("\n")


def _join(lines: list[str]) -> bytes:
    return _bytes("\n".join(lines))


def _header_end(data: bytes) -> int:
    """Where a PLY header ends (0 for other files)."""
    mark = data.find(b"end_header\n")
    return 0 if mark < 0 else mark + len(b"end_header\n")


def vertex_line_indices(fmt: str, lines: list[str]) -> list[int]:
    """Indices of the lines holding vertex coordinates in a text model."""
    found = []
    if fmt == "ac":
        left = 0
        for i, line in enumerate(lines):
            words = line.split()
            if left and words:
                found.append(i)
                left -= 1
            elif len(words) == 2 and words[0] == "numvert" and words[1].isdigit():
                left = int(words[1])
    elif fmt == "obj":
        found = [i for i, line in enumerate(lines) if line.startswith("v ")]
    elif fmt == "stl-ascii":
        found = [i for i, line in enumerate(lines) if line.strip().startswith("vertex ")]
    elif fmt in ("ply-ascii", "off"):
        n, start = _vertex_block(fmt, lines)
        found = list(range(start, min(start + n, len(lines))))
    return found


def _vertex_block(fmt: str, lines: list[str]) -> tuple[int, int]:
    """(vertex count, index of the first vertex line) of a PLY or OFF file."""
    if fmt == "ply-ascii":
        n = next((int(line.split()[2]) for line in lines
                  if line.startswith("element vertex ")), 0)
        start = next((i + 1 for i, line in enumerate(lines) if line.strip() == "end_header"), 0)
        return n, start
    body = [i for i, line in enumerate(lines) if line.strip() and not line.startswith("#")]
    if len(body) < 2 or not lines[body[1]].split()[0].isdigit():
        return 0, 0
    return int(lines[body[1]].split()[0]), body[1] + 1


def _coordinates(line: str, fmt: str) -> tuple[str, list[str]]:
    """A vertex line split into its prefix (``v``, ``vertex``) and three numbers."""
    words = line.split()
    if fmt in ("obj", "stl-ascii"):
        return words[0] + " ", words[1:4]
    return "", words[:3]


def _format(x: float) -> str:
    return repr(x) if math.isfinite(x) else ("nan" if math.isnan(x) else
                                             ("inf" if x > 0 else "-inf"))


def _rewrite_vertices(data: bytes, fmt: str, transform) -> bytes:
    """Replace every vertex line's coordinates by ``transform(i, [x, y, z])``."""
    lines = _lines(data)
    for n, i in enumerate(vertex_line_indices(fmt, lines)):
        prefix, coordinates = _coordinates(lines[i], fmt)
        try:
            xyz = [float(c) for c in coordinates]
        except ValueError:
            continue
        if len(xyz) != 3:
            continue
        rest = lines[i].split()[len(prefix.split()) + 3:]
        lines[i] = prefix + " ".join(_format(x) for x in transform(n, xyz)) + \
            ("" if not rest else " " + " ".join(rest))
    return _join(lines)


def _table_spans(lines: list[str]) -> list[tuple[str, int, int]]:
    """TOML tables as (name, header index, end index); the root table is ''."""
    spans, name, start = [], "", 0
    for i, line in enumerate(lines):
        stripped = line.strip()
        if stripped.startswith("["):
            spans.append((name, start, i))
            name, start = stripped.strip("[] "), i
    spans.append((name, start, len(lines)))
    return spans


def _key_lines(lines: list[str]) -> list[int]:
    return [i for i, line in enumerate(lines)
            if re.match(r"\s*[A-Za-z_][\w-]*\s*=", line)]


# -- every format ---------------------------------------------------------------------


@mutator(ALL)
def truncate(data: bytes, fmt: str, rng: random.Random) -> bytes:
    return data[:rng.randrange(len(data) + 1)]


@mutator(ALL)
def binary_junk(data: bytes, fmt: str, rng: random.Random) -> bytes:
    junk = bytes(rng.randrange(256) for _ in range(rng.choice((1, 4, 16, 64))))
    at = rng.randrange(len(data) + 1)
    return data[:at] + junk + data[at:]


@mutator(TEXT)
def garbage_token(data: bytes, fmt: str, rng: random.Random) -> bytes:
    text = _text(data)
    spaces = [m.start() for m in re.finditer(r"[ \n]", text)] or [0]
    at = rng.choice(spaces)
    return _bytes(text[:at] + " " + rng.choice(GARBAGE_TOKENS) + text[at:])


@mutator(TEXT)
def hostile_number(data: bytes, fmt: str, rng: random.Random) -> bytes:
    text = _text(data)
    matches = list(NUMBER.finditer(text))
    if not matches:
        return data
    lexicon = HOSTILE_TOML_VALUES if fmt == "toml" else HOSTILE_NUMBERS
    chosen = sorted(rng.sample(matches, min(len(matches), rng.choice((1, 1, 2, 3)))),
                    key=lambda m: m.start(), reverse=True)
    for m in chosen:
        text = text[:m.start()] + rng.choice(lexicon) + text[m.end():]
    return _bytes(text)


#: How each text format writes a comment line, where it has one.
COMMENT = {"toml": b"# ", "obj": b"# ", "off": b"# ", "ply-ascii": b"comment "}


@mutator(TEXT)
def non_utf8(data: bytes, fmt: str, rng: random.Random) -> bytes:
    bad = rng.choice(NON_UTF8)
    where = rng.choice(("comment", "name", "anywhere"))
    if where == "comment" and fmt in COMMENT:
        lines = data.split(b"\n")
        at = 1 if fmt == "ply-ascii" else rng.randrange(len(lines) + 1)
        return b"\n".join(lines[:at] + [COMMENT[fmt] + bad] + lines[at:])
    if where == "name":
        m = re.search(rb'(?:name\s*=?\s*"|MATERIAL ")', data)
        if m:
            return data[:m.end()] + bad + data[m.end():]
    at = rng.randrange(len(data) + 1)
    return data[:at] + bad + data[at:]


@mutator(TEXT)
def duplicate_line(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    i = rng.randrange(len(lines))
    return _join(lines[:i + 1] + [lines[i]] * rng.choice((1, 1, 2, 100)) + lines[i + 1:])


@mutator(TEXT)
def remove_line(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    del lines[rng.randrange(len(lines))]
    return _join(lines)


@mutator(TEXT)
def swap_lines(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[i], lines[j] = lines[j], lines[i]
    return _join(lines)


@mutator(TEXT)
def long_line(data: bytes, fmt: str, rng: random.Random) -> bytes:
    kind = rng.choice(("token", "numbers", "name"))
    if kind == "token":
        line = "a" * 1_000_000
    elif kind == "numbers":
        line = " ".join(["0"] * 100_000)
    elif fmt == "toml":
        line = 'name = "' + "n" * 1_000_000 + '"'
    else:
        line = 'name "' + "n" * 1_000_000 + '"'
    lines = _lines(data)
    at = rng.randrange(1, len(lines) + 1)
    return _join(lines[:at] + [line] + lines[at:])


#: Factors for :func:`scale_vertices`: squares or cubes that overflow (1e155,
#: 1e154, 1e300), underflow (1e-300, 1e-320), an inertia that is singular in
#: float64 (1e-65, 0) or whose eigenvalues are huge (1e62), a reflection.
SCALE_FACTORS = (1e155, 1e154, -1e155, 1e150, 1e300, 1e-300, 1e-320, 1e62, 1e-65, 0.0)

#: The factors of SCALE_FACTORS that keep a mesh's shape (no underflow, no
#: zero): a closed model stays closed, and a convex one convex unless the
#: factor is negative (a reflection turns the faces' winding inward, and
#: "convex" means a solid bounded by outward faces: refsim then says no).
SHAPE_KEEPING_FACTORS = (1e155, 1e154, -1e155, 1e150, 1e62)


def scale_by(data: bytes, fmt: str, factor: float) -> bytes:
    """Every vertex coordinate of a text model multiplied by ``factor``."""
    return _rewrite_vertices(data, fmt, lambda i, xyz: [x * factor for x in xyz])


@mutator("ac", "obj", "stl-ascii", "ply-ascii", "off")
def scale_vertices(data: bytes, fmt: str, rng: random.Random) -> bytes:
    return scale_by(data, fmt, rng.choice(SCALE_FACTORS))


@mutator("ac", "obj", "stl-ascii", "ply-ascii", "off")
def collapse(data: bytes, fmt: str, rng: random.Random) -> bytes:
    shape = rng.choice(("point", "line", "plane"))

    def transform(i, xyz):
        x, y, z = xyz
        return {"point": [0.5, 0.5, 0.5], "line": [x, 0.0, 0.0], "plane": [x, y, 0.0]}[shape]

    return _rewrite_vertices(data, fmt, transform)


# -- counts -------------------------------------------------------------------------------

HUGE_COUNTS = ("1000000000", "999999999999999999", "9223372036854775807", "4294967296",
               "2147483648", "-1", "0", "1e3")


@mutator("ac", "toml", "ply-ascii", "ply-binary", "off", "stl-binary")
def huge_count(data: bytes, fmt: str, rng: random.Random) -> bytes:
    if fmt == "stl-binary":                        # the uint32 facet count at byte 80
        count = rng.choice((0, 1, 0xFFFFFFFF, 0x7FFFFFFF, 1_000_000_000))
        return data[:80] + struct.pack("<I", count) + data[84:]
    if fmt == "toml":
        table, assignment = rng.choice((
            ("particles", "count = 1000000000"), ("particles", "count = 10000000000"),
            ("particles", "count = 40000000"), ("integration", "duration = 1e308"),
            ("integration", "step = 5e-324"), ("integration", "duration = 100000")))
        return _set_scene_key(data, rng, table, assignment)
    text = _text(data)
    if fmt == "off":
        lines = text.split("\n")
        lines[1] = " ".join([rng.choice(HUGE_COUNTS)] + lines[1].split()[1:])
        return _bytes("\n".join(lines))
    pattern = (r"(?m)^(\s*(?:numvert|numsurf|refs|kids|data|mat)\s+)(\S+)" if fmt == "ac"
               else r"(?m)^(element \w+ )(\d+)")
    matches = list(re.finditer(pattern, text))
    if not matches:
        return data
    m = rng.choice(matches)
    return _bytes(text[:m.start(2)] + rng.choice(HUGE_COUNTS) + text[m.end(2):])


@mutator(BINARY_MESH)
def binary_floats(data: bytes, fmt: str, rng: random.Random) -> bytes:
    """Overwrite one to three float32 coordinates with NaN, inf, the largest
    float32 or a subnormal (binary STL: the vertex fields of a facet record;
    binary PLY: any aligned word after the header)."""
    out = bytearray(data)
    values = (math.nan, math.inf, -math.inf, 3.4e38, 1e-45, -0.0)
    for _ in range(rng.choice((1, 2, 3))):
        if data.startswith(b"ply"):
            start = _header_end(data)
            if len(data) - start < 4:
                break
            at = start + 4 * rng.randrange((len(data) - start) // 4)
        else:
            facets = (len(data) - 84) // 50
            if facets < 1:
                break
            at = 84 + 50 * rng.randrange(facets) + 12 + 4 * rng.randrange(9)
        out[at:at + 4] = struct.pack("<f", rng.choice(values))
    return bytes(out)


# -- AC3D structure ---------------------------------------------------------------------


def _object_lines(lines: list[str]) -> list[int]:
    return [i for i, line in enumerate(lines) if line.startswith("OBJECT")]


def _insert_object_token(data: bytes, rng: random.Random, token_line: str, token: str) -> bytes:
    """Put ``token_line`` into a random object, replacing its ``token`` line if any."""
    lines = _lines(data)
    objects = _object_lines(lines)
    if not objects:
        return data
    start = rng.choice(objects)
    end = next((j for j in range(start + 1, len(lines)) if lines[j].startswith(
        ("OBJECT", "numvert", "numsurf", "kids"))), len(lines))
    for j in range(start + 1, end):
        if lines[j].split()[:1] == [token]:
            lines[j] = token_line
            return _join(lines)
    return _join(lines[:start + 1] + [token_line] + lines[start + 1:])


HOSTILE_ROTS = ("1e155 0 0 0 1e155 0 0 0 1e155", "1e154 0 0 0 1e154 0 0 0 1e154",
                "0 0 0 0 0 0 0 0 0", "1 0 0 1 0 0 1 0 0", "1e-300 0 0 0 1e-300 0 0 0 1e-300",
                "nan 0 0 0 1 0 0 0 1", "-1 0 0 0 1 0 0 0 1", "1e308 1e308 0 0 1e308 0 0 0 1e308",
                "1e62 0 0 0 1e62 0 0 0 1e62", "1e-65 0 0 0 1e-65 0 0 0 1e-65")


@mutator("ac")
def hostile_rot(data: bytes, fmt: str, rng: random.Random) -> bytes:
    return _insert_object_token(data, rng, "rot " + rng.choice(HOSTILE_ROTS), "rot")


@mutator("ac")
def hostile_loc(data: bytes, fmt: str, rng: random.Random) -> bytes:
    loc = rng.choice(("1e308 1e308 1e308", "1e155 0 0", "-1e308 0 0", "1e300 1e300 1e300",
                      "5e-324 0 0", "1e154 1e154 1e154"))
    return _insert_object_token(data, rng, "loc " + loc, "loc")


@mutator("ac", "toml")
def deep_nesting(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    if fmt == "ac":                       # the first object inside N groups of one kid
        objects = _object_lines(lines)
        if not objects:
            return data
        wrapper = ["OBJECT group", "kids 1"] * rng.choice((500, 5000, 50_000))
        return _join(lines[:objects[0]] + wrapper + lines[objects[0]:])
    depth = rng.choice((100, 500, 5000))
    kind = rng.choice(("array", "inline-table", "header", "body-array"))
    if kind == "array":
        return _join(["deep = " + "[" * depth + "]" * depth] + lines)
    if kind == "inline-table":
        return _join(["deep = " + "{ a = " * depth + "1" + " }" * depth] + lines)
    if kind == "header":
        return _join(lines + ["[" + ".".join(["a"] * depth) + "]", "x = 1"])
    return _set_scene_key(data, rng, "body", "position = " + "[" * depth + "0.0" + "]" * depth)


@mutator("ac")
def long_polygon(data: bytes, fmt: str, rng: random.Random) -> bytes:
    return long_polygon_ac3d(rng.choice((1000, 4000, 20_000)), star=rng.random() < 0.5)


@mutator("ac", "toml")
def swap_sections(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    if data.startswith(b"AC3D"):
        starts = [i for i, line in enumerate(lines)
                  if line.startswith(("OBJECT", "numvert", "numsurf", "SURF", "kids",
                                      "MATERIAL"))]
    else:
        starts = [start for _, start, _ in _table_spans(lines)]
    if len(starts) < 2:
        return data
    bounds = starts + [len(lines)]
    sections = [lines[bounds[k]:bounds[k + 1]] for k in range(len(starts))]
    i, j = rng.sample(range(len(sections)), 2)
    sections[i], sections[j] = sections[j], sections[i]
    return _join(lines[:starts[0]] + [line for s in sections for line in s])


# -- TOML structure -------------------------------------------------------------------


def _set_scene_key(data: bytes, rng: random.Random, table: str, assignment: str) -> bytes:
    """``assignment`` (``key = value``) set in a random ``table`` of the scene:
    replacing the key's line there, or added under the table's header (a new
    table at the end when the scene has none)."""
    lines = _lines(data)
    key = assignment.split("=")[0].strip()
    spans = [s for s in _table_spans(lines) if s[0] == table]
    if not spans:
        header = "[[body]]" if table == "body" else f"[{table}]"
        return _join(lines + [header, assignment])
    _, start, end = rng.choice(spans)
    for i in range(start + 1, end):
        if re.match(rf"\s*{re.escape(key)}\s*=", lines[i]):
            lines[i] = assignment
            return _join(lines)
    return _join(lines[:start + 1] + [assignment] + lines[start + 1:])


@mutator("toml")
def set_key(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    keys = _key_lines(lines)
    if not keys:
        return data
    i = rng.choice(keys)
    key = lines[i].split("=")[0].rstrip()
    lines[i] = f"{key} = {rng.choice(HOSTILE_TOML_VALUES)}"
    return _join(lines)


@mutator("toml")
def add_key(data: bytes, fmt: str, rng: random.Random) -> bytes:
    table = rng.choice(sorted(HOSTILE_SCENE_KEYS))
    return _set_scene_key(data, rng, table, rng.choice(HOSTILE_SCENE_KEYS[table]))


@mutator("toml")
def remove_key(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    keys = _key_lines(lines)
    if not keys:
        return data
    del lines[rng.choice(keys)]
    return _join(lines)


@mutator("toml")
def model_ref(data: bytes, fmt: str, rng: random.Random) -> bytes:
    lines = _lines(data)
    models = [i for i, line in enumerate(lines) if re.match(r"\s*model\s*=", line)]
    if not models:
        return _set_scene_key(data, rng, "body",
                              f'model = "{rng.choice(HOSTILE_MODEL_REFS)}"')
    lines[rng.choice(models)] = f'model = "{rng.choice(HOSTILE_MODEL_REFS)}"'
    return _join(lines)


@mutator(TEXT)
def line_endings(data: bytes, fmt: str, rng: random.Random) -> bytes:
    kind = rng.choice(("crlf", "bom", "tabs", "cr"))
    if kind == "crlf":
        return data.replace(b"\n", b"\r\n")
    if kind == "bom":
        return b"\xef\xbb\xbf" + data
    if kind == "cr":
        return data.replace(b"\n", b"\r")
    return data.replace(b" ", b"\t")


def mutate(name: str, data: bytes, fmt: str, seed) -> bytes:
    """The mutant of ``data`` (format ``fmt``) by mutator ``name`` with
    ``random.Random(seed)``."""
    return MUTATORS[name].apply(data, fmt, random.Random(seed))
