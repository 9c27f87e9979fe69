"""Layer 6, result files: solution files (docs/reference/files.md), tables with fill values, provenance.

Owns the solution Dataset and its netCDF file, 2D or 3D (``solution_file``: the mesh's UGRID
topology, history, attributes, atomic writes, reading back; ``solution_fields``: the fields and the
contact boundary, one code path for both dimensions), table files whose undefined entries are fill values
rather than NaN (``fill_values``), and the provenance every file records (``provenance``: package
versions, git commit), and what the command shows and says about its writes (``command_line``). Imports from vemkit: every layer below (``exceptions`` … ``solvers``).
"""
