"""The verification report: its tables stand beside the published references, undefined entries
print as a dash, and a figure of every scene is drawn from a real solution (the Hertz one with the
contact panels)."""

import numpy as np
import pytest

from vemkit.report.verification import scene_figure, verification_markdown, von_mises
from vemkit.studies import verification as V


def _dataset():
    records = []
    for level, h in enumerate((0.4, 0.2)):
        records.append(
            {
                "scene": "kirsch",
                "family": "triangle",
                "level": level,
                "h": h,
                "n_dofs": 900 * 4**level,
                "error_h1": 0.05 * h / 0.4,
                "error_h1_semi": 0.1 * h / 0.4,
                "error_l2": 0.01 * (h / 0.4) ** 2,
                "stress_concentration": 2.9 + 0.1 * level,
            }
        )
    records.append(
        {
            "scene": "cook",
            "family": "triangle",
            "level": 0,
            "h": 1.0,
            "n_dofs": 2986,
            "v_mid": 23.877,
            "v_mid_difference": 23.877 / 23.96 - 1,
            "v_corner": 24.89,
        }
    )
    records.append(
        {
            "scene": "hertz",
            "family": "triangle",
            "level": 0,
            "h": 0.01,
            "n_dofs": 32142,
            "contact_force": 0.0046777,
            "radius": 1.0,
            "normal_k": 1e4,
            "half_width": 0.07532,
            "half_width_hertz": 0.07717,
            "half_width_difference": 0.07532 / 0.07717 - 1,
            "peak_pressure": 0.03911,
            "peak_pressure_hertz": 0.03859,
            "peak_pressure_difference": 0.03911 / 0.03859 - 1,
        }
    )
    return V.verification_dataset(records, commit="abc")


def test_tables_stand_beside_the_references():
    text = verification_markdown(_dataset())
    assert "| triangle | 1 | 2986 | 23.877 | -0.35 % | 24.89 |" in text
    assert "| published | | | 23.96 | | |" in text
    kirsch = [line for line in text.splitlines() if line.startswith("| triangle | 0.2 |")][0]
    assert "| 1.000 |" in kirsch and "| 2.000 |" in kirsch and kirsch.endswith("| 3.0000 |")
    first = [line for line in text.splitlines() if line.startswith("| triangle | 0.4 |")][0]
    assert first.count("| – |") == 3  # no order at the coarsest size
    assert "| triangle | 0.01 | 32142 | 0.004678 | 0.07532 | 0.07717 | -2.40 % | 0.03911 | 0.03859 | +1.35 % |" in text
    assert "k_ν = 10000" in text and "L-bracket" not in text  # a scene without runs has no section
    for table in text.split("\n\n"):
        rows = [line for line in table.splitlines() if line.startswith("|")]
        assert len({row.count("|") for row in rows}) <= 1, rows[0]  # every row as wide as its header


@pytest.mark.parametrize("name, family, h", [("kirsch", "voronoi", 0.4), ("hertz", "triangle", 0.02)])
def test_scene_figures_draw_a_real_solution(name, family, h):
    from pathlib import Path

    kept = {}
    scene = Path(__file__).resolve().parents[2] / "config" / "scenes" / f"{name}.yaml"
    (run,) = V.run_case(
        name, scene, family, sizes=(h,), on_solution=lambda _, problem, ds: kept.update(p=problem, ds=ds)
    )
    hertz = (run["half_width_hertz"], run["peak_pressure_hertz"]) if name == "hertz" else None
    fig = scene_figure(name, kept["p"].mesh, kept["ds"], hertz=hertz)
    assert len(fig.axes) >= (6 if name == "hertz" else 3)
    s11, s22, s12 = (kept["ds"][k].values for k in ("stress_11", "stress_22", "stress_12"))
    assert np.allclose(von_mises(kept["ds"]) ** 2, 0.5 * ((s11 - s22) ** 2 + s11**2 + s22**2) + 3 * s12**2)
