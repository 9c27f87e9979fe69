"""The Section 4 study's pipeline (workflow/rules/order2.smk): `snakemake order2` plans one solve per
(case, level) on the paper's scene and on each manufactured contact scene, the k = 2 reference, one error
job per case and scene, the gathered files and the figures (the default target's own test checks that it
does not include them); every level nests in the reference."""

import ast
from pathlib import Path

from test_workflow import planned_jobs

ROOT = Path(__file__).resolve().parents[2]


def _order2_settings():
    text = (ROOT / "workflow" / "rules" / "order2.smk").read_text(encoding="utf-8")
    return ast.literal_eval(text[text.index("ORDER2 = {") + len("ORDER2 = ") : text.index("ORDER2_CASES")])


def test_order2_plans_every_case_and_level():
    settings = _order2_settings()
    jobs = planned_jobs("order2")
    levels = sum(len(case["levels"]) for case in settings["cases"].values())
    assert jobs["order2_solve"] == levels
    extra = settings["manufactured_cases"]
    assert jobs["order2_manufactured_solve"] == (levels + sum(len(c["levels"]) for c in extra.values())) * len(
        settings["manufactured"]
    )
    assert jobs["order2_reference"] == 1 and jobs["order2_errors"] == len(settings["cases"])
    assert jobs["order2_manufactured_errors"] == (len(settings["cases"]) + len(extra)) * len(settings["manufactured"])
    assert jobs["order2_gather"] == 1 and jobs["order2_manufactured_gather"] == 1 and jobs["order2_figure"] == 2
    for scene in settings["manufactured"]:
        assert (ROOT / "config" / "order2" / f"{scene}.yaml").is_file()
    assert {case["order"] for case in settings["cases"].values()} == {1, 2}


def test_every_level_is_nested_in_the_reference():
    """The errors are exact only for meshes whose cells contain whole reference cells."""
    settings = _order2_settings()
    for name, case in settings["cases"].items():
        refine = 2 ** case.get("options", {}).get("levels", 0) if case["family"] == "hanging" else 1
        for n in case["levels"]:
            assert settings["reference"]["n"] % (n * refine) == 0 and n * refine < settings["reference"]["n"], (name, n)


def test_the_paper_workflow_refuses_order2_overrides(tmp_path):
    """Table 1 and the convergence study measure Pi_1 of vertex values: k = 2 would be mis-measured."""
    import yaml
    from test_workflow import dry_run

    path = tmp_path / "k2.yaml"
    path.write_text(yaml.safe_dump({"overrides": ["discretization.order=2"]}))
    run = dry_run("--configfile", str(path))
    message = run.stdout + run.stderr
    assert run.returncode != 0
    assert "discretization.order = 2" in message and "Traceback" not in message


def test_the_tradeoff_study_runs_the_k2_families():
    import yaml

    families = yaml.safe_load((ROOT / "config" / "sweeps.yaml").read_text(encoding="utf-8"))["tradeoff"]["families"]
    k2 = [name for name, spec in families.items() if spec.get("order") == 2]
    assert k2
    jobs = planned_jobs("results/tradeoff/pareto.md")
    assert jobs["tradeoff_family"] == len(families)
