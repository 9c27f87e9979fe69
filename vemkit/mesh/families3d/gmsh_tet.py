"""Quality Delaunay tetrahedra of a box or an extruded 2D domain, made by gmsh (docs/reference/files.md, family ``tet``).

``delaunay_tet(n, box=..., sides=...)`` meshes a box; ``delaunay_tet_extruded(n, body)`` an
:class:`~vemkit.config.domain3d.Extruded` body (its base polygon with circle arcs and circular or
polygonal holes, extruded along z to its depth). gmsh's OpenCASCADE kernel builds the geometry
(arcs as circle arcs, circles as circles: the mesh's boundary vertices lie on the curved sides),
its 3D Delaunay mesher fills it and (``optimize=True``, the default) its optimizer improves the
worst tetrahedra by moves and swaps: measured radius ratios (3 x inradius / circumradius) >= 0.24
and dihedral angles within 12 ... 159 degrees on 10⁵ cells, at the price of about 1.3 % of the
interior faces no longer locally Delaunay. ``optimize=False`` keeps gmsh's Delaunay mesh as it is
(at most 0.03 % of the faces, next to the boundary, not locally Delaunay: the mesh is constrained
by the boundary triangles) with its slivers (radius ratios down to 0.015, dihedral angles 0.8 ...
179 degrees). tests/mesh3d/test_tet_gmsh.py checks both. 10⁵ cells take about 4 s of CPU (gmsh: 85 %).

Size: the target edge length is ``EDGE_PER_N / n`` (``EDGE_PER_N`` fitted so that the interior has
6 n³ tetrahedra per unit volume, as many as the Kuhn tetrahedra of the n-grid; ``h`` = 1 / n as for
every 3D family, so the edges are about 0.89 h; a body thinner than that gets flat tetrahedra:
prefer the prism families there); near the boundary
the tetrahedra are a little smaller, so a body of volume V and surface A has about
``6 n³ V + BOUNDARY_CELLS n² A`` of them (``tet_counts``, the prediction of ``resources.py``).
Curved sides get at least ``CURVATURE_ELEMENTS`` edges per full circle.

Naming: the box's faces by ``sides``; on an extruded body every lateral face by the 2D side name
of the base curve it is swept from, the end faces z = 0 and z = depth by ``ends``.

gmsh runs inside ``gmsh_session``: no terminal output, no files, its SIGINT handler not installed,
finalized after use (a session the caller opened is left open: vemkit's model removed, the
caller's current model and the options vemkit set restored);
any gmsh failure becomes a one-line ``MeshError``, and so does a missing or unloadable gmsh.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import replace
from itertools import count

import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import csr_rows, from_face_soup

#: target edge length x n: gmsh's Delaunay tetrahedra at edge length l fill a unit volume with about
#: 4.28 / l³ of them away from the boundary, so l = (4.28 / 6)^(1/3) / n. This and the counts below
#: are least-squares fits (relative) on 14 meshes of 1.9 10³ ... 2.1 10⁵ cells: cubes, a flat box
#: 1 x 1 x 0.2, an extruded plate with an arc and a circular hole, an extruded annulus
EDGE_PER_N = 0.8935
#: extra cells per n² unit area of boundary (the smaller tetrahedra at the surface)
BOUNDARY_CELLS = 1.965
#: boundary triangles per n² unit area, and vertices per cell and per boundary triangle
BOUNDARY_FACES = 3.112
VERTICES_PER_CELL = 0.1553
VERTICES_PER_BOUNDARY_FACE = 0.2902
#: fewest mesh edges along a full circle (the 2D families' MIN_CIRCLE_VERTICES)
CURVATURE_ELEMENTS = 8
#: the faces of a positively oriented tetrahedron (a, b, c, d), outward
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
#: gmsh's linear tetrahedron and triangle element types
GMSH_TET, GMSH_TRIANGLE = 4, 2
INSTALL_HINT = "install it with pip install gmsh (on Debian it needs libglu1-mesa libxcursor1 libxft2 libxinerama1)"

_models = count()


def import_gmsh():
    """The gmsh module; a one-line MeshError when it is missing or its library cannot be loaded."""
    try:
        import gmsh
    except ImportError as error:  # OSError of a missing shared library surfaces as ImportError too
        reason = " ".join(str(error).split())[:160]
        raise MeshError(
            f"mesh family tet (kind delaunay) needs the gmsh Python package: {reason}; {INSTALL_HINT} "
            "(kind structured needs no gmsh)",
            key="discretization.mesh.family",
        ) from None
    except OSError as error:
        raise MeshError(
            f"mesh family tet: the gmsh library cannot be loaded ({error}); {INSTALL_HINT}",
            key="discretization.mesh.family",
        ) from None
    return gmsh


#: the gmsh options vemkit sets (restored afterwards in a session the caller opened)
SESSION_OPTIONS = {"General.Terminal": 0, "General.Verbosity": 1, "General.NumThreads": 1}


def _mesh_options(edge: float, optimize: bool = True) -> dict:
    return {
        "Mesh.Optimize": int(bool(optimize)),
        "Mesh.MeshSizeMax": edge,
        "Mesh.MeshSizeMin": 0.0,
        "Mesh.MeshSizeFromPoints": 0,
        "Mesh.MeshSizeExtendFromBoundary": 1,
        "Mesh.MeshSizeFromCurvature": CURVATURE_ELEMENTS,
        "Mesh.Algorithm": 6,  # Frontal-Delaunay surfaces
        "Mesh.Algorithm3D": 1,  # Delaunay
        "Mesh.ElementOrder": 1,
    }


@contextmanager
def gmsh_session(what: str, edge: float, optimize: bool = True):
    """A fresh gmsh model, silent, with the mesh options for target edge length ``edge``; every gmsh
    exception inside becomes a one-line MeshError on ``what``."""
    gmsh = import_gmsh()
    owner = not gmsh.isInitialized()
    name = f"vemkit_tet_{next(_models)}"
    options = {**SESSION_OPTIONS, **_mesh_options(edge, optimize)}
    saved, previous = {}, None
    try:
        if owner:
            gmsh.initialize([], readConfigFiles=False, interruptible=False)
        else:
            saved = {key: gmsh.option.getNumber(key) for key in options}
            previous = gmsh.model.getCurrent()
        for key, value in options.items():
            gmsh.option.setNumber(key, value)
        gmsh.model.add(name)
        yield gmsh
    except MeshError:
        raise
    except Exception as error:
        reason = " ".join(str(error).split())[:200] or type(error).__name__
        raise MeshError(
            f"{what}: gmsh failed ({reason}); try another mesh size, or check the domain", key="discretization.mesh"
        ) from None
    finally:
        if gmsh.isInitialized():
            try:
                if owner:
                    gmsh.finalize()
                else:
                    if name in gmsh.model.list():
                        gmsh.model.setCurrent(name)
                        gmsh.model.remove()
                    if previous:
                        gmsh.model.setCurrent(previous)
                    for key, value in saved.items():
                        gmsh.option.setNumber(key, value)
            except Exception:  # pragma: no cover - nothing left to clean up
                pass


def _flag(optimize) -> bool:
    if not isinstance(optimize, (bool, np.bool_)):
        raise MeshError(f"tet option optimize = {optimize!r}: give true or false", key="discretization.mesh.optimize")
    return bool(optimize)


def edge_length(n: float) -> float:
    if not n > 0:
        raise MeshError(f"mesh n = {n}: the number of cells per unit length must be > 0", key="discretization.mesh.n")
    return EDGE_PER_N / float(n)


def _delaunay_meta(n, optimize, **body) -> dict:
    """The ``meta`` of a gmsh tet mesh of ``body`` (its own entries: the box, or the extruded body's):
    ``n``, its edge length (``edge_length``) and the checked ``optimize`` flag."""
    optimize = _flag(optimize)
    edge = edge_length(n)
    return {"family": "tet", "kind": "delaunay", "n": n, "edge": edge, **body, "mesher": "gmsh", "optimize": optimize}


def tet_counts(n: float, volume: float, area: float) -> tuple:
    """(cells, vertices, faces) predicted for a body of ``volume`` and surface ``area`` (module doc)."""
    n = float(n)
    cells = 6.0 * n**3 * volume + BOUNDARY_CELLS * n**2 * area
    boundary = BOUNDARY_FACES * n**2 * area
    vertices = VERTICES_PER_CELL * cells + VERTICES_PER_BOUNDARY_FACE * boundary
    return max(1, int(round(cells))), max(4, int(round(vertices))), max(4, int(round(2.0 * cells + 0.5 * boundary)))


def n_for_cells(cells: float, volume: float, area: float) -> float:
    """The n whose predicted cell count is ``cells`` (the cubic of ``tet_counts`` solved by bisection)."""
    lo, hi = 0.0, (float(cells) / (6.0 * volume)) ** (1.0 / 3.0) + 1.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 6.0 * mid**3 * volume + BOUNDARY_CELLS * mid**2 * area < cells else (lo, mid)
    return hi


def _collect(gmsh, surface_names: dict, meta: dict) -> PolyhedralMesh:
    """The PolyhedralMesh of the current gmsh model's tetrahedra, boundary faces named by surface."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    tags = np.asarray(tags, dtype=np.int64)
    points = np.asarray(coords, dtype=float).reshape(-1, 3)
    index = np.full(int(tags.max()) + 1 if tags.size else 1, -1, dtype=np.int64)
    index[tags] = np.arange(tags.size)
    types, _, nodes = gmsh.model.mesh.getElements(3)
    blocks = [np.asarray(nd, np.int64).reshape(-1, 4) for t, nd in zip(types, nodes) if t == GMSH_TET]
    other = [t for t in types if t != GMSH_TET]
    if other or not blocks:
        raise MeshError(
            f"gmsh made {'no tetrahedra' if not blocks else f'elements of type {other[0]}'}; "
            "expected linear tetrahedra only",
            key="discretization.mesh",
        )
    tets = index[np.concatenate(blocks)]
    used = np.unique(tets)
    renumber = np.full(points.shape[0], -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    tets, points = renumber[tets], points[used]
    p = points[tets]
    det = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
    tets[det < 0] = tets[det < 0][:, [0, 2, 1, 3]]
    m = tets.shape[0]
    mesh = from_face_soup(points, np.full(m, 4), np.full(4 * m, 3), tets[:, TET_FACES].ravel(), None, (), meta)
    names = list(dict.fromkeys(surface_names.values()))
    keys, labels = [], []
    for surface, name in surface_names.items():
        types, _, nodes = gmsh.model.mesh.getElements(2, surface)
        for t, nd in zip(types, nodes):
            if t == GMSH_TRIANGLE:
                tri = renumber[index[np.asarray(nd, np.int64).reshape(-1, 3)]]
                keys.append(np.sort(tri, axis=1))
                labels.append(np.full(tri.shape[0], names.index(name)))
    bf = mesh.boundary_faces
    faces = np.sort(csr_rows(mesh.face_offsets, mesh.face_vertices)[bf], axis=1)
    label = _match_rows(
        faces,
        np.concatenate(keys) if keys else np.zeros((0, 3), np.int64),
        np.concatenate(labels) if labels else np.zeros(0, np.int64),
    )
    if (label < 0).any():
        f = int(bf[np.flatnonzero(label < 0)[0]])
        raise MeshError(
            f"gmsh's mesh has boundary face {f} on no surface of the body (a hole or a crack in its "
            "volume mesh); try another mesh size",
            key="discretization.mesh",
        )
    parts = {name: bf[label == k] for k, name in enumerate(names)}
    return replace(mesh, boundary=parts, meta=meta)


def _match_rows(rows: np.ndarray, keys: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """The label of the row of ``keys`` equal to each row of ``rows`` (-1 where none is)."""
    both = np.concatenate([rows, keys])
    order = np.lexsort(both.T[::-1])
    s = both[order]
    same = np.zeros(order.size, dtype=bool)
    same[1:] = (s[1:] == s[:-1]).all(axis=1)
    out = np.full(rows.shape[0], -1, dtype=np.int64)
    # a mesh row followed by its equal key row (or the reverse): lexsort is stable, so rows come first
    hit = np.flatnonzero(same)
    a, b = order[hit - 1], order[hit]
    first = (a < rows.shape[0]) & (b >= rows.shape[0])
    out[a[first]] = labels[b[first] - rows.shape[0]]
    return out


def delaunay_tet(
    n=None,
    box=((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)),
    sides=("left", "right", "front", "back", "bottom", "top"),
    optimize: bool = True,
) -> PolyhedralMesh:
    """gmsh's quality Delaunay tetrahedra of the box, at edge length ``EDGE_PER_N / n`` (module doc)."""
    lower, upper = (np.asarray(b, dtype=float) for b in box)
    meta = _delaunay_meta(n, optimize, box=[lower.tolist(), upper.tolist()])
    edge, optimize = meta["edge"], meta["optimize"]
    with gmsh_session("mesh family tet on the box", edge, optimize) as gmsh:
        occ = gmsh.model.occ
        occ.addBox(*lower.tolist(), *(upper - lower).tolist())
        occ.synchronize()
        scale = 1e-6 * float(np.max(upper - lower))
        names = {}
        for _, surface in gmsh.model.getEntities(2):
            lo_hi = np.asarray(gmsh.model.getBoundingBox(2, surface)).reshape(2, 3)
            flat = int(np.argmin(lo_hi[1] - lo_hi[0]))
            side = 2 * flat + int(abs(lo_hi[0, flat] - upper[flat]) < scale + 1e-7 * abs(upper[flat]))
            names[surface] = side  # the box face's index: named (and snapped) below
        gmsh.model.mesh.generate(3)
        mesh = _collect(gmsh, names, meta)
    return _box_snapped(mesh, lower, upper, sides)


def _box_snapped(mesh: PolyhedralMesh, lower, upper, sides) -> PolyhedralMesh:
    """Boundary vertices put exactly on their box planes (gmsh's coordinates can be off by round-off), so
    the volumes sum to the box's to round-off; the parts (keyed by the box face's index 0 ... 5) get
    their names, in the sides' order (a name given twice: one part)."""
    vertices = mesh.vertices.copy()
    parts = {name: np.zeros(0, np.int64) for name in dict.fromkeys(sides)}
    for k, name in enumerate(sides):
        part = mesh.boundary.get(str(k), np.zeros(0, np.int64))
        ids = np.unique(mesh.face_vertices[(mesh.face_offsets[part][:, None] + np.arange(3)).ravel()])
        vertices[ids, k // 2] = (lower, upper)[k % 2][k // 2]
        parts[name] = np.sort(np.concatenate([parts[name], part]))
    return replace(mesh, vertices=vertices, boundary=parts)


def delaunay_tet_extruded(n, body, optimize: bool = True) -> PolyhedralMesh:
    """gmsh's quality Delaunay tetrahedra of an extruded 2D body (``Extruded``; module doc)."""
    from vemkit.config.domain import CircleHole

    base, depth, ends = body.base, float(body.depth), tuple(body.ends)
    meta = _delaunay_meta(n, optimize, depth=depth, ends=list(ends), base=base.to_spec())
    edge, optimize = meta["edge"], meta["optimize"]
    with gmsh_session("mesh family tet on the extruded domain", edge, optimize) as gmsh:
        occ = gmsh.model.occ
        curve_names = {}

        def ring(corners, names, arcs=()):
            ids = [occ.addPoint(float(x), float(y), 0.0) for x, y in corners]
            curves = []
            for i, name in enumerate(names):
                a, b = ids[i], ids[(i + 1) % len(ids)]
                centre = arcs[i] if arcs else None
                if centre is None:
                    curve = occ.addLine(a, b)
                else:
                    c = occ.addPoint(float(centre[0]), float(centre[1]), 0.0)
                    curve = occ.addCircleArc(a, c, b)
                curve_names[curve] = name
                curves.append(curve)
            return occ.addCurveLoop(curves)

        loops = [ring(base.polygon, base.sides, base.arcs)]
        for hole in base.holes:
            if isinstance(hole, CircleHole):
                curve = occ.addCircle(hole.cx, hole.cy, 0.0, hole.r)
                curve_names[curve] = hole.side
                loops.append(occ.addCurveLoop([curve]))
            else:
                loops.append(ring(hole.polygon, hole.sides))
        surface = occ.addPlaneSurface(loops)
        swept = occ.extrude([(2, surface)], 0.0, 0.0, depth)
        occ.synchronize()
        names = {surface: ends[0]}
        top = [tag for dim, tag in swept if dim == 2][0]
        names[top] = ends[1]
        for dim, tag in swept:
            if dim != 2 or tag == top:
                continue
            bounding = [abs(c) for d, c in gmsh.model.getBoundary([(2, tag)], oriented=False) if d == 1]
            found = [curve_names[c] for c in bounding if c in curve_names]
            if not found:
                raise MeshError(
                    "mesh family tet: a lateral face of the extruded body has no base curve (gmsh "
                    "renumbered the geometry); report this domain",
                    key="domain",
                )
            names[tag] = found[0]
        gmsh.model.mesh.generate(3)
        mesh = _collect(gmsh, names, meta)
    return _ends_snapped(mesh, depth, ends)


def _ends_snapped(mesh: PolyhedralMesh, depth: float, ends) -> PolyhedralMesh:
    """The end faces' vertices put exactly at z = 0 and z = depth."""
    vertices = mesh.vertices.copy()
    for name, z in zip(ends, (0.0, depth)):
        part = mesh.boundary.get(name, np.zeros(0, np.int64))
        ids = np.unique(mesh.face_vertices[(mesh.face_offsets[part][:, None] + np.arange(3)).ravel()])
        vertices[ids, 2] = z
    return replace(mesh, vertices=vertices)


def surface_area(body) -> float:
    """The surface area of a Box or an Extruded body (arcs and circles exact)."""
    from vemkit.config.domain import CircleHole, arc_angles

    if hasattr(body, "lower"):
        a, b, c = np.subtract(body.upper, body.lower)
        return float(2.0 * (a * b + b * c + a * c))
    base = body.base
    k = len(base.polygon)
    perimeter = 0.0
    for i in range(k):
        p, q = base.polygon[i], base.polygon[(i + 1) % k]
        centre = base.arcs[i] if base.arcs else None
        if centre is None:
            perimeter += math.dist(p, q)
        else:
            r, _, dt = arc_angles(p, q, centre)
            perimeter += r * abs(dt)
    for hole in base.holes:
        if isinstance(hole, CircleHole):
            perimeter += 2.0 * math.pi * hole.r
        else:
            perimeter += sum(
                math.dist(hole.polygon[i], hole.polygon[(i + 1) % len(hole.polygon)]) for i in range(len(hole.polygon))
            )
    return float(2.0 * base.exact_area + body.depth * perimeter)
