"""Issue 37, cause 10 (in part): `Session.run` with wrong types raised plain AttributeError or
TypeError (a str or int for parameters, a str duration) or tried to allocate a duration of 1e300 s,
and refused numpy's float32 and int64 numbers. Now: DesignerError naming the argument, numpy scalars
accepted and run like Python floats."""

from __future__ import annotations

import numpy as np
import pytest
from clitools import ARM_SCENARIO

from designer.cosim import load
from designer.cosim.session import prepare
from designer.errors import DesignerError


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    path = tmp_path_factory.mktemp("arm") / "arm.toml"
    path.write_text(ARM_SCENARIO)
    with prepare(load(path)) as s:
        yield s


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"parameters": "j1"}, "parameters is a str"),
        ({"parameters": 5}, "parameters is an int"),
        ({"parameters": {"j1": 0.3}}, "parameters['j1'] is a float"),
        ({"parameters": {"j1": {"theta.k": "0.3"}}}, "is not a finite number"),
        ({"parameters": {"j1": {"theta.k": np.bool_(True)}}}, "is not a finite number"),
        ({"duration": "2"}, "duration"),
        ({"duration": 1e300}, "memory"),
        ({"duration": -1.0}, "duration"),
        # it ran, diverged and advised "a smaller step"
        ({"parameters": {"j1": {"theta.c": 1e308}}}, "N.m.s/rad is beyond any physical joint"),
    ],
    ids=[
        "str",
        "int",
        "joint float",
        "text value",
        "numpy bool",
        "str duration",
        "1e300 s",
        "negative",
        "c 1e308",
    ],
)
def test_wrong_arguments_are_named(session, kwargs, words):
    with pytest.raises(DesignerError, match=words.replace("[", r"\[").replace("]", r"\]")):
        session.run(**kwargs)


def test_numpy_numbers_run_as_python_floats(session):
    session.run({"j1": {"theta.offset": np.int64(0)}}, duration=0.01)
    plain = session.run({"j1": {"theta.k": 0.25, "theta.c": 8.3e-4}}, duration=0.05)
    numpy = session.run(
        {"j1": {"theta.k": np.float32(0.25), "theta.c": np.float64(8.3e-4)}}, duration=np.float64(0.05)
    )
    assert numpy.laws["j1"]["k"] == 0.25 and numpy.laws["j1"]["c"] == 8.3e-4
    assert np.allclose(numpy.values, plain.values, rtol=1e-6, atol=1e-12)


def test_enabled_switches_the_spring_damper_as_documented(session):
    """The FMU's documented Boolean `theta.enabled` (it was refused as "not a finite number", a
    Boolean having no Real setter). Off, the joint is free: the same trace as k = c = 0, and the laws
    the metrics and references use say so; a number for it is refused."""
    off = session.run({"j1": {"theta.enabled": False}}, duration=0.2)
    free = session.run({"j1": {"theta.k": 0.0, "theta.c": 0.0}}, duration=0.2)
    on = session.run({"j1": {"theta.enabled": np.bool_(True)}}, duration=0.2)
    plain = session.run(None, duration=0.2)
    assert np.array_equal(off.values, free.values)
    assert off.laws["j1"]["k"] == 0.0 and off.laws["j1"]["c"] == 0.0
    assert np.array_equal(on.values, plain.values) and not np.array_equal(on.values, off.values)
    assert session.run(None, duration=0.2).laws == plain.laws  # a case's switch does not stick
    with pytest.raises(DesignerError, match="is not true or false"):
        session.run({"j1": {"theta.enabled": 0}})
