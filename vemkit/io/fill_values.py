"""Table files whose undefined entries are declared fill values, never NaN (CF ``_FillValue``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from vemkit.io.solution_file import write_netcdf

FLOAT_FILL = -9999.0  # stands for an undefined float entry in files (netCDF _FillValue); never NaN
INT_FILL = -1


def write_with_fill_values(ds: xr.Dataset, path) -> Path:
    """Write a table Dataset atomically, undefined entries declared instead of stored as NaN.

    A float variable holding NaN is written with ``_FillValue = -9999.0`` in their place, an
    integer data variable holding -1 with ``_FillValue = -1``; the others carry no fill value.
    ``read_with_fill_values`` turns the float fill values back into NaN.
    """
    out = ds.copy()
    for key in list(out.variables):
        var = out[key]
        attrs = {k: v for k, v in var.attrs.items() if k != "_FillValue"}
        var.encoding.pop("_FillValue", None)
        if np.issubdtype(var.dtype, np.floating) and np.isnan(var.values).any():
            out[key] = var.copy(data=np.where(np.isnan(var.values), FLOAT_FILL, var.values))
            out[key].attrs = {**attrs, "_FillValue": FLOAT_FILL}
        elif np.issubdtype(var.dtype, np.integer) and key not in out.dims and (var.values == INT_FILL).any():
            out[key].attrs = {**attrs, "_FillValue": var.dtype.type(INT_FILL)}
        else:
            out[key].attrs = attrs
            if var.dtype != object:
                out[key].encoding["_FillValue"] = None
    return write_netcdf(out, path)


def read_with_fill_values(path) -> xr.Dataset:
    """A file of ``write_with_fill_values``: float fill values back to NaN, integer ones kept as -1."""
    with xr.open_dataset(path, mask_and_scale=False) as ds:
        ds = ds.load()
    for key in list(ds.variables):
        var = ds[key]
        fill = var.attrs.get("_FillValue")
        if fill is not None:
            attrs = {k: v for k, v in var.attrs.items() if k != "_FillValue"}
            ds[key] = var.where(var != fill) if np.issubdtype(var.dtype, np.floating) else var
            ds[key].attrs = attrs
    return ds
