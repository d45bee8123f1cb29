"""Scenarios end to end through exported joint FMUs: robot, virtual rig, checks, outputs, CLI."""

import importlib
import json
import textwrap
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from designer.cosim import load, prepare, run, write_outputs
from designer.cosim.robot_scenario import robot_reference
from designer.errors import DesignerError

# the module, not the function `designer.cosim.run` that shadows it as an attribute of the package
cosim_run = importlib.import_module("designer.cosim.run")
cosim_session = importlib.import_module("designer.cosim.session")

ARM = """
[simulation]
duration = {duration}
step = {step}
[robot]
model = "arm"
[joints.j1]
coefficients = {{ k = 330, c = 0.83 }}
reference = {{ type = "sine", amplitude = 0.5, frequency = 0.5 }}
[joints.j2]
{joint2}
reference = {{ type = "step", amplitude = 0.3, at = 0.2 }}
[validation]
duration = 0.5
steps = [2e-3, 1e-3, 5e-4, 2.5e-4]
"""
J2 = "coefficients = { k = 330, c = 0.83 }\nfmi_version = 3"
RIG = """
[simulation]
duration = 20.0
step = 1e-3
[rig]
sweep = 20.0
joint = { axis = "theta", coefficients = { k = 330, c = 0.83, m = 2e-6 } }
factors = { density = 60, length = 24, width = 4.5, height = 9, layer = 0.16, raster = 45 }
[validation]
duration = 0.5
steps = [1e-3, 5e-4, 2.5e-4, 1.25e-4]
"""


def write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def arm(tmp_path, duration=10.0, step=1e-3, joint2=J2):
    return write(tmp_path, ARM.format(duration=duration, step=step, joint2=joint2))


def test_two_link_arm_through_fmus_matches_in_engine_reference(tmp_path):
    sc = load(arm(tmp_path))
    with prepare(sc) as session:
        laws = session.laws(session.parameters(None))
        res = session.trace()
    ref = robot_reference(sc, laws, sc.step, sc.duration, "euler")
    assert laws["j1"]["k"] == pytest.approx(0.33) and laws["j1"]["c"] == pytest.approx(8.3e-4)
    for j in sc.joints:
        assert np.abs(res.column(f"robot.{j}.q") - ref.column(f"robot.{j}.q")).max() <= 1e-6
    assert np.abs(res.column("robot.j2.s")).max() > 0.05


def test_validation_error_falls_with_step_and_outputs(tmp_path):
    out = tmp_path / "out"
    result = run(load(arm(tmp_path, duration=1.0)), validate=True)
    write_outputs(result, out)
    val = result.validation
    assert val["max_error"] <= 1e-9
    rows = val["steps"]
    for big, small in zip(rows, rows[1:], strict=False):
        assert small["max_error"] <= big["max_error"] * small["step"] / big["step"] * 1.05
    assert {p.name for p in out.iterdir()} == {
        "timeseries.csv",
        "timeseries.parquet",
        "metrics.json",
        "plot.png",
    }
    assert json.loads((out / "metrics.json").read_text())["metrics"]["j2"]["overshoot_pct"] >= 0


def test_rig_log_identifies_the_fmus_coefficients(tmp_path):
    from designer.rig.identify import identify

    out = tmp_path / "rig"
    result = run(load(write(tmp_path, RIG)), validate=True)
    write_outputs(result, out, plot=False)
    summary = result.summary()
    fit = identify(out / "rig_log.csv")[0].axes["theta"]
    assert fit.k == pytest.approx(330, rel=5e-3)
    assert fit.c == pytest.approx(0.83, rel=5e-3)
    rows = summary["validation"]["steps"]
    for big, small in zip(rows, rows[1:], strict=False):
        assert small["max_error"] <= big["max_error"] * small["step"] / big["step"] * 1.05


@pytest.mark.parametrize(
    "joint2, step, message",
    [
        ('fmu = "missing.fmu"', 1e-3, "missing.fmu does not exist"),
        (J2, -1e-3, "step = -0.001 must be positive"),
    ],
)
def test_bad_scenarios_fail_before_running(tmp_path, joint2, step, message):
    with pytest.raises(DesignerError, match=message):
        load(arm(tmp_path, step=step, joint2=joint2))


def test_unknown_robot_joint_fails_before_running(tmp_path):
    path = write(
        tmp_path, ARM.format(duration=1, step=1e-3, joint2=J2).replace("[joints.j2]", "[joints.elbow]")
    )
    with pytest.raises(DesignerError, match="no joint 'elbow'"):
        load(path)


def test_interrupted_run_leaves_complete_files_or_none(tmp_path, monkeypatch):
    sc = load(arm(tmp_path, duration=0.2))
    out = tmp_path / "out"

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cosim_run, "plot_result", interrupt)
    with pytest.raises(KeyboardInterrupt):
        write_outputs(run(sc), out)
    # the files are staged and moved in together: none of them (issue 26: a lone timeseries.csv)
    assert not out.exists()
    write_outputs(run(sc), out, plot=False)  # into an existing folder: the old set stays whole
    assert len(np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)) == 201
    (out / "notes.txt").write_text("the user's")
    with pytest.raises(KeyboardInterrupt):
        write_outputs(run(sc), out)
    assert sorted(p.name for p in out.iterdir()) == [
        "metrics.json",
        "notes.txt",
        "timeseries.csv",
        "timeseries.parquet",
    ]
    monkeypatch.setattr(cosim_session, "run_master", interrupt)
    with pytest.raises(KeyboardInterrupt):
        write_outputs(run(sc), tmp_path / "none")
    assert not (tmp_path / "none").exists()


def test_cli_json(tmp_path):
    from designer_cli import cosim

    app = typer.Typer()
    app.callback()(lambda: None)
    cosim.register(app)
    result = CliRunner().invoke(
        app, ["cosim", str(arm(tmp_path, duration=0.5)), "-o", str(tmp_path / "o"), "--json"]
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert set(doc["metrics"]) == {"j1", "j2"} and "validation" not in doc


DESIGN = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 45}
DESIGN_TOML = "design = { density = 60, length = 24, width = 4.5, height = 9, layer = 0.16, raster = 45 }"


def _suggestion(tmp_path):
    from designer.design.suggestions import suggest
    from designer.model.surrogate import Surrogate

    doc = suggest(Surrogate.load(), k=0.8, fixed={"length": 24}, top=2).to_dict()
    (tmp_path / "s.json").write_text(json.dumps(doc))
    return doc


def test_joints_from_a_design_and_a_suggestion_run_through_the_surrogate(tmp_path):
    from designer import Joint

    doc = _suggestion(tmp_path)
    text = ARM.format(duration=0.3, step=1e-3, joint2='suggestion = "s.json"\ncandidate = 2')
    sc = load(write(tmp_path, text.replace("coefficients = { k = 330, c = 0.83 }", DESIGN_TOML)))
    expect = {
        "j1": Joint.from_design(DESIGN, axes=["theta"]).axes["theta"],
        "j2": Joint.from_suggestion(tmp_path / "s.json", candidate=2, axes=["theta"]).axes["theta"],
    }
    # the suggestion's k on x (N/mm) taken to theta with the PRB model: K = k (0.85 L)^2
    k2 = doc["candidates"][1]["predicted"]["k"]["value"] * (0.85 * 24) ** 2
    assert expect["j2"].k == pytest.approx(k2, rel=1e-9) and 250 < k2 < 420
    with prepare(sc) as session:
        laws = session.laws(session.parameters(None))
        for j in sc.joints:
            assert laws[j]["k"] == pytest.approx(expect[j].k * 1e-3, rel=1e-9)  # N.mm/rad -> N.m/rad
            assert laws[j]["c"] == pytest.approx(expect[j].c * 1e-3, rel=1e-9)
        res = session.trace()
    assert np.abs(res.column("robot.j2.s")).max() > 0.01
    assert sc.joints["j2"].joint.provenance["source"] == "suggestion s.json, candidate 2"


def test_rig_joint_from_a_design_has_the_predicted_mass(tmp_path):
    text = RIG.replace("coefficients = { k = 330, c = 0.83, m = 2e-6 }", DESIGN_TOML)
    src = load(write(tmp_path, text)).rig_joint
    theta = src.joint.axes["theta"]
    assert theta.m is not None and theta.m > 0 and theta.k > 0


@pytest.mark.parametrize(
    "joint2, message",
    [
        ('suggestion = "nothing.json"', "cannot read a suggestion"),
        ('suggestion = "s.json"\ncandidate = 9', "candidate 9 does not exist"),
        ('suggestion = "s.json"\ncandidate = "best"', "is not a whole number"),
        ("coefficients = { k = 1, c = 1 }\ncandidate = 1", "candidate needs a suggestion"),
        ('suggestion = "s.json"\n' + DESIGN_TOML, "it has: design, suggestion"),
        ("design = { density = 60 }", "missing factor"),
        ('design = "good"', "design must be a table"),
        (DESIGN_TOML.replace("density = 60", "density = 300"), "outside the tested range"),
    ],
)
def test_bad_design_and_suggestion_joints_fail_before_running(tmp_path, joint2, message):
    _suggestion(tmp_path)
    with pytest.raises(DesignerError, match=message):
        load(arm(tmp_path, joint2=joint2))


def test_the_arm_example_takes_its_joints_from_a_suggestion():
    examples = Path(__file__).resolve().parent.parent / "examples"
    sc = load(examples / "two_link_arm.toml")
    for name, candidate in (("j1", 1), ("j2", 2)):
        assert (
            sc.joints[name].joint.provenance["source"] == f"suggestion suggestion.json, candidate {candidate}"
        )
        assert 250 < sc.joints[name].joint.axes["theta"].k < 420  # N.mm/rad
    assert "designer suggest --k 0.8 --fix length=24" in (examples / "two_link_arm.sh").read_text()


def _coded(**changes):
    from designer import Joint
    from designer.cosim import JointSource, Scenario, Sine

    joint = Joint.from_coefficients({"theta": {"k": 330, "c": 0.83}}, name="j1")
    kwargs = dict(
        duration=0.2, step=1e-3, joints={"j1": JointSource(joint=joint)}, motors={"j1": Sine(0.5, 0.5)}
    )
    return Scenario(**(kwargs | changes))


def test_scenario_built_in_code_runs_in_memory_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    sc = _coded().check()
    assert sc.kind == "robot" and sc.outputs == {"csv": True, "parquet": True, "plot": True}
    result = run(sc)
    frame = result.to_frame()
    assert list(frame.columns[:1]) == ["t"] and len(frame) == 201
    assert frame["t"].iloc[-1] == pytest.approx(0.2)
    assert "robot.j1.q" in frame and "j1.theta.f" in frame
    assert set(result.metrics) == {"j1"} and result.laws["j1"]["k"] == pytest.approx(0.33)
    assert list(tmp_path.iterdir()) == []
    # the same scenario from TOML gives the same numbers, bit for bit
    text = ARM.format(duration=0.2, step=1e-3, joint2="").split("[joints.j2]")[0]
    np.testing.assert_array_equal(run(load(write(tmp_path, text))).values, result.values)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"step": 0}, "step = 0 must be positive"),
        ({"duration": float("nan")}, "duration = nan is not a finite number"),
        ({"duration": 1e-4}, "shorter than step"),
        ({"algorithm": "newton"}, "algorithm = 'newton' is not allowed"),
        ({"joints": {}}, "needs joints"),
        ({"motors": {"j9": None}}, "motors name joint"),
        ({"outputs": {"pdf": True}}, "not a set of switches"),
        ({"duration": 1e9}, "needs about .* of memory, .* available"),
        ({"validation_steps": (1e-3,)}, "fewer than two steps"),
        # issue 37, cause 8: 100 000 duplicate steps ran one after another
        ({"validation_steps": (1e-3,) * 100_000}, "lists 0.001 more than once"),
        ({"validation_steps": tuple(1e-3 / (i + 1) for i in range(11))}, "lists 11 steps; .* 2 to 10"),
    ],
)
def test_invalid_scenario_built_in_code_is_refused_naming_the_field(changes, message):
    sc = _coded(**changes)  # building stores; checking (by load, prepare, run) refuses
    with pytest.raises(DesignerError, match=message):
        sc.check()
    with pytest.raises(DesignerError, match=message):
        run(sc)


def test_joint_source_checks_its_fields():
    from designer import Joint
    from designer.cosim import JointSource

    joint = Joint.from_coefficients({"theta": {"k": 330, "c": 0.83}})
    with pytest.raises(DesignerError, match="exactly one of fmu= or joint="):
        JointSource().check()
    with pytest.raises(DesignerError, match="has no axis 'x'"):
        JointSource(axis="x", joint=joint).check()
    with pytest.raises(DesignerError, match="'theta.stiffness' is not a parameter"):
        JointSource(joint=joint, parameters={"theta.stiffness": 1.0}).check()


def test_an_fmu_on_the_wrong_axis_is_refused_with_the_export_that_fixes_it(tmp_path, capsys):
    """README's first hour once said nothing of the axis: an FMU exported on x given to a hinge was
    refused with "has no axis theta (it has: x)" and no way out. The refusal names the export line."""
    from clitools import run_inprocess

    fmu = tmp_path / "joint.fmu"
    export = ["export", "fmu", "--k", "0.8", "--c", "2e-3", "--platforms", "host", "-o", fmu]
    assert run_inprocess(export, capsys)[0] == 0
    scenario = arm(tmp_path, duration=0.1, joint2='fmu = "joint.fmu"')
    code, _, err = run_inprocess(["cosim", scenario, "-o", tmp_path / "out"], capsys)
    assert code == 2 and "Traceback" not in err
    assert "has no axis theta (it has: x; export the joint on axis theta:" in err
    assert "`designer export fmu ... --axis theta`" in err
    export[export.index("-o") : export.index("-o")] = ["--axis", "theta"]  # the fix, as stated
    assert run_inprocess(export, capsys)[0] == 0
    assert run_inprocess(["cosim", scenario, "-o", tmp_path / "out"], capsys)[0] == 0


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("duration = 1", "duraton = 1", "unknown key 'duraton' in \\[simulation\\].*did you mean 'duration'"),
        ('model = "arm"', 'modle = "arm"', "unknown key 'modle' in \\[robot\\].*did you mean 'model'"),
        ('type = "step", amplitude', 'type = "step", amplitud = 1, amplitude', "unknown key 'amplitud'"),
        (
            "coefficients = { k = 330, c = 0.83 }\nreference",
            "coefficients = { k = 330, c = 0.83, stifness = 2 }\nreference",
            "unknown key",
        ),
    ],
)
def test_typos_in_scenario_keys_are_named_with_the_closest_key(tmp_path, old, new, message):
    text = ARM.format(duration=1, step=1e-3, joint2=J2)
    assert old in text
    with pytest.raises(DesignerError, match=message):
        load(write(tmp_path, text.replace(old, new, 1)))


def test_joint_parameters_from_an_ssv_file(tmp_path):
    from designer import Joint
    from designer.export.ssp import ssv_text

    stiffer = Joint.from_coefficients({"theta": {"k": 660, "c": 0.83}}, name="j1")
    (tmp_path / "j1.ssv").write_text(ssv_text(stiffer, "j1"))
    text = ARM.format(duration=0.3, step=1e-3, joint2=J2)
    text = text.replace(
        "coefficients = { k = 330, c = 0.83 }\nreference",
        'coefficients = { k = 330, c = 0.83 }\nparameters = "j1.ssv"\nreference',
        1,
    )
    sc = load(write(tmp_path, text))
    assert sc.joints["j1"].parameters["theta.k"] == pytest.approx(0.66)  # N.mm/rad in the SSV's units -> SI
    assert run(sc).laws["j1"]["k"] == pytest.approx(0.66)
