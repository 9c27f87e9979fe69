"""The Section 4 study's pipeline (workflow/rules/order2.smk): `snakemake order2` plans one solve per
(case, level), the k = 2 reference, one error job per case, the gathered file and the figure (the
default target's own test checks that it does not include them); every level nests in the reference."""

import ast
from pathlib import Path

from test_workflow import planned_jobs

ROOT = Path(__file__).resolve().parents[2]


def _order2_settings():
    text = (ROOT / "workflow" / "rules" / "order2.smk").read_text(encoding="utf-8")
    return ast.literal_eval(text[text.index("ORDER2 = {") + len("ORDER2 = "):text.index("ORDER2_CASES")])


def test_order2_plans_every_case_and_level():
    settings = _order2_settings()
    jobs = planned_jobs("order2")
    levels = sum(len(case["levels"]) for case in settings["cases"].values())
    assert jobs["order2_solve"] == levels
    assert jobs["order2_reference"] == 1 and jobs["order2_errors"] == len(settings["cases"])
    assert jobs["order2_gather"] == 1 and jobs["order2_figure"] == 1
    assert {case["order"] for case in settings["cases"].values()} == {1, 2}


def test_every_level_is_nested_in_the_reference():
    """The errors are exact only for meshes whose cells contain whole reference cells."""
    settings = _order2_settings()
    for name, case in settings["cases"].items():
        refine = 2 ** case.get("options", {}).get("levels", 0) if case["family"] == "hanging" else 1
        for n in case["levels"]:
            assert settings["reference"]["n"] % (n * refine) == 0 and n * refine < settings["reference"]["n"], (name, n)
