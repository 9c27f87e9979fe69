"""Rule tradeoff_adaptive: the adaptive loop as configurations of the speed-accuracy study
(vemkit.studies.adaptivity_compare.tradeoff_records), against the study's reference solution."""

import os
import sys

# single-threaded solves, as rule tradeoff_family (see there)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "GOTO_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_var] = "1"
_NUMPY_EARLY = "numpy" in sys.modules

from _helpers import logged  # noqa: E402

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.config.scene import load_scene
    from vemkit.studies import tradeoff
    from vemkit.studies.adaptivity_compare import tradeoff_records
    from vemkit.studies.convergence import ReferenceSolution, write_records

    if _NUMPY_EARLY:
        print("warning: numpy was loaded before the thread counts were set to 1", flush=True)
    s, a = smk.params.settings, smk.params.adaptive
    scene = load_scene(s["scene"], s["overrides"] + [f"discretization.mesh={{family: square, n: {int(a['n'])}}}"])
    reference = ReferenceSolution(smk.input.reference)
    tradeoff.check_reference_scene(scene, reference.dataset.attrs.get("scene", ""))

    def progress(r):
        print(f"{r['family']} {r['solver']:<5} tol {r['tol']:.0e} {r['message']:<8} {r['n_dofs']:>6} dofs  "
              f"error {r['error_h1']:.4e}  {r['cost_time']:.3f} s", flush=True)

    records = tradeoff_records(scene, reference, theta=a["theta"], max_dofs=a["max_dofs"], solvers=s["solvers"],
                               tolerances=s["tolerances"], stabilization=s["reference"]["stabilization"],
                               max_iterations=s["max_iterations"], progress=progress)
    write_records(records, smk.output[0])
