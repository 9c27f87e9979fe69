"""What vemkit accepts, and what a request will cost before it is spent (issue 9).

Size: a solve of D degrees of freedom peaks at about ``BASE_BYTES + BYTES_PER_DOF * D`` of
memory (mesh, assembly, AMG hierarchy or sparse factorization, semismooth Newton or Uzawa, the
result Dataset and its netCDF file). The constants are the peak resident memory (ru_maxrss) of
``vemkit solve`` on the paper scene, measured for the square, voronoi, triangle and hanging
families at n = 64 ... 512 with both solvers, rounded up (README "Input rules and limits").

A request is refused, with the estimate in the message, when its DOFs exceed ``max_dofs``
(default :data:`DEFAULT_MAX_DOFS`; ``vemkit solve --max-dofs`` raises it) or its estimated peak
memory exceeds :data:`MEMORY_FRACTION` of the memory available to the process (MemAvailable,
a cgroup limit, RLIMIT_AS, whichever is smallest) — that one always.

A mesh file's counts are the ones it declares (:mod:`vemkit.config.mesh_file_header`); a triangle
mesh adds the triangles of the body's parts thinner than h (:mod:`vemkit.config.mesh_resolution`).
:func:`memory_budget` bounds what a third-party reader of a user's file may allocate.
With the nodal volumetric strain the memory is scaled by its wider stencil (:func:`nodal_average_estimate`).
"""

from __future__ import annotations

import math
import os
import resource
from contextlib import contextmanager
from typing import NamedTuple

from vemkit.config.boundary_conditions import check_file_sides
from vemkit.config.domain import domain_from_spec
from vemkit.config.mesh_file_header import mesh_file_header
from vemkit.config.mesh_resolution import scene_cells_per_length, thin_part_triangles
from vemkit.config.volumetric import NODAL_AVERAGE_ENTRIES
from vemkit.exceptions import ResourceLimitError

__all__ = [
    "BASE_BYTES",
    "BYTES_PER_DOF",
    "DEFAULT_MAX_DOFS",
    "MEMORY_FRACTION",
    "Resources",
    "available_memory",
    "check_resources",
    "check_scene_estimate",
    "check_scene_resources",
    "domain_area",
    "estimate_mesh",
    "estimate_resources",
    "estimate_resources3d",
    "memory_budget",
    "scene_resources",
]

DEFAULT_MAX_DOFS = 4_000_000  # the paper's finest level (n = 1024) has 2.1 million on squares
BASE_BYTES = 400 * 2**20  # Python with numpy, scipy, numba, xarray, netCDF4 loaded
BYTES_PER_DOF = 2_500  # measured 1.0-1.6 kB (see the module docstring); a margin on top
MEMORY_FRACTION = 0.8
MAX_CELLS_PER_SIDE = 1e8  # estimates are capped here (1e16 cells), so that extreme sizes stay numbers


class Resources(NamedTuple):
    """A prediction: mesh cells and vertices, degrees of freedom, peak memory in bytes."""

    cells: int
    vertices: int
    dofs: int
    peak_bytes: int

    def describe(self) -> str:
        return f"about {self.cells:,} cells, {self.dofs:,} DOFs and {_gib(self.peak_bytes)} of memory"

    def on_ranks(self, here: int, ranks: int) -> "Resources":
        """The memory on this machine of the solve split across ``ranks`` MPI ranks, ``here`` of them
        on it: each rank its own Python and libraries (BASE_BYTES) and its share of the rest."""
        if ranks <= 1:
            return self
        return self._replace(peak_bytes=int(here * (BASE_BYTES + (self.peak_bytes - BASE_BYTES) / ranks)))


def _gib(count: float) -> str:
    return f"{count / 2**30:.1f} GiB" if count >= 2**30 else f"{count / 2**20:.0f} MiB"


def estimate_resources(cells: int, vertices: int) -> Resources:
    """The prediction for a mesh of ``cells`` and ``vertices`` (2 DOFs per vertex, an upper bound)."""
    dofs = 2 * int(vertices)
    return Resources(int(cells), int(vertices), dofs, BASE_BYTES + BYTES_PER_DOF * dofs)


BYTES_PER_NONZERO_3D = 40  # fitted: the stiffness (12 B/entry) and its AMG copies at the peak (docstring)
BYTES_PER_DOF_3D = 600  # fitted: mesh, geometry, rigid modes (48 B/DOF), CG vectors, coarse levels


def stiffness_entries3d(cells: int, vertices: int, faces: int) -> int:
    """The nonzeros of the 3D k = 1 stiffness matrix predicted from the mesh counts (model of
    ``estimate_resources3d``): 9 per ordered pair of vertices that share a cell."""
    C, V, F = max(int(cells), 1), int(vertices), int(faces)
    incidences = max(4 * F - 4 * C, 4 * C)  # sum_c n_c (n_c = 2 f_c - 4, simple polyhedra)
    face_incidences = 1.5 * incidences  # sum_f m_f (3 n_c / 2 edges per cell, 2 cells per face)
    edges = V + F - C - 1  # Euler: V - E + F - C = 1 (a ball)
    pairs = incidences**2 / C - face_incidences**2 / max(F, 1) + 4 * edges - V
    return int(9 * min(max(pairs, V), float(V) * V))


def estimate_resources3d(cells: int, vertices: int, faces: int) -> Resources:
    """The prediction for a 3D k = 1 mesh of ``cells``, ``vertices`` and ``faces`` (3 DOFs per
    vertex, an upper bound): peak = BASE_BYTES + BYTES_PER_NONZERO_3D x nnz + BYTES_PER_DOF_3D x DOFs.

    nnz: 9 per ordered pair of vertices sharing a cell. Inclusion-exclusion over the cells, faces,
    edges and vertices holding a pair (the star of a pair is a ball: cells - faces + edges - vertices
    = 1) counts them exactly as  sum_c n_c^2 - sum_f m_f^2 + 4 E - V  (n_c vertices of cell c, m_f of
    face f; exact in the interior: 27 per vertex on hexahedra, 15 on the Kuhn tetrahedra). From the
    counts alone: E = V + F - C - 1 (Euler), sum_c n_c = 4 F - 4 C and sum_f m_f = 3/2 sum_c n_c
    (simple polyhedra: three faces at every vertex of a cell), the squares by their means
    ((sum n_c)^2 / C, (sum m_f)^2 / F; the face term so underestimated, the pairs overestimated).
    Against the matrices of the families on the unit cube at n = 12: hexahedra +29 %, Kuhn tetrahedra
    +24 % (boundary vertices have fewer neighbours), Voronoi +5 %, random octree -8 % (hanging nodes);
    69^3 hexahedra +6.4 %.

    The bytes are fitted to the peak resident memory (ru_maxrss) of ``benchmarks/elasticity3d.py``
    (hexahedra, bottom clamped, AMG-CG with the six rigid modes, ``AMGSolver``): 0.41, 0.88 and 3.44 GiB
    at n = 25, 40 and 69 (3.8, 15.5 and 79.8 million entries; 0.05, 0.2 and 1.01 million DOFs), i.e.
    about 0.28 GiB of Python and libraries plus 38-40 B per entry: the stiffness's 12 B (float64 +
    int32 column), its 3 x 3 BSR copy (~9 B) and pyamg's strength, prolongator and Galerkin products
    at the set-up's peak. The model's 40 B per entry, 600 B per DOF and BASE_BYTES predict 0.59,
    1.15 and 4.13 GiB there (1.44, 1.31 and 1.20 times the measured peaks).
    """
    dofs = 3 * int(vertices)
    nonzeros = stiffness_entries3d(cells, vertices, faces)
    return Resources(
        int(cells), int(vertices), dofs, BASE_BYTES + BYTES_PER_NONZERO_3D * nonzeros + BYTES_PER_DOF_3D * dofs
    )


#: dimension -> the prediction for a built mesh from (cells, nodes of its space, facets): what the
#: adaptive loop checks before it solves a refined mesh (a plane mesh's model reads no facets)
RESOURCE_MODELS = {
    2: lambda cells, nodes, _facets: estimate_resources(cells, nodes),
    3: lambda cells, nodes, facets: estimate_resources3d(cells, nodes, facets),
}


def domain_area(domain) -> float:
    """Area of a scene's ``domain`` (docs/reference/files.md): 1 for the unit square, else the shoelace area of
    its outer polygon (holes ignored: an upper bound)."""
    if not isinstance(domain, dict) or "polygon" not in domain:
        return 1.0
    corners = domain["polygon"]
    twice = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1]))
    return max(abs(float(twice)) / 2.0, 1e-300)


def _cells_per_length(options: dict, area: float, cells_per_square: float) -> float:
    if options.get("n") is not None:
        return float(options["n"])
    if options.get("h") is not None:
        return 1.0 / float(options["h"])
    if options.get("cells") is not None:
        return math.sqrt(float(options["cells"]) / (cells_per_square * area))
    return 1.0


def estimate_mesh(mesh_options: dict, area: float = 1.0) -> tuple[int, int]:
    """(cells, vertices) of the mesh ``discretization.mesh`` asks for, without building it.

    On the unit square with n cells per side: exact for square (n², (n+1)²) and structured
    triangles; Delaunay triangles 2 n² within 2 % (triangle.py) and about (n+1)² vertices; Voronoi
    n² cells, 2 n² + 2 n vertices; hanging: refinement at a side adds 3 n (2^levels - 1) cells,
    random refinement multiplies them by (1 + 3 fraction) per level, vertices <= 1.5 cells +
    4 n 2^levels + 1 (upper bounds, checked against the families in tests/config). Any other
    domain: the same with n √area cells per side.
    """
    family = mesh_options.get("family")
    triangles = family == "triangle"
    per_side = _cells_per_length(mesh_options, area, 2.0 if triangles else 1.0) * math.sqrt(area)
    n = math.ceil(min(per_side, MAX_CELLS_PER_SIDE))  # h = 1e-300: a lower bound, far beyond any limit
    if family == "square" or (triangles and mesh_options.get("kind") == "structured"):
        return (2 if triangles else 1) * n * n, (n + 1) ** 2
    if triangles:
        return (204 * n * n) // 100 + 1, (105 * (n + 1) ** 2) // 100 + 8
    if family == "voronoi":
        return n * n, 2 * n * n + 2 * n + 4
    levels = int(mesh_options.get("levels", 1))
    if mesh_options.get("rule", "contact") == "random":
        cells = int(n * n * (1.0 + 3.0 * float(mesh_options.get("fraction", 0.3))) ** levels) + 1
    else:
        cells = n * n + 3 * n * (2**levels - 1)
    return cells, (3 * cells) // 2 + 4 * n * 2**levels + 1


def _read_int(path: str) -> int | None:
    try:
        with open(path, encoding="ascii") as handle:
            text = handle.read().split()[0]
    except (OSError, IndexError):
        return None
    return int(text) if text.isdigit() else None


def available_memory() -> int | None:
    """Bytes this process may still use (None if unknown): the smallest of MemAvailable, the
    cgroup memory limit minus its usage, and the address-space limit (RLIMIT_AS)."""
    candidates = []
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    candidates.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    limit = _read_int("/sys/fs/cgroup/memory.max")
    if limit is not None and limit < 2**60:
        candidates.append(limit - (_read_int("/sys/fs/cgroup/memory.current") or 0))
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        candidates.append(soft)
    if not candidates and hasattr(os, "sysconf"):
        try:
            candidates.append(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (OSError, ValueError):
            pass
    return max(min(candidates), 0) if candidates else None


def check_resources(
    estimate: Resources,
    max_dofs: int | None = DEFAULT_MAX_DOFS,
    what: str = "the scene",
    fix: str = "a smaller discretization.mesh.n",
    ranks: tuple[int, int] = (1, 1),
) -> None:
    """ResourceLimitError if ``estimate`` exceeds ``max_dofs`` or the machine (message: the
    estimate, the limit and the fix); ``ranks``: (on this machine, in all) of a solve split across
    MPI ranks (:meth:`Resources.on_ranks`)."""
    if max_dofs is not None and estimate.dofs > max_dofs:
        raise ResourceLimitError(
            f"{what} needs {estimate.describe()}, more than the limit of {max_dofs:,} DOFs; "
            f"use {fix}, or raise the limit with --max-dofs",
            key="max_dofs",
            estimate=estimate._asdict(),
        )
    free = available_memory()
    estimate = estimate.on_ranks(*ranks)
    if free is not None and estimate.peak_bytes > MEMORY_FRACTION * free:
        raise ResourceLimitError(
            f"{what} needs {estimate.describe()}, more than this machine has available ({_gib(free)}); use {fix}",
            key="memory",
            estimate=estimate._asdict(),
        )


def scene_resources(scene, layout: dict | None = None) -> Resources | None:
    """Cells, DOFs and peak memory of solving ``scene``, predicted without building its mesh
    (None for a mesh read from a file: its size is known once it is read). ``layout``: the nodes of
    the scene's element per mesh entity (``Element.layout`` of ``vemkit.vem.elements``; default one
    per vertex, k = 1)."""
    if "family" not in scene.mesh_options:
        if scene.mesh_file is None:
            return None
        header = mesh_file_header(scene.mesh_file)
        return estimate_resources(header.cells, header.vertices)
    cells, vertices = estimate_mesh(scene.mesh_options, domain_area(scene.domain))
    if scene.mesh_options["family"] == "triangle":  # quality triangles fill parts thinner than h
        extra = thin_part_triangles(domain_from_spec(scene.domain), 1.0 / scene_cells_per_length(scene))
        cells, vertices = cells + extra, vertices + extra // 2
    # nodes on vertices, edges (Euler: about V + C) and cells; measured peak memory per DOF of k = 2 as
    # for k = 1 (benchmarks/order2.py: 0.80 GiB at 525 312 DOFs, k = 1 0.74 GiB)
    layout = layout or {"vertex": 1}
    nodes = sum(
        layout.get(entity, 0) * count
        for entity, count in (("vertex", vertices), ("edge", vertices + cells), ("cell", cells))
    )
    return estimate_resources(cells, nodes)._replace(vertices=vertices)


def check_scene_resources(
    scene, max_dofs: int | None = DEFAULT_MAX_DOFS, layout: dict | None = None, ranks: tuple[int, int] = (1, 1)
) -> Resources | None:
    """The prediction of :func:`scene_resources` (``layout``: the element's nodes per entity);
    ResourceLimitError beyond ``max_dofs`` or the machine's memory (``ranks``: :func:`check_resources`)."""
    estimate = scene_resources(scene, layout)
    return None if estimate is None else check_scene_estimate(scene, estimate, max_dofs, ranks=ranks)


def check_scene_estimate(
    scene, estimate: Resources, max_dofs: int | None, dimension: int = 2, ranks: tuple[int, int] = (1, 1)
) -> Resources:
    """ResourceLimitError if the scene's predicted ``estimate`` is beyond ``max_dofs`` or the machine's
    memory (``ranks``: :func:`check_resources`); a mesh file's sides checked against the scene (its
    header, ``dimension`` 3: a 3D file)."""
    if scene.volumetric_strain == "nodal_average":
        estimate = nodal_average_estimate(estimate, dimension)
    options = scene.mesh_options
    if "file" in options:
        check_resources(
            estimate,
            max_dofs,
            what=f"the mesh file {options['file']} ({estimate.vertices:,} vertices)",
            fix="a coarser mesh",
            ranks=ranks,
        )
        check_file_sides(scene, mesh_file_header(scene.mesh_file, dimension))
        return estimate
    size = ", ".join(f"{k} = {v}" for k, v in options.items() if k in ("n", "h", "cells", "layers"))
    check_resources(
        estimate,
        max_dofs,
        what=f"the scene ({options['family']} mesh, {size})",
        fix="a coarser discretization.mesh",
        ranks=ranks,
    )
    return estimate


def nodal_average_estimate(estimate: Resources, dimension: int) -> Resources:
    """The prediction with the nodal volumetric strain (``vemkit.config.volumetric``): its stiffness
    holds up to ``NODAL_AVERAGE_ENTRIES[dimension]`` times the entries, and the memory beyond
    BASE_BYTES (mostly per entry: the matrix and the AMG hierarchy) grows as much (an upper bound)."""
    factor = NODAL_AVERAGE_ENTRIES[dimension]
    return estimate._replace(peak_bytes=int(BASE_BYTES + factor * (estimate.peak_bytes - BASE_BYTES)))


def _address_space() -> int | None:
    """The bytes of address space this process has mapped now (None if unknown)."""
    try:
        with open("/proc/self/statm", encoding="ascii") as handle:
            return int(handle.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


@contextmanager
def memory_budget(extra_bytes: int):
    """Let the code inside map at most ``extra_bytes`` more memory (RLIMIT_AS lowered for its
    duration, restored after): an allocation beyond is a MemoryError at once, instead of a machine
    that swaps. For third-party readers of user files (meshio, netCDF) whose allocations follow
    what the file says; no effect where the limit cannot be read or set."""
    mapped = _address_space()
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    limit = None if mapped is None else mapped + int(extra_bytes)
    if limit is not None and hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    if limit is None or (soft != resource.RLIM_INFINITY and soft <= limit):
        yield
        return
    try:
        resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    except (ValueError, OSError):
        yield
        return
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
