"""Layer 6, result files: solution files (docs/reference/files.md), tables with fill values, provenance.

Owns the solution Dataset and its netCDF file (``solution_file``: UGRID mesh, fields, contact
boundary, history, attributes; atomic writes), table files whose undefined entries are fill values
rather than NaN (``fill_values``), and the provenance every file records (``provenance``: package
versions, git commit). Imports from vemkit: every layer below (``exceptions`` … ``solvers``).
"""
