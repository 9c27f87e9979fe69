"""Readable refusals of gmsh ``.msh`` files that meshio cannot read (issue 18, item 5).

meshio reports a broken file as raw Python text ("list index out of range", "99", "invalid literal
for int() with base 10") or only prints a warning. When it fails, :func:`gmsh_read_error` scans the
ASCII file itself (formats 2.2 and 4.1: the sections, the node and element lines) for the first
line that is wrong and returns a MeshError naming the file, that line and what it should hold, with
the fix; where no line can be named (a binary file) it names the file, meshio's reason and the fix.
:func:`read_gmsh_data` is meshio's reading with these refusals, for the 2D and the 3D reader.
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import meshio.gmsh

from vemkit.exceptions import MeshError

#: nodes of each gmsh element type (gmsh reference manual, "MSH file format": element types)
NODES_PER_TYPE = {
    1: 2,
    2: 3,
    3: 4,
    4: 4,
    5: 8,
    6: 6,
    7: 5,
    8: 3,
    9: 6,
    10: 9,
    11: 10,
    12: 27,
    13: 18,
    14: 14,
    15: 1,
    16: 8,
    17: 20,
    18: 15,
    19: 13,
    20: 9,
    21: 10,
    22: 12,
    23: 15,
    24: 15,
    25: 21,
    26: 4,
    27: 5,
    28: 6,
    29: 20,
    30: 35,
    31: 56,
    92: 64,
    93: 125,
}
FIX = "fix that line, or export the mesh again from gmsh as ASCII (format 2.2 or 4.1)"


class _Problem(Exception):
    def __init__(self, index: int, text: str):
        super().__init__(text)
        self.line, self.text = index + 1, text


def read_gmsh_data(path):
    """meshio's reading of a gmsh file (2D or 3D; not meshio.read: on a broken file it prints and
    exits the process), its warnings kept off the terminal; a file it cannot read, or whose section
    it finds unclosed, is a MeshError naming the file, the line and the fix (``gmsh_read_error``).
    A MemoryError passes (the caller's memory budget reports it)."""
    path = Path(path)
    notes: list = []
    with meshio_warnings(notes):
        try:
            data = meshio.gmsh.read(path)
        except MemoryError:
            raise
        except Exception as error:  # meshio's raw Python text: located and explained instead
            raise gmsh_read_error(path, " ".join(str(error).split()) or type(error).__name__) from None
    unclosed = [note for note in notes if "not closed" in note]
    if unclosed:
        raise gmsh_read_error(path, unclosed[0])
    return data


def gmsh_read_error(path, reason: str) -> MeshError:
    """The MeshError for a gmsh file meshio could not read (``reason``: meshio's own words)."""
    path = Path(path)
    try:
        found = _first_problem(path.read_bytes().decode("utf-8", "replace").splitlines())
    except OSError:
        found = None
    if found is None:
        return MeshError(
            f"{path.name}: cannot be read as gmsh ({reason[:160]}); check that gmsh opens it and "
            "export it again as ASCII (format 2.2 or 4.1)",
            key=str(path),
        )
    return MeshError(f"{path.name}, line {found.line}: {found.text}; {FIX}", key=str(path))


#: files larger than this are not scanned for their largest node number (the message then names the file)
SCAN_BYTES = 64 << 20


def largest_node_tag(path) -> tuple[int, int] | None:
    """(line, number) of the largest node number of an ASCII gmsh file (2.2 or 4.1), or None: what
    makes meshio allocate a table of that many entries."""
    path = Path(path)
    try:
        if path.stat().st_size > SCAN_BYTES:
            return None
        lines = path.read_bytes().decode("utf-8", "replace").splitlines()
        sections = {name: (start, end) for name, start, end in _sections(lines)}
        version = _format(lines, *sections["MeshFormat"])
        start, end = sections["Nodes"]
        if version is None:
            return None
        if version < 4:
            rows = range(start + 1, end)
        else:
            rows, i = [], start + 1
            while i < end:
                n = int(lines[i].split()[3])
                rows += range(i + 1, i + 1 + n)
                i += 1 + 2 * n
        line = max(rows, key=lambda k: int(lines[k].split()[0]))
        return line + 1, int(lines[line].split()[0])
    except (_Problem, KeyError, IndexError, ValueError, OSError):
        return None


def _first_problem(lines: list) -> _Problem | None:
    version = None
    tags: set = set()
    try:
        for name, start, end in _sections(lines):
            if name == "MeshFormat":
                version = _format(lines, start, end)
                if version is None:
                    return None  # binary: no lines to name
            elif name == "Nodes" and version is not None:
                tags = (_nodes_2 if version < 4 else _nodes_4)(lines, start, end)
            elif name == "Elements" and version is not None:
                (_elements_2 if version < 4 else _elements_4)(lines, start, end, tags)
    except _Problem as problem:
        return problem
    return None


def _show(text: str) -> str:
    text = text.strip()
    return repr(text if len(text) <= 40 else text[:37] + "...")


def _sections(lines):
    """(name, first body line, closing line) of each ``$Name ... $EndName`` section."""
    i = 0
    while i < len(lines):
        head = lines[i].strip()
        if not head:
            i += 1
            continue
        if not head.startswith("$") or head.startswith("$End"):
            raise _Problem(i, f"expected a section such as $Nodes, found {_show(head)}")
        j = i + 1
        while j < len(lines) and not lines[j].strip().startswith("$"):
            j += 1
        if j == len(lines):
            raise _Problem(len(lines) - 1, f"the file ends inside {head} (no $End{head[1:]}): it is truncated")
        if lines[j].strip() != f"$End{head[1:]}":
            raise _Problem(j, f"{head} (line {i + 1}) is not closed by $End{head[1:]}; found {_show(lines[j])}")
        yield head[1:], i + 1, j
        i = j + 1


def _numbers(lines, index: int, what: str, count=None, kind=int) -> list:
    fields = lines[index].split()
    try:
        values = [kind(f) for f in fields]
    except ValueError:
        raise _Problem(
            index, f"{what} must be {'integers' if kind is int else 'numbers'}, found {_show(lines[index])}"
        ) from None
    if count is not None and len(values) != count:
        raise _Problem(
            index,
            f"{what} has {count} {'integers' if kind is int else 'numbers'}, found "
            f"{len(values)} ({_show(lines[index])})",
        )
    return values


def _format(lines, start: int, end: int):
    if end == start:
        raise _Problem(start, "$MeshFormat holds 'version file-type data-size', e.g. '2.2 0 8'")
    fields = lines[start].split()
    try:
        version, binary = float(fields[0]), int(fields[1])
    except (ValueError, IndexError):
        raise _Problem(
            start, f"the format line is 'version file-type data-size', e.g. '2.2 0 8', found {_show(lines[start])}"
        ) from None
    if int(version) not in (2, 4):
        raise _Problem(start, f"gmsh format {version:g}; vemkit reads 2.2 and 4.1")
    return None if binary else version


def _body(lines, start: int, end: int, what: str) -> tuple[int, int]:
    """The declared count (first body line) and the index of the first entry."""
    if end == start:
        raise _Problem(start, f"${what} is empty: its first line is the count")
    return _numbers(lines, start, f"the ${what} header")[0], start + 1


def _nodes_2(lines, start: int, end: int) -> set:
    count, first = _body(lines, start, end, "Nodes")
    if end - first != count:
        raise _Problem(start, f"$Nodes declares {count} nodes but lists {end - first}")
    tags = set()
    for i in range(first, end):
        tag, *_ = _numbers(lines, i, "a node line 'tag x y z'", 4, float)
        tags.add(int(tag))
    return tags


def _element(lines, i: int, kind: int, nodes: list, tags: set) -> None:
    if kind not in NODES_PER_TYPE:
        raise _Problem(i, f"element type {kind} is not a gmsh element type (1: line, 2: triangle, 3: quadrangle)")
    if len(nodes) != NODES_PER_TYPE[kind]:
        raise _Problem(i, f"an element of type {kind} has {NODES_PER_TYPE[kind]} nodes, found {len(nodes)}")
    missing = [n for n in nodes if n not in tags]
    if tags and missing:
        raise _Problem(i, f"the element uses node {missing[0]}, which $Nodes does not declare")


def _elements_2(lines, start: int, end: int, tags: set) -> None:
    count, first = _body(lines, start, end, "Elements")
    for i in range(first, end):
        fields = _numbers(lines, i, "an element line 'tag type ntags tags... nodes...'")
        if len(fields) < 3 or len(fields) < 3 + fields[2]:
            raise _Problem(i, f"an element line is 'tag type ntags tags... nodes...', found {_show(lines[i])}")
        _element(lines, i, fields[1], fields[3 + fields[2] :], tags)
    if end - first != count:
        raise _Problem(start, f"$Elements declares {count} elements but lists {end - first}")


def _nodes_4(lines, start: int, end: int) -> set:
    _numbers(lines, start, "the $Nodes header 'blocks nodes min-tag max-tag'", 4)
    tags, i = set(), start + 1
    while i < end:
        _dim, _entity, parametric, n = _numbers(lines, i, "a node block header 'dim entity parametric count'", 4)
        if i + 1 + 2 * n > end:
            raise _Problem(i, f"the node block declares {n} nodes but $Nodes ends before them")
        tags.update(_numbers(lines, j, "a node tag line", 1)[0] for j in range(i + 1, i + 1 + n))
        for j in range(i + 1 + n, i + 1 + 2 * n):
            _numbers(lines, j, "a node line 'x y z'", None, float)
        i += 1 + 2 * n
    return tags


def _elements_4(lines, start: int, end: int, tags: set) -> None:
    _numbers(lines, start, "the $Elements header 'blocks elements min-tag max-tag'", 4)
    i = start + 1
    while i < end:
        _dim, _entity, kind, n = _numbers(lines, i, "an element block header 'dim entity type count'", 4)
        if i + 1 + n > end:
            raise _Problem(i, f"the element block declares {n} elements but $Elements ends before them")
        for j in range(i + 1, i + 1 + n):
            _element(lines, j, kind, _numbers(lines, j, "an element line 'tag nodes...'")[1:], tags)
        i += 1 + n


@contextmanager
def meshio_warnings(notes: list):
    """meshio's gmsh warnings collected in ``notes`` instead of printed on the terminal."""
    modules = [
        m
        for m in vars(meshio.gmsh).values()
        if hasattr(m, "warn") and callable(m.warn) and getattr(m, "__name__", "").startswith("meshio.gmsh")
    ]
    saved = [(m, m.warn) for m in modules]
    for module in modules:
        module.warn = lambda text, *args, **kwargs: notes.append(str(text))
    try:
        yield notes
    finally:
        for module, warn in saved:
            module.warn = warn
