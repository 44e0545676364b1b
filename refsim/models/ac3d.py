"""Reading and writing AC3D (``.ac``) models (seed S1).

The seed "reads in models' output from a public domain modeler called AC3D"
and keeps per-triangle information. :func:`parse_ac3d` turns an AC3D file into
one :class:`~refsim.models.mesh.Mesh`; :func:`format_ac3d` writes a mesh back
so that reading it again gives the same mesh, value for value.

Reference: "The AC3D file format", Inivis / ac3d.org, last updated 27 March
2003 (http://www.inivis.com/ac3d/man/ac3dfileformat.html, mirrored at
paulbourke.org/dataformats/ac3d). The grammar, with ``*`` marking optional
lines::

    AC3D<hex version>
    MATERIAL %s rgb %f %f %f  amb %f %f %f  emis %f %f %f  spec %f %f %f  shi %d  trans %f
    OBJECT world|poly|group|light
      *name %s  *data %d  *texture %s  *texrep %f %f  *rot %f x9  *loc %f %f %f
      *url %s  *numvert %d (then %d lines "%f %f %f")
      *numsurf %d (then %d surfaces: SURF %d, *mat %d, refs %d, then %d lines "%d %f %f")
      kids %d (then %d child objects)

What the reader does with it:

- All objects of a file form one mesh. A vertex's world position composes
  the transforms down the tree: ``world = R_parent (R_child v + loc_child) +
  loc_parent``, applied child first, and only where a ``rot`` or ``loc`` is
  given (so untransformed coordinates keep their exact bits).
- ``rot`` order. The spec does not say how its nine numbers fill the matrix.
  We follow PLIB's ``ssgLoadAC`` (the loader behind FlightGear and most AC3D
  content) and the Blender 2.4 importer: the numbers are read row by row into
  a matrix ``M`` that multiplies *row* vectors, ``p' = p M``. So the first
  three numbers are the image of the x axis, the next three of y, the last
  three of z: in our column-vector convention (docs/design.md: columns are the
  body's axes) the file lists ``R = M.T`` column by column (column-major).
  ``rot 0 1 0  -1 0 0  0 0 1`` turns x into y (+90 degrees about z).
  Any finite matrix is applied as given (AC3D may store a scale in it).
  No axis conversion: AC3D is y-up, like refsim (PLIB swaps y and z for its
  own z-up world; we do not).
- Surfaces: the type is ``flags & 0xF``. Type 0 (polygon) becomes triangles:
  three refs as they are, more by :func:`~refsim.models.triangulate.ear_clip`
  in the object's own coordinates. Types 1 and 2 (closed line, line) carry no
  area: they are skipped with one :class:`~refsim.errors.ModelWarning` per
  file. Each triangle keeps its surface's material index, full ``SURF``
  flags and the index of its object.
- Objects: ``Mesh.objects`` has one entry per ``poly`` object, in file
  order, even one without triangles (so that every object of a written mesh
  comes back), and one per ``world``/``group``/``light`` object only if it
  holds polygons itself. An unnamed object is named after its type
  (``"poly"``), as AC3D shows it.
- Materials: ``Mesh.materials`` is the file's palette, each line's text after
  the rgb triple kept verbatim (surrounding whitespace stripped) so that the
  writer reproduces it. With no MATERIAL lines the palette is refsim's
  default material, and ``mat 0`` (or no ``mat``) refers to it.
- ``data %d`` counts the bytes of the blob that starts on the next line (the
  UTF-8 bytes, or Latin-1 for a file that is not UTF-8); the rest of the
  line where the blob ends must be blank. Windows line endings are turned
  into ``\\n`` first, as C's text mode does, so ``\\r`` is not counted.

Strictness (the spec is a closed grammar, so an unknown token is an error):
any malformed file raises :class:`~refsim.errors.ModelError` naming the file
and the 1-based line, for a missing header, an unknown token, a wrong number
of values, a non-numeric or non-finite number, a negative count, a count
that runs past the end of the file, a vertex or material index out of range,
a polygon with fewer than three refs, an unterminated quote, a duplicated
object token, or a file with no triangles at all (no line then). Lenient
where the format is: blank lines anywhere, any spaces and tabs, ``\\r\\n`` line
endings, a UTF-8 byte-order mark, MATERIAL lines between objects, and the
tokens newer AC3D versions write (``texoff``, ``crease``, ``subdiv``,
``folded``, ``hidden``, ``locked``), which are checked or skipped. Numbers
are ASCII decimals (``SURF`` flags also ``0x`` hex); quoted strings may hold
spaces and have no escapes. Objects are parsed with an explicit stack, so
deep nesting cannot exhaust Python's recursion limit.

The writer emits ``AC3Db``, the palette, and one ``OBJECT world`` whose kids
are one ``OBJECT poly`` per entry of ``mesh.objects`` holding that object's
triangles, with identity transforms and floats written by ``repr`` (shortest
text that reads back to the same double). Each object lists the vertices its
triangles use in ascending index order; when that would not reproduce the
mesh's vertex order on reading (the reader keeps vertices in order of first
appearance), the first object lists every vertex instead. Faces are written
grouped by object; a mesh whose ``face_object`` is not sorted comes back with
its faces regrouped (stable within each object), and the writer warns.

Cost: reading is O(L + sum k^2) for L lines and polygons of k corners, plus
the O(n log n) weld in :class:`Mesh`; writing is O(n log n + m * objects).
"""

from __future__ import annotations

import bisect
import math
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from refsim.errors import ModelError, ModelWarning
from refsim.models.mesh import Material, Mesh
from refsim.models.triangulate import ear_clip
from refsim.storage.reading import read_regular_file
from refsim.storage.writing import write_text_atomic

#: The header the writer emits (version 0xb, the spec's version).
HEADER = "AC3Db"

OBJECT_TYPES = ("world", "poly", "group", "light")

#: Surface types, ``flags & SURF_TYPE_MASK`` (spec, "SURF %d").
SURF_TYPE_MASK = 0xF
SURF_POLYGON, SURF_CLOSED_LINE, SURF_LINE = 0, 1, 2

#: The keywords after ``rgb`` on a MATERIAL line and how many numbers follow each.
MATERIAL_FIELDS = {"amb": 3, "emis": 3, "spec": 3, "shi": 1, "trans": 1}

#: Object tokens of newer AC3D files that carry nothing the simulation uses;
#: the line is skipped whatever follows the token.
SKIPPED_TOKENS = frozenset({"subdiv", "folded", "hidden", "locked"})

#: Integers (counts, indices, flags) longer than this many characters are
#: rejected before conversion: they exceed int64 (and Python refuses to
#: convert strings of more than 4300 digits).
MAX_DIGITS = 18

_SPACE = " \t\r\f\v"
_BARE = re.compile(r'[^ \t\r\f\v"]+')
_FLOAT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:inf|infinity|nan)",
                    re.ASCII | re.IGNORECASE)
_INT = re.compile(r"[+-]?\d+", re.ASCII)
_FLAGS = re.compile(r"0[xX][0-9a-fA-F]+|\d+", re.ASCII)
_HEADER = re.compile(r"AC3D[0-9a-fA-F]+", re.ASCII)


class _Quoted(str):
    """A token that was written as a quoted string (never a keyword or number)."""

    __slots__ = ()


def _quoted(token: str) -> bool:
    return isinstance(token, _Quoted)


_TO_SPACE = str.maketrans({c: " " for c in _SPACE})


def _tokenize(line: str) -> list[str] | str:
    """Split one line into tokens; a quoted string is one :class:`_Quoted` token.

    Returns the tokens, or an error message for an unterminated or stray quote.
    """
    if '"' not in line:  # fast path: most lines are numbers
        return [w for w in line.translate(_TO_SPACE).split(" ") if w]
    tokens = _tokenize_with_ends(line)
    return tokens if isinstance(tokens, str) else [t for t, _ in tokens]


def _tokenize_with_ends(line: str) -> list[tuple[str, int]] | str:
    """The tokens of ``line``, each with the offset just past it."""
    tokens: list[tuple[str, int]] = []
    pos, n = 0, len(line)
    while True:
        while pos < n and line[pos] in _SPACE:
            pos += 1
        if pos == n:
            return tokens
        if line[pos] == '"':
            close = line.find('"', pos + 1)
            if close < 0:
                return "unterminated quote"
            tokens.append((_Quoted(line[pos + 1:close]), close + 1))
            pos = close + 1
        else:
            match = _BARE.match(line, pos)
            if match is None:                    # line[pos] is neither a space nor a quote
                raise ValueError(f"_tokenize_with_ends: no token at offset {pos} of {line!r}")
            tokens.append((match.group(), match.end()))
            pos = match.end()
        if pos < n and line[pos] not in _SPACE:
            return "a quote must start a new token" if line[pos] == '"' else \
                "a quoted string must be followed by a space"


def _material_rest_problem(tokens: list[str]) -> str | None:
    """Why the text after a MATERIAL line's rgb triple is malformed, or None."""
    seen, i = set(), 0
    while i < len(tokens):
        key = tokens[i]
        if _quoted(tokens[i]) or key not in MATERIAL_FIELDS:
            return f"unknown MATERIAL field {_show(key)}"
        if key in seen:
            return f"MATERIAL field {_show(key)} given twice"
        seen.add(key)
        values = tokens[i + 1:i + 1 + MATERIAL_FIELDS[key]]
        if len(values) != MATERIAL_FIELDS[key]:
            return f"MATERIAL field {_show(key)} needs {MATERIAL_FIELDS[key]} number(s)"
        for t in values:
            problem = _float_problem(t)
            if problem:
                return f"MATERIAL field {_show(key)}: {problem}"
        i += 1 + MATERIAL_FIELDS[key]
    return None


def _show(token: str) -> str:
    """A token for an error message: quoted, escaped, at most 24 characters."""
    return repr(str(token) if len(token) <= 24 else token[:24] + "...")


def _float_problem(token: str) -> str | None:
    if _quoted(token) or not _FLOAT.fullmatch(token):
        return f"expected a number, got {_show(token)}"
    if not math.isfinite(float(token)):
        return f"number {_show(token)} is not finite"
    return None


@dataclass
class _Object:
    kind: str
    line: int
    name: str | None = None
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    rot: np.ndarray | None = None  # M, applied to row vectors: p' = p M
    loc: np.ndarray | None = None
    surfaces: list = field(default_factory=list)  # (refs, flags, mat, line)


class _Parser:
    """One pass over the lines of an AC3D file; builds the mesh's arrays."""

    def __init__(self, text: str, path, count_encoding: str):
        if text.startswith("\ufeff"):
            text = text[1:]
        self.text = text.replace("\r\n", "\n")
        self.path = path
        self.count_encoding = count_encoding
        self.lines = self.text.split("\n")
        self.i = 0  # index of the next line to read
        self._starts: list[int] | None = None     # offset of each line in text, when needed
        self.materials: list[Material] = []
        self.objects: list[str] = []
        self.vertex_blocks: list[np.ndarray] = []
        self.n_vertices = 0
        self.faces: list[np.ndarray] = []
        self.face_material: list[np.ndarray] = []
        self.face_flags: list[np.ndarray] = []
        self.face_object: list[np.ndarray] = []
        self.skipped_lines = 0

    # -- lines and tokens -------------------------------------------------------------

    def error(self, message: str, line: int | None) -> ModelError:
        return ModelError(message, path=self.path, line=line)

    def eof_line(self) -> int:
        """The line number just past the end of the file."""
        n = len(self.lines)
        return n if self.lines[-1] == "" else n + 1

    def next_tokens(self, what: str):
        """The next non-blank line as ``(line number, tokens)``."""
        while self.i < len(self.lines):
            line = self.lines[self.i]
            self.i += 1
            if line.strip(_SPACE):
                tokens = _tokenize(line)
                if isinstance(tokens, str):
                    raise self.error(tokens, self.i)
                return self.i, tokens
        raise self.error(f"unexpected end of file: expected {what}", self.eof_line())

    def at_end(self) -> bool:
        while self.i < len(self.lines) and not self.lines[self.i].strip(_SPACE):
            self.i += 1
        return self.i >= len(self.lines)

    def count(self, tokens, lineno: int, what: str) -> int:
        """The single non-negative integer after a token like ``numvert``."""
        if len(tokens) != 2:
            raise self.error(f"'{tokens[0]}' needs exactly one value", lineno)
        return self.integer(tokens[1], lineno, what)

    def integer(self, token: str, lineno: int, what: str) -> int:
        if _quoted(token) or not _INT.fullmatch(token):
            raise self.error(f"{what}: expected an integer, got {_show(token)}", lineno)
        if len(token) > MAX_DIGITS:
            raise self.error(f"{what}: integer {token[:20]}... is too large", lineno)
        value = int(token)
        if value < 0:
            raise self.error(f"{what} must not be negative, got {value}", lineno)
        return value

    def floats(self, tokens, lineno: int, what: str) -> list[float]:
        values = []
        for t in tokens:
            problem = _float_problem(t)
            if problem:
                raise self.error(f"{what}: {problem}", lineno)
            values.append(float(t))
        return values

    def values(self, tokens, lineno: int, k: int):
        """The ``k`` numbers after a keyword, as floats."""
        if len(tokens) != k + 1:
            raise self.error(f"'{tokens[0]}' needs {k} number(s), got "
                             f"{len(tokens) - 1}", lineno)
        return np.array(self.floats(tokens[1:], lineno, tokens[0]), dtype=np.float64)

    # -- file structure ---------------------------------------------------------------

    def parse(self):
        lineno, tokens = self.next_tokens("the AC3D header")
        if len(tokens) != 1 or _quoted(tokens[0]) or not _HEADER.fullmatch(tokens[0]):
            raise self.error("not an AC3D file: the first line must be 'AC3D' and a hex "
                             "version, e.g. 'AC3Db'", lineno)
        while not self.at_end():
            lineno, tokens = self.next_tokens("MATERIAL or OBJECT")
            key = tokens[0] if not _quoted(tokens[0]) else None
            if key == "MATERIAL":
                self.material(tokens, lineno)
            elif key == "OBJECT":
                self.object_tree(tokens, lineno)
            else:
                raise self.error(f"unknown token {_show(tokens[0])} (expected MATERIAL or "
                                 "OBJECT)", lineno)

    def material(self, tokens, lineno: int):
        if len(tokens) < 6 or _quoted(tokens[2]) or tokens[2] != "rgb":
            raise self.error("MATERIAL needs a name and 'rgb r g b'", lineno)
        rgb = np.array(self.floats(tokens[3:6], lineno, "MATERIAL rgb"))
        problem = _material_rest_problem(tokens[6:])
        if problem:
            raise self.error(problem, lineno)
        line = self.lines[lineno - 1]
        ends = _tokenize_with_ends(line)
        if isinstance(ends, str):                # cannot be: the line was tokenized
            raise self.error(ends, lineno)
        rest = line[ends[5][1]:].strip(_SPACE)
        self.materials.append(Material(name=str(tokens[1]), rgb=tuple(rgb.tolist()),
                                       rest=rest))

    def object_tree(self, tokens, lineno: int):
        """An object and all its descendants, depth first, in file order.

        ``stack`` holds, for each open parent, its chain of transforms and how
        many of its kids are still to be read. A chain is ``None`` (identity)
        or a link ``(rot, loc, parent_chain)``: extending it is O(1), so deep
        trees cost O(depth), not O(depth^2).
        """
        stack: list[list] = [[None, 1]]          # [chain, kids still to read] per parent
        first: tuple[list[str], int] | None = (tokens, lineno)
        while stack:
            chain, left = stack[-1]
            if left == 0:
                stack.pop()
                continue
            stack[-1][1] -= 1
            if first:
                tokens, lineno = first
                first = None
            else:
                lineno, tokens = self.next_tokens("a child OBJECT")
                if _quoted(tokens[0]) or tokens[0] != "OBJECT":
                    raise self.error(f"expected a child OBJECT, got {_show(tokens[0])}",
                                     lineno)
            obj, kids = self.object_body(tokens, lineno)
            if obj.rot is not None or obj.loc is not None:
                chain = (obj.rot, obj.loc, chain)
            self.finish_object(obj, chain)
            if kids:
                stack.append([chain, kids])

    def object_body(self, tokens, lineno: int):
        """The lines of one object up to and including ``kids``."""
        if len(tokens) != 2 or _quoted(tokens[1]) or tokens[1] not in OBJECT_TYPES:
            raise self.error("OBJECT needs one type: world, poly, group or light", lineno)
        obj = _Object(kind=str(tokens[1]), line=lineno)
        seen = set()
        while True:
            ln, t = self.next_tokens(f"'kids' to end the OBJECT at line {lineno}")
            key = t[0] if not _quoted(t[0]) else None
            if key == "kids":
                return obj, self.count(t, ln, "kids")
            if key in SKIPPED_TOKENS:
                continue
            if key in seen:
                raise self.error(f"'{key}' given twice in the OBJECT at line {lineno}", ln)
            seen.add(key)
            if key in ("name", "texture", "url"):
                if len(t) != 2:
                    raise self.error(f"'{key}' needs exactly one string", ln)
                if key == "name":
                    obj.name = str(t[1])
            elif key == "data":
                self.skip_data(self.count(t, ln, "data"), ln)
            elif key in ("texrep", "texoff"):
                self.values(t, ln, 2)
            elif key == "crease":
                self.values(t, ln, 1)
            elif key == "rot":
                obj.rot = self.values(t, ln, 9).reshape(3, 3)
            elif key == "loc":
                obj.loc = self.values(t, ln, 3)
            elif key == "numvert":
                obj.vertices = self.vertex_lines(self.count(t, ln, "numvert"), ln)
            elif key == "numsurf":
                for _ in range(self.count(t, ln, "numsurf")):
                    self.surface(obj, ln)
            else:
                raise self.error(f"unknown token {_show(t[0])} in OBJECT", ln)

    def vertex_lines(self, n: int, lineno: int) -> np.ndarray:
        rows = []
        for j in range(n):
            ln, t = self.next_tokens(f"vertex {j + 1} of {n} (numvert at line {lineno})")
            if len(t) != 3:
                raise self.error(f"a vertex needs 3 coordinates, got {len(t)}", ln)
            rows.append(self.floats(t, ln, "vertex coordinate"))
        return np.array(rows, dtype=np.float64).reshape(n, 3)

    def surface(self, obj: _Object, numsurf_line: int):
        ln, t = self.next_tokens(f"SURF (numsurf at line {numsurf_line})")
        if _quoted(t[0]) or t[0] != "SURF":
            raise self.error(f"expected SURF, got {_show(t[0])}", ln)
        if len(t) != 2 or _quoted(t[1]) or not _FLAGS.fullmatch(t[1]):
            raise self.error("SURF needs one flags value (decimal or 0x hex)", ln)
        if len(t[1]) > MAX_DIGITS:
            raise self.error(f"SURF flags {t[1][:20]}... are too large", ln)
        flags, surf_line = int(t[1], 0 if t[1][:2].lower() == "0x" else 10), ln
        if flags > np.iinfo(np.int64).max:
            raise self.error(f"SURF flags {t[1]} do not fit in 64 bits", ln)
        kind = flags & SURF_TYPE_MASK
        if kind not in (SURF_POLYGON, SURF_CLOSED_LINE, SURF_LINE):
            raise self.error(f"unknown surface type {kind} (flags {t[1]})", ln)
        mat = 0
        ln, t = self.next_tokens(f"'mat' or 'refs' of the SURF at line {surf_line}")
        if not _quoted(t[0]) and t[0] == "mat":
            mat = self.count(t, ln, "mat")
            if mat >= max(len(self.materials), 1):
                raise self.error(f"material index {mat} out of range: {len(self.materials)} "
                                 "MATERIAL line(s) so far", ln)
            ln, t = self.next_tokens(f"'refs' of the SURF at line {surf_line}")
        if _quoted(t[0]) or t[0] != "refs":
            raise self.error(f"expected 'refs', got {_show(t[0])}", ln)
        n, refs_line = self.count(t, ln, "refs"), ln
        refs = []
        for j in range(n):
            ln, t = self.next_tokens(f"ref {j + 1} of {n} (refs at line {refs_line})")
            if len(t) != 3:
                raise self.error(f"a ref needs 'index u v', got {len(t)} value(s)", ln)
            index = self.integer(t[0], ln, "vertex index")
            if index >= len(obj.vertices):
                raise self.error(f"vertex index {index} out of range: the object has "
                                 f"{len(obj.vertices)} vertices", ln)
            self.floats(t[1:], ln, "texture coordinate")
            refs.append(index)
        if kind != SURF_POLYGON:
            self.skipped_lines += 1
            return
        if n < 3:
            raise self.error(f"a polygon needs at least 3 refs, got {n}", refs_line)
        obj.surfaces.append((np.array(refs, dtype=np.int64), flags, mat, surf_line))

    def skip_data(self, n: int, lineno: int):
        """Skip the ``n``-byte blob that starts on the line after ``lineno``."""
        if self._starts is None:
            starts, offset = [], 0
            for line in self.lines:
                starts.append(offset)
                offset += len(line) + 1
            self._starts = starts
        starts = self._starts
        start = starts[self.i] if self.i < len(self.lines) else len(self.text)
        chunk = self.text[start:start + n]
        if chunk.isascii():
            end = start + n if len(chunk) == n else None
        else:
            end, total = None, 0
            for j, ch in enumerate(chunk):
                total += len(ch.encode(self.count_encoding, "surrogatepass"))
                if total >= n:
                    if total > n:
                        raise self.error(f"data count {n} ends inside a character", lineno)
                    end = start + j + 1
                    break
        if end is None:
            raise self.error(f"data count {n} runs past the end of the file", lineno)
        k = bisect.bisect_right(starts, end) - 1
        if starts[k] == end:
            self.i = k
        else:
            tail = self.text[end:starts[k] + len(self.lines[k])]
            if tail.strip(_SPACE):
                raise self.error(f"text after the {n} data bytes: {_show(tail.strip(_SPACE))}",
                                 k + 1)
            self.i = k + 1

    # -- assembling the mesh ------------------------------------------------------------

    def finish_object(self, obj: _Object, chain):
        """Move one object's vertices to world space and its polygons to triangles."""
        local = obj.vertices
        world = local
        with np.errstate(over="ignore", invalid="ignore"):  # overflow refused below
            while chain is not None and len(world):  # child first, up to the root
                rot, loc, chain = chain
                if rot is not None:
                    world = world @ rot
                if loc is not None:
                    world = world + loc
        if not np.isfinite(world).all():
            raise self.error("a vertex's world coordinates overflow (not finite) after "
                             "applying rot/loc", obj.line)
        triangles, material, flags = [], [], []
        for refs, surf_flags, mat, _ in obj.surfaces:
            tri = refs[None, :] if len(refs) == 3 else refs[ear_clip(local[refs])]
            triangles.append(tri)
            material.append(np.full(len(tri), mat, dtype=np.int64))
            flags.append(np.full(len(tri), surf_flags, dtype=np.int64))
        if obj.kind != "poly" and not triangles:
            return
        index = len(self.objects)
        self.objects.append(obj.name if obj.name is not None else obj.kind)
        if triangles:
            tri = np.concatenate(triangles) + self.n_vertices
            self.faces.append(tri)
            self.face_material.append(np.concatenate(material))
            self.face_flags.append(np.concatenate(flags))
            self.face_object.append(np.full(len(tri), index, dtype=np.int64))
        self.vertex_blocks.append(world)
        self.n_vertices += len(world)

    def mesh(self, weld_tolerance: float) -> Mesh:
        if not self.faces:
            raise self.error("the file has no polygon surfaces (no triangles)", None)
        if self.skipped_lines:
            warnings.warn(ModelWarning(
                f"{self.path or '<ac3d>'}: skipped {self.skipped_lines} line surface(s) "
                "(SURF types 1 and 2 have no area)"), stacklevel=5)   # read_ac3d's caller
        name = Path(self.path).stem if self.path is not None else None
        return Mesh(np.concatenate(self.vertex_blocks), np.concatenate(self.faces),
                    weld_tolerance=weld_tolerance,
                    face_material=np.concatenate(self.face_material),
                    face_flags=np.concatenate(self.face_flags),
                    face_object=np.concatenate(self.face_object),
                    materials=self.materials, objects=self.objects, name=name,
                    source=None if self.path is None else str(self.path))


def parse_ac3d(text: str, path=None, *, weld_tolerance: float = 0.0) -> Mesh:
    """Parse the text of an AC3D file into one :class:`Mesh`.

    Parameters
    ----------
    text : str
        The whole file. ``data`` counts are taken as UTF-8 bytes.
    path : str or PathLike, optional
        Named in error messages; its stem becomes the mesh's name.
    weld_tolerance : float
        Passed to :class:`Mesh` (0 welds exactly equal vertices).

    Raises
    ------
    ModelError
        For any malformed file, naming ``path`` and the 1-based line.
    """
    return _parse(text, path, weld_tolerance, "utf-8")


def _parse(text: str, path, weld_tolerance: float, count_encoding: str) -> Mesh:
    parser = _Parser(text, path, count_encoding)
    parser.parse()
    return parser.mesh(weld_tolerance)


def read_ac3d(path, *, weld_tolerance: float = 0.0) -> Mesh:
    """Read an AC3D file (seed S1): its polygons triangulated, its objects,
    materials and surface flags kept per triangle, welded to shared-vertex form.

    Parameters
    ----------
    path : str or PathLike
        UTF-8 text, or Latin-1 when it is not valid UTF-8.
    weld_tolerance : float
        Passed to :class:`Mesh`: 0 welds exactly equal vertices only.

    Returns
    -------
    Mesh
        ``vertices`` (n, 3) float64, ``faces`` (m, 3) int64 and per-face
        ``face_material``, ``face_flags``, ``face_object`` (m,).

    Raises
    ------
    ModelError
        Naming the file and, for a malformed file, the line; a directory,
        FIFO or device is refused without being opened.
    """
    return parse_ac3d_bytes(read_regular_file(path, ModelError), path,
                            weld_tolerance=weld_tolerance)


def parse_ac3d_bytes(raw: bytes, path, *, weld_tolerance: float = 0.0) -> Mesh:
    """:func:`read_ac3d` of the bytes ``raw`` already read from ``path``
    (which names the file in messages)."""
    try:
        return _parse(raw.decode("utf-8"), path, weld_tolerance, "utf-8")
    except UnicodeDecodeError:
        return _parse(raw.decode("latin-1"), path, weld_tolerance, "latin-1")


# -- writing ----------------------------------------------------------------------------


def _quote_name(name, what: str) -> str:
    if not isinstance(name, str):
        raise ModelError(f"{what} must be a string, got {type(name).__name__}")
    if any(c in name for c in '"\n\r'):
        raise ModelError(f"{what} {name!r} cannot be written to AC3D: it contains a quote "
                         "or a line break")
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        raise ModelError(f"{what} {name!r} is not encodable as UTF-8") from None
    return f'"{name}"'


def _material_line(material: Material) -> str:
    name = _quote_name(material.name, "material name")
    rgb = [float(c) for c in material.rgb]
    if len(rgb) != 3 or not np.isfinite(rgb).all():
        raise ModelError(f"material {material.name!r}: rgb must be 3 finite numbers")
    rest = str(material.rest).strip(_SPACE)
    tokens = _tokenize(rest) if "\n" not in rest else "a line break"
    problem = tokens if isinstance(tokens, str) else _material_rest_problem(tokens)
    if problem:
        raise ModelError(f"material {material.name!r}: cannot write its rest "
                         f"{material.rest!r}: {problem}")
    r, g, b = rgb
    return f"MATERIAL {name} rgb {r!r} {g!r} {b!r}  {rest}".rstrip(_SPACE)


def format_ac3d(mesh: Mesh) -> str:
    """The AC3D text of ``mesh``; :func:`parse_ac3d` reads it back exactly.

    Raises
    ------
    ModelError
        When the mesh holds something AC3D cannot carry: a name with a quote or
        line break, a material or object index out of range, or ``face_flags``
        that are negative or name a non-polygon surface type.
    """
    faces, flags = mesh.faces, mesh.face_flags
    n_objects, n_materials = len(mesh.objects), len(mesh.materials)
    if mesh.n_faces and (mesh.face_object.min() < 0 or mesh.face_object.max() >= n_objects):
        raise ModelError(f"face_object out of range [0, {n_objects})", path=mesh.source)
    if mesh.n_faces and (mesh.face_material.min() < 0
                         or mesh.face_material.max() >= n_materials):
        raise ModelError(f"face_material out of range [0, {n_materials})", path=mesh.source)
    if (flags < 0).any() or (flags & SURF_TYPE_MASK).any():
        raise ModelError("face_flags must be >= 0 with surface type 0 (polygon) in the low "
                         "4 bits", path=mesh.source)
    if (np.diff(mesh.face_object) < 0).any():
        warnings.warn(ModelWarning(
            "face_object is not sorted: AC3D groups faces by object, so the written file "
            "lists the faces in a different order"), stacklevel=2)

    # Which faces and vertices each object holds.
    members = [np.flatnonzero(mesh.face_object == k) for k in range(n_objects)]
    used = [np.unique(faces[f]) for f in members]
    order = np.concatenate(used)
    _, first = np.unique(order, return_index=True)
    if not (np.diff(first) > 0).all():
        # Reading keeps vertices in order of first appearance: let the first
        # object introduce them all, in index order.
        used[0] = np.arange(mesh.n_vertices)

    lines = [HEADER]
    lines += [_material_line(m) for m in mesh.materials]
    lines += ["OBJECT world", f"kids {n_objects}"]
    for k, name in enumerate(mesh.objects):
        lines += ["OBJECT poly", f"name {_quote_name(name, 'object name')}",
                  f"numvert {len(used[k])}"]
        lines += [f"{x!r} {y!r} {z!r}" for x, y, z in mesh.vertices[used[k]].tolist()]
        local = np.searchsorted(used[k], faces[members[k]]).tolist()
        lines.append(f"numsurf {len(members[k])}")
        for (a, b, c), f, m in zip(local, flags[members[k]].tolist(),
                                   mesh.face_material[members[k]].tolist(), strict=True):
            lines += [f"SURF {f:#x}", f"mat {m}", "refs 3", f"{a} 0 0", f"{b} 0 0", f"{c} 0 0"]
        lines.append("kids 0")
    return "\n".join(lines) + "\n"


def write_ac3d(mesh: Mesh, path) -> None:
    """Write ``mesh`` to ``path`` as AC3D, atomically; :func:`read_ac3d`
    reads back the same mesh, bit for bit.

    Parameters
    ----------
    mesh : Mesh
    path : str or PathLike
        A symlink is written through; a directory, FIFO or device is refused
        (:mod:`refsim.storage.writing`).

    Raises
    ------
    ModelError
        A mesh AC3D cannot hold (a name with a quote, say), naming it.
    OutputError
        The file cannot be written.

    Notes
    -----
    The text is formatted first (a mesh AC3D cannot hold raises before any
    file is touched), then written by :func:`refsim.storage.writing.write_text_atomic`: a
    reader sees the old file or the new one, never half of one.
    """
    text = format_ac3d(mesh)
    try:
        write_text_atomic(path, text)
    except OSError as exc:
        raise ModelError(f"cannot write the file: {exc.strerror or exc}", path=path) from None
