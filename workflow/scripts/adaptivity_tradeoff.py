"""Rule tradeoff_adaptive: the adaptive loop as configurations of the speed-accuracy study
(vemkit.studies.adaptivity_compare.tradeoff_records), against the study's reference solution."""

from _single_thread import NUMPY_EARLY  # first: one BLAS thread before numpy loads (see there)

from _helpers import logged  # noqa: E402

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.config.scene import load_scene
    from vemkit.studies import tradeoff
    from vemkit.studies.adaptivity_compare import tradeoff_records
    from vemkit.studies.error_records import ReferenceSolution, write_records

    if NUMPY_EARLY:
        print("warning: numpy was loaded before the thread counts were set to 1", flush=True)
    s, a = smk.params.settings, smk.params.adaptive
    scene = load_scene(s["scene"], s["overrides"] + [f"discretization.mesh={{family: square, n: {int(a['n'])}}}"])
    reference = ReferenceSolution(smk.input.reference)
    tradeoff.check_reference_scene(scene, reference.dataset.attrs.get("scene", ""))

    def progress(r):
        print(
            f"{r['family']} {r['solver']:<5} tol {r['tol']:.0e} {r['message']:<8} {r['n_dofs']:>6} dofs  "
            f"error {r['error_h1']:.4e}  {r['cost_time']:.3f} s",
            flush=True,
        )

    records = tradeoff_records(
        scene,
        reference,
        theta=a["theta"],
        max_dofs=a["max_dofs"],
        solvers=s["solvers"],
        tolerances=s["tolerances"],
        stabilization=s["reference"]["stabilization"],
        max_iterations=s["max_iterations"],
        progress=progress,
    )
    write_records(records, smk.output[0])
