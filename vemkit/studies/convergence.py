"""Convergence studies: per-run error records -> one self-describing ``xarray.Dataset``.

The records (one coarse solve against the reference of the same stabilization, docs/reference/mathematics.md) are
``vemkit.studies.error_records``; :func:`convergence_dataset` gathers them on the grid ``family x
stabilization x h`` and :func:`write_convergence` stores the result as netCDF4.

Missing values are explicit, never a quiet NaN in the file. Two kinds of entries are undefined:
the convergence ``order`` at the coarsest ``h`` of every (family, stabilization) (an order needs
two levels), and every variable where a family has no mesh at that ``h``. In memory they are NaN
(floats) or -1 (integers); on disk those values are replaced by the variable's declared
``_FillValue`` (-9999.0 for floats, -1 for integers; CF convention), so ``xarray.open_dataset``
masks them back to NaN and ``netCDF4`` returns masked arrays. Variables without undefined
entries declare no ``_FillValue``. The variable ``defined`` (int8) marks the existing runs and
``order_defined`` the entries where an order is defined.
"""

from __future__ import annotations

import json
import math

import numpy as np
import xarray as xr

from vemkit.io.fill_values import FLOAT_FILL, INT_FILL, read_with_fill_values, write_with_fill_values
from vemkit.io.provenance import git_commit, package_versions
from vemkit.studies.error_records import RECORD_KEYS

_VARIABLES = (
    "error_h1",
    "error_h1_semi",
    "error_l2",
    "error_paper",
    "n_dofs",
    "n_cells",
    "iterations",
    "wall_time",
    "assembly_time",
    "h_max",
)


# -- orders ---------------------------------------------------------------------------------------
def convergence_orders(h, errors) -> np.ndarray:
    """Observed orders log(e_{k-1}/e_k) / log(h_{k-1}/h_k) between successive levels.

    ``h`` and ``errors`` are in the order of the levels (coarse to fine, or any order: the levels
    are sorted by decreasing h first). Levels whose error is NaN are skipped; the order of a level
    is taken against the next coarser level that has an error. The first (coarsest) level, and a
    level whose error or predecessor's error is not positive, gets NaN. The result is aligned
    with the input.
    """
    h = np.asarray(h, dtype=float)
    e = np.asarray(errors, dtype=float)
    out = np.full(h.shape, np.nan)
    previous = None
    for k in np.argsort(-h, kind="stable"):
        if not np.isfinite(e[k]):
            continue
        if previous is not None and e[k] > 0 and e[previous] > 0 and h[k] != h[previous]:
            out[k] = math.log(e[previous] / e[k]) / math.log(h[previous] / h[k])
        previous = k
    return out


def with_paper_variant(ds: xr.Dataset, records, suffix: str, comment: str) -> xr.Dataset:
    """``ds`` with ``error_paper_<suffix>`` and ``order_paper_<suffix>``: the paper's measure of
    ``records`` (a variant of the discretization, e.g. ``gauss``) on the grid of ``ds``; NaN where
    the variant has no run (fill values in the file)."""
    shape = ds["error_h1"].shape
    errors = np.full(shape, np.nan)
    fams, stabs = [str(f) for f in ds["family"].values], [str(s) for s in ds["stabilization"].values]
    ns = [int(n) for n in ds["n"].values]
    for r in records:
        if r["family"] in fams and r["stabilization"] in stabs and int(r["n"]) in ns:
            errors[fams.index(r["family"]), stabs.index(r["stabilization"]), ns.index(int(r["n"]))] = r["error_paper"]
    orders = np.apply_along_axis(lambda e: convergence_orders(ds["h"].values, e), -1, errors)
    dims = ("family", "stabilization", "h")
    return ds.assign(
        {
            f"error_paper_{suffix}": (
                dims,
                errors,
                {
                    "long_name": f"error_paper with {comment}",
                    "units": "1",
                    "comment": "undefined where the variant was not run",
                },
            ),
            f"order_paper_{suffix}": (
                dims,
                orders,
                {"long_name": f"observed order of error_paper_{suffix}", "units": "1"},
            ),
        }
    )


# -- the dataset ----------------------------------------------------------------------------------
def _checked(records) -> list:
    records = list(records)
    if not records:
        raise ValueError("no error records: nothing to gather")
    for r in records:
        missing = [k for k in ("family", "stabilization", "n", "error_h1", "error_h1_semi") if k not in r]
        if missing:
            raise ValueError(f"error record {r!r} lacks {', '.join(missing)}")
        for key in ("error_h1", "error_h1_semi", "error_paper"):
            if key in r and not (np.isfinite(r[key]) and r[key] >= 0):
                raise ValueError(
                    f"error record {r['family']}/{r['stabilization']}/n{r['n']}: {key} = {r[key]}"
                    " is not a finite non-negative number"
                )
    return records


def _gridded(records, fams, stabs, ns):
    """({variable: (family, stabilization, h) array, NaN where missing}, the mask of existing runs)."""
    shape = (len(fams), len(stabs), len(ns))
    data = {k: np.full(shape, np.nan) for k in _VARIABLES}
    seen = np.zeros(shape, dtype=bool)
    for r in records:
        if r["family"] not in fams or r["stabilization"] not in stabs:
            continue
        idx = (fams.index(r["family"]), stabs.index(r["stabilization"]), ns.index(int(r["n"])))
        if float(r["n"]) != int(r["n"]):
            raise ValueError(f"error record {r['family']}/{r['stabilization']}: n = {r['n']} is not an integer level")
        if seen[idx]:
            raise ValueError(f"two error records for {r['family']}/{r['stabilization']}/n{r['n']}")
        seen[idx] = True
        for k in _VARIABLES:
            if k in r:
                data[k][idx] = float(r[k])
    return data, seen


def _orders(h, errors) -> np.ndarray:
    """convergence_orders of every (family, stabilization) row of a (family, stabilization, h) array."""
    out = np.full(errors.shape, np.nan)
    for i in range(errors.shape[0]):
        for j in range(errors.shape[1]):
            out[i, j] = convergence_orders(h, errors[i, j])
    return out


_UNDEFINED_FIRST = "undefined at the coarsest h (an order needs two levels): _FillValue in the file, NaN in memory"
_ORDERS = {  # order variable: (error variable, long name)
    "order": ("error_h1", "observed convergence order of error_h1: log(e_prev/e) / log(h_prev/h)"),
    "order_h1_semi": ("error_h1_semi", "observed convergence order of error_h1_semi"),
    "order_paper": ("error_paper", "observed convergence order of error_paper (the paper's Table 1 order)"),
}


def _add_variables(ds, data, seen, h, has_paper) -> None:
    dims = ("family", "stabilization", "h")
    for key in ("error_h1", "error_h1_semi", "error_l2", "error_paper", "wall_time", "assembly_time", "h_max"):
        if key != "error_paper" or has_paper:
            long_name, units = RECORD_KEYS[key]
            ds[key] = (dims, data[key], {"long_name": long_name, "units": units})
    for name, (error, long_name) in _ORDERS.items():
        if error != "error_paper" or has_paper:
            ds[name] = (
                dims,
                _orders(h, data[error]),
                {"long_name": long_name, "units": "1", "comment": _UNDEFINED_FIRST},
            )
    for key in ("n_dofs", "n_cells", "iterations"):
        long_name, units = RECORD_KEYS[key]
        values = np.where(np.isnan(data[key]), INT_FILL, data[key]).astype(np.int64)
        ds[key] = (dims, values, {"long_name": long_name, "units": units})
    ds["defined"] = (
        dims,
        seen.astype(np.int8),
        {
            "long_name": "1 where the run exists, 0 where the family has no mesh at this h",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "missing present",
        },
    )
    ds["order_defined"] = (
        dims,
        np.isfinite(ds["order"].values).astype(np.int8),
        {
            "long_name": "1 where order is defined",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "undefined defined",
        },
    )


def _provenance(title, scene_yaml, parameters, commit) -> dict:
    versions = package_versions()
    return {
        "title": title,
        "Conventions": "CF-1.8",
        "error_measure": "relative errors of Pi_1 u_h against Pi_1 u_ref in the broken norms over the "
        "reference mesh (docs/reference/mathematics.md); error_h1: full H1 norm, error_h1_semi: H1 seminorm; "
        "error_paper: the paper's own measure |Pi_1^ref(I_ref u_h - u_ref)|_H1 / "
        "|Pi_1^ref u_ref|_H1 (interpolation at the reference vertices, projection on the "
        "reference mesh, H1 seminorm), the one its Table 1 prints",
        "missing_values": "order is undefined at the coarsest h; in the file, a float variable with "
        f"undefined entries has _FillValue = {FLOAT_FILL} there, an integer one {INT_FILL}; "
        "no NaN is stored; see the variables defined and order_defined",
        "scene": scene_yaml,
        "parameters": json.dumps(parameters or {}, sort_keys=True, default=str),
        "package_versions": json.dumps(versions, sort_keys=True),
        "git_commit": commit if commit is not None else git_commit(),
        **{f"version_{name}": version for name, version in versions.items()},
    }


def convergence_dataset(
    records,
    *,
    scene_yaml: str = "",
    parameters=None,
    families=None,
    stabilizations=None,
    title: str = "vemkit convergence study",
    commit: str | None = None,
) -> xr.Dataset:
    """The convergence Dataset (dims ``family``, ``stabilization``, ``h``) of error records.

    ``families`` / ``stabilizations`` fix the order of the labels (default: first appearance).
    ``h`` runs from coarse to fine, as in the paper's Table 1. See the module docstring for how
    undefined entries are marked.
    """
    records = _checked(records)
    fams = list(families) if families is not None else list(dict.fromkeys(r["family"] for r in records))
    stabs = (
        list(stabilizations) if stabilizations is not None else list(dict.fromkeys(r["stabilization"] for r in records))
    )
    ns = sorted({int(r["n"]) for r in records})
    data, seen = _gridded(records, fams, stabs, ns)
    h = 1.0 / np.asarray(ns, dtype=float)  # n increasing: h runs from coarse to fine
    ds = xr.Dataset(
        coords={
            "family": ("family", np.array(fams, dtype=str), {"long_name": "mesh family label"}),
            "stabilization": (
                "stabilization",
                np.array(stabs, dtype=str),
                {"long_name": "stabilization alpha_K of the dofi-dofi form (docs/reference/mathematics.md)"},
            ),
            "h": ("h", h, {"long_name": "nominal mesh size h = 1/n", "units": "mm"}),
            "n": ("h", np.asarray(ns, dtype=np.int64), {"long_name": "cells per side n = 1/h"}),
        }
    )
    _add_variables(ds, data, seen, h, has_paper=any("error_paper" in r for r in records))
    ds.attrs.update(_provenance(title, scene_yaml, parameters, commit))
    return ds


def write_convergence(ds: xr.Dataset, path):
    """Write atomically; undefined entries as declared fill values (``vemkit.io.fill_values``)."""
    return write_with_fill_values(ds, path)


def read_convergence(path) -> xr.Dataset:
    """Read a file written by :func:`write_convergence`: float fill values back to NaN, integer ones kept as -1."""
    return read_with_fill_values(path)


def square_rows(ds: xr.Dataset, family: str = "square") -> xr.Dataset:
    """The Table 1 part of a convergence Dataset: one family, h where it has runs."""
    sub = ds.sel(family=[family])
    keep = sub["defined"].values.astype(bool).any(axis=(0, 1))
    return sub.isel(h=np.flatnonzero(keep))
