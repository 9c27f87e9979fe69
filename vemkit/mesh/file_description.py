"""A netCDF file described once (variables, dimensions, attributes), written by one of two sinks.

A :class:`FileDescription` holds, in file order, each variable's dimensions, data and attributes
(and an xarray ``encoding``, only ``_FillValue``), which variables are coordinates, and the global
attributes. It is where the mesh and solution files' contents (docs/reference/files.md) are spelled out;
the two sinks only translate it:

- :meth:`FileDescription.to_dataset`: the ``xarray.Dataset`` of the Python API and the studies;
- :meth:`FileDescription.write_netcdf4`: the file itself through netCDF4, without importing xarray
  or pandas (0.3-0.6 s of a command's start-up). It writes what ``Dataset.to_netcdf(format="NETCDF4",
  engine="netcdf4")`` writes for these contents: the dimensions in order of first use, float
  variables with ``_FillValue = NaN`` unless they say otherwise, the ``coordinates`` attribute
  (the sorted coordinates whose dimensions a variable has) and, for coordinates no variable names,
  the global ``coordinates`` attribute (the tests compare the two files).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

import numpy as np


class Variable(NamedTuple):
    dims: tuple[str, ...]
    data: np.ndarray
    attrs: dict[str, Any]
    encoding: dict[str, Any]

    @property
    def values(self) -> np.ndarray:
        return self.data


class FileDescription:
    """The contents of one netCDF file: variables in file order, coordinates, global attributes."""

    def __init__(self, attrs: dict | None = None):
        self.variables: dict[str, Variable] = {}
        self.coordinates: list[str] = []
        self.attrs: dict[str, Any] = dict(attrs or {})

    def add(self, name: str, dims, data, attrs=None, *, coordinate: bool = False, encoding=None) -> None:
        """Set variable ``name`` (a new one goes last; a replaced one keeps its place, as in xarray)."""
        dims = (dims,) if isinstance(dims, str) else tuple(dims)
        data = np.asarray(data)
        if data.ndim != len(dims):
            raise ValueError(f"variable {name}: {data.ndim}-dimensional data for the dimensions {dims}")
        self.variables[name] = Variable(dims, data, dict(attrs or {}), dict(encoding or {}))
        if coordinate and name not in self.coordinates:
            self.coordinates.append(name)

    def __getitem__(self, name: str) -> Variable:
        return self.variables[name]

    def __contains__(self, name: str) -> bool:
        return name in self.variables

    def to_dataset(self):
        """The ``xarray.Dataset`` of this description (the variables in the same order)."""
        import xarray as xr

        ds = xr.Dataset({k: (v.dims, v.data, v.attrs) for k, v in self.variables.items()}, attrs=dict(self.attrs))
        for name, var in self.variables.items():
            ds[name].encoding.update(var.encoding)
        return ds.set_coords(self.coordinates) if self.coordinates else ds

    def write_netcdf4(self, path) -> None:
        """Write the file (netCDF4/HDF5) as ``self.to_dataset().to_netcdf(path)`` would."""
        import netCDF4

        with netCDF4.Dataset(Path(path), "w", format="NETCDF4") as nc:
            nc.set_auto_maskandscale(False)
            for key, value in self._global_attrs().items():
                _set_attribute(nc, key, value)
            for name, size in self._dimensions().items():
                nc.createDimension(name, size)
            for name, var in self.variables.items():
                if var.data.dtype.kind not in "iuf":
                    raise TypeError(f"variable {name}: {var.data.dtype} data; the netCDF4 sink writes numbers only")
                attrs = dict(var.attrs)
                fill = attrs.pop("_FillValue", var.encoding.get("_FillValue", _default_fill(var.data.dtype)))
                created = nc.createVariable(name, var.data.dtype, var.dims, fill_value=fill)
                attrs.update(self._coordinates_of(name, var))
                created.setncatts(attrs)
                created[...] = var.data

    def _dimensions(self) -> dict[str, int]:
        sizes: dict[str, int] = {}
        for name, var in self.variables.items():
            for dim, size in zip(var.dims, var.data.shape, strict=True):
                if sizes.setdefault(dim, size) != size:
                    raise ValueError(f"variable {name}: dimension {dim} of size {size}, elsewhere {sizes[dim]}")
        return sizes

    def _coordinates_of(self, name: str, var: Variable) -> dict[str, str]:
        """xarray's ``coordinates`` attribute: the coordinates on a subset of the variable's dimensions."""
        if name in self.coordinates or name in var.dims or "coordinates" in var.attrs:
            return {}
        names = sorted(c for c in self.coordinates if set(self.variables[c].dims) <= set(var.dims))
        return {"coordinates": " ".join(names)} if names else {}

    def _global_attrs(self) -> dict[str, Any]:
        """The global attributes, with ``coordinates`` naming the coordinates no variable names."""
        named = {
            c for k, v in self.variables.items() for c in self._coordinates_of(k, v).get("coordinates", "").split()
        }
        loose = sorted(set(self.coordinates) - named)
        if loose and "coordinates" not in self.attrs:
            return {**self.attrs, "coordinates": " ".join(loose)}
        return self.attrs


def _default_fill(dtype: np.dtype):
    """xarray's default ``_FillValue``: NaN for floating-point variables, none for the others."""
    return np.nan if np.issubdtype(dtype, np.floating) else None


def _set_attribute(nc, key: str, value) -> None:
    """An attribute as xarray writes it: a list of several strings as NC_STRING, the rest as given."""
    array = np.asarray(value)
    if array.dtype.kind in "US" and array.size > 1:
        nc.setncattr_string(key, value)
    else:
        nc.setncattr(key, value)
