"""vemkit: lowest-order virtual elements for elastic bodies in frictional contact."""

import os as _os

# vemkit's work is sparse (CSR products, AMG cycles, Numba kernels with their own threads):
# multi-threaded dense BLAS only spins and competes with them (4x slower CG measured on 2 cores).
# Users who want BLAS threads set these variables themselves before importing vemkit.
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

__version__ = "0.1.0"
