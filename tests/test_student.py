"""designer.model.student against scipy.special's stdtr and stdtrit (what it replaces on the path of
suggest and next), and the import it saves."""

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.special import stdtr, stdtrit

from designer.errors import DesignerError
from designer.model import student

#: the study's degrees of freedom (c_x 43, k_x 37.35...) among others up to LARGE_DOF
DOFS = [1, 1.5, 2, 3, 4.2, 5, 9, 10, 37.35225645940347, 43, 100, 300, 1000]
TS = [t for t in np.linspace(-40, 40, 401) if abs(t) > 0.01] + [0.5, -0.5, 2.0, 1e3, -1e3, -200.0]
PS = [1e-6, 0.025, 0.1, 0.3, 0.6, 0.9, 0.975, 0.995, 0.999999]


@pytest.mark.parametrize("dof", DOFS)
def test_cdf_and_quantile_agree_with_scipy_within_1e_12(dof):
    for t in TS:
        want = float(stdtr(dof, t))
        assert math.isclose(student.cdf(dof, float(t)), want, rel_tol=1e-12, abs_tol=1e-300), (dof, t)
    for p in PS:
        assert math.isclose(student.quantile(dof, p), float(stdtrit(dof, p)), rel_tol=1e-12), (dof, p)


def test_the_cauchy_case_is_exact_near_zero():
    """dof 1 is the Cauchy distribution: 1/2 + atan(t) / pi, where scipy's stdtr loses digits."""
    for t in (-1e-8, 1e-5, 0.3, -2.0):
        assert math.isclose(student.cdf(1, t), 0.5 + math.atan(t) / math.pi, rel_tol=1e-14)


def test_beyond_large_dof_scipy_answers_and_bad_arguments_are_designer_errors():
    assert student.cdf(1e5, 1.3) == float(stdtr(1e5, 1.3))
    assert student.quantile(1e5, 0.975) == float(stdtrit(1e5, 0.975))
    assert (
        student.cdf(5, math.inf) == 1.0 and student.cdf(5, -math.inf) == 0.0 and student.quantile(5, 0.5) == 0
    )
    with pytest.raises(DesignerError, match="dof"):
        student.cdf(0, 1.0)
    with pytest.raises(DesignerError, match="probability"):
        student.quantile(5, 1.0)


def test_suggest_and_next_do_not_import_scipy():
    code = (
        "import sys\nfrom designer_cli.main import main\n"
        "for args in (['suggest', '--k', '0.8', '--c', '2e-3'], ['next', '--k', '0.8']):\n"
        "    sys.argv = ['designer', *args]\n"
        "    try:\n        main()\n    except SystemExit:\n        pass\n"
        "print('SCIPY', sorted(m for m in sys.modules if m.startswith('scipy.')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "SCIPY []"
