"""A reference solution file a user names (``adaptivity.reference``, docs/reference/files.md) read as an input.

The file is user input like a scene or a mesh file, so it is read the same careful way:

- a regular ``.nc`` file whose declared counts fit a plane mesh (``vemkit.config.mesh_file_header``);
- the memory its use will take predicted from those counts before anything is read, and refused
  beyond the machine (``vemkit.config.limits``: the reference's projection and quadrature cost about
  what a solve of its size does);
- its mesh read and validated like any mesh file (``vemkit.mesh.files.read_mesh``: a vertex index out
  of range, a broken cell is a one-line refusal, never a kernel indexing outside an array);
- only the variables it needs (``u1``, ``u2`` on the mesh's nodes) read, after checking their shape:
  any other variable of the file, however large, is never read; a NaN or inf in them is refused;
- its ``scene`` attribute parsed by the safe YAML loader (``vemkit.config.safe_yaml``; at most
  ``MAX_FILE_BYTES``, a mapping) and its order checked: the error measure is k = 1, an order-2
  reference is refused.

Every refusal is one line naming ``adaptivity.reference`` and the file, with the input's own error type.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from vemkit.config.limits import check_resources, estimate_resources
from vemkit.config.mesh_file_header import mesh_file_header
from vemkit.config.safe_yaml import MAX_FILE_BYTES, parse_yaml
from vemkit.exceptions import InputError, ResourceLimitError

KEY = "adaptivity.reference"
FIX = "give a solution file written by vemkit solve (relative to the scene file)"


def _refused(path: Path, problem: str, kind=InputError) -> InputError:
    return kind(f"{KEY} = {str(path)!r}: {problem}", key=KEY)


def _restated(path: Path, error: InputError) -> InputError:
    """``error`` (a refusal of the file's mesh or size) as one naming adaptivity.reference, same type."""
    if isinstance(error, ResourceLimitError):
        return ResourceLimitError(f"{KEY} = {str(path)!r}: {error}", key=KEY, estimate=error.estimate)
    return _refused(path, str(error), type(error))


def _scene_data(path: Path, text) -> dict:
    if not isinstance(text, str):
        raise _refused(path, f"has no scene attribute (text); {FIX}")
    if len(text.encode("utf-8", errors="replace")) > MAX_FILE_BYTES:
        raise _refused(path, f"its scene attribute is larger than {MAX_FILE_BYTES // 1024} KiB (a scene); {FIX}")
    data = parse_yaml(text, f"{KEY} {path.name}: the scene attribute") or {}
    if not isinstance(data, dict):
        raise _refused(path, f"its scene attribute is not a scene (a mapping); {FIX}")
    return data


def _order(data: dict, attrs: dict) -> object:
    """The order k the file declares (attribute ``order``, else its scene's discretization.order)."""
    discretization = data.get("discretization")
    declared = discretization.get("order", 1) if isinstance(discretization, dict) else 1
    return attrs.get("order", declared) if declared == 1 else declared


def _node_values(path: Path, nc, n_vertices: int) -> dict:
    """u1, u2 of the file, checked to be one float per mesh node before they are read."""
    values = {}
    for name in ("u1", "u2"):
        variable = nc.variables.get(name)
        if variable is None:
            raise _refused(path, f"has no variable {name}; {FIX}")
        if variable.shape != (n_vertices,) or getattr(variable.dtype, "kind", "O") != "f":
            raise _refused(
                path,
                f"variable {name} must hold one float per mesh node ({n_vertices:,}), not "
                f"{variable.dtype} of shape {variable.shape}; {FIX}",
            )
        values[name] = np.asarray(variable[:], dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(values[name]))
        if bad.size:  # refused here: the true errors computed from it would blame the output file
            raise _refused(
                path,
                f"variable {name} holds {bad.size:,} NaN or inf value{'s' if bad.size > 1 else ''} (the first at "
                f"node {bad[0]}: {values[name][bad[0]]}); a reference must be a finite solution: {FIX}",
            )
    return values


def read_reference_file(path) -> tuple:
    """(mesh, dataset of u1, u2 with the attributes scene, order, stabilization, the parsed scene) of
    the reference file ``path``, checked as the module docstring says."""
    import netCDF4

    from vemkit.mesh.files import read_mesh

    path = Path(path)
    if path.suffix != ".nc":
        raise _refused(path, f"is not a netCDF (.nc) file; {FIX}")
    try:
        header = mesh_file_header(path)
        check_resources(
            estimate_resources(header.cells, header.vertices),
            None,
            what=f"the reference ({header.vertices:,} vertices, {header.cells:,} cells)",
            fix="a reference on a coarser mesh",
        )
        mesh = read_mesh(path)
    except InputError as error:
        raise _restated(path, error) from None
    with netCDF4.Dataset(path, "r") as nc:
        nc.set_auto_mask(False)
        names = set(nc.ncattrs())
        attrs = {name: nc.getncattr(name) for name in ("scene", "order", "stabilization") if name in names}
        data = _scene_data(path, attrs.get("scene"))
        order = _order(data, attrs)
        if order != 1:
            raise _refused(
                path,
                f"is an order-{order} solution (discretization.order = {order}); the true error "
                "of vemkit adapt is a k = 1 measure: give a reference solved with "
                "discretization.order = 1",
                kind=InputError,
            )
        values = _node_values(path, nc, mesh.n_vertices)
    dataset = xr.Dataset(
        {name: ("mesh2d_nNodes", v) for name, v in values.items()},
        attrs={"scene": attrs["scene"], "order": 1, "stabilization": str(attrs.get("stabilization", ""))},
    )
    return mesh, dataset, data
