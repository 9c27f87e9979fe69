"""Imported first by the scripts that time solves: back to one BLAS/OpenMP thread before numpy loads.

Those rules ask for 2 threads only to keep other jobs off the core they time; Snakemake sets the
BLAS and OpenMP thread counts to the rule's threads, but vemkit's solves are meant single-threaded
(multi-threaded BLAS slows the sparse solves down). ``NUMPY_EARLY``: numpy was already loaded, so
the setting came too late (the script warns in its log).
"""

import os
import sys

for _var in (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "GOTO_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "NUMEXPR_NUM_THREADS",
):
    os.environ[_var] = "1"
NUMPY_EARLY = "numpy" in sys.modules
