"""vemkit.studies.mindlin: Johnson's shear traction (its limits: full slip is mu times Hertz's
pressure, full stick at the centre), and the loading in steps on a small box (every step passes the
independent check with its own reference; a repeated load step changes nothing)."""

import math

import numpy as np

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.studies.mindlin import loading_in_steps, mindlin_shear

SSN = {"method": "ssn", "tol": 1e-10, "linear": "direct"}


def test_mindlin_shear_limits():
    a, mu, P = 0.1, 0.3, 2e-3
    r = np.linspace(0.0, a, 7)
    p = 3 * P / (2 * math.pi * a**2) * np.sqrt(1 - (r / a) ** 2)  # Hertz
    assert np.allclose(mindlin_shear(r, a, 0.0, mu, P), mu * p, rtol=1e-14, atol=0)
    assert np.allclose(mindlin_shear(r, a, a, mu, P), 0.0, atol=1e-18)  # Q = 0: no shear


def _box(shift):
    data = {
        "model": "3d",
        "domain": {"box": [[0, 0, 0], [1, 1, 0.5]]},
        "material": {"E": 1000.0, "nu": 0.3},
        "boundary": {"dirichlet": {"top": [shift, 0.0, -0.01]}, "contact": ["bottom"]},
        "contact": {"gap": "0.002*x", "normal": {"k": 200.0, "m": 1.0}, "friction": {"k": 60.0, "m": 1.0}},
        "discretization": {"mesh": {"family": "hex", "n": 3}},
    }
    return scene_problem(scene_from_dict(data))


def test_loading_in_steps_on_a_box():
    steps = loading_in_steps(_box, [0.001, 0.002, 0.002], SSN)
    assert all(check["passed"] for *_, check in steps)
    (_, _, previous, _, _), (_, _, again, reference, _) = steps[-2:]
    assert np.max(np.abs(again.u - previous.u)) < 1e-10 * np.max(np.abs(previous.u))
    assert np.allclose(reference, steps[-2][1].contact.tangential_displacement(previous.u))
