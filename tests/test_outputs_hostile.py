"""Issue 37, cause 2: outputs that would destroy a user's files. A folder of the user's named like a
file the command writes (res/metrics.json, sw/summary.json) was replaced with everything in it, and
`identify log.csv -o log.csv` overwrote the raw log; each is refused before any work, naming the path,
and the user's files stay as they were."""

from __future__ import annotations

import pytest
from clitools import ARM_SCENARIO, SIX_FLAGS, assert_clean_failure, run_inprocess, snapshot

from designer.errors import DesignerError
from designer.files import atomic_folder

SWEEP = (
    'scenario = "arm.toml"\n[sweep]\npath = "engine"\ncheck = 0\n[cases]\ntype = "grid"\n'
    "[cases.joints.j1]\nk = [300, 330]\n"
)


def users_folder(parent, name: str):
    """A folder of the user's named like an output file, with a file of theirs in it."""
    folder = parent / name
    folder.mkdir(parents=True)
    (folder / "notes.txt").write_text("mine\n")
    return folder


@pytest.mark.parametrize(
    "command, folder, name",
    [
        (["cosim", "arm.toml", "-o", "res"], "res", "metrics.json"),
        (["cosim", "arm.toml", "-o", "res"], "res", "plot.png"),
        (["sweep", "sweep.toml", "-o", "sw"], "sw", "summary.json"),
        (["sweep", "sweep.toml", "-o", "sw"], "sw", "results.parquet"),
    ],
)
def test_a_folder_named_like_an_output_file_is_refused_before_work(
    command, folder, name, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path.parent / "cache"))
    (tmp_path / "arm.toml").write_text(ARM_SCENARIO)
    (tmp_path / "sweep.toml").write_text(SWEEP)
    users_folder(tmp_path / folder, name)
    before = snapshot(tmp_path)
    code, out, err = run_inprocess(command, capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert f"{folder}/{name}" in err and "folder" in err, err
    assert snapshot(tmp_path) == before


def test_moving_results_in_never_replaces_a_folder_with_a_file(tmp_path):
    """The library's last line: a file staged for a name that is a folder there is refused, and
    nothing moves (also for a writer that did not name its files up front)."""
    target = tmp_path / "out"
    users_folder(target, "a.txt")
    (target / "b.txt").write_text("old\n")
    before = snapshot(tmp_path)
    with pytest.raises(DesignerError, match="a.txt"):
        with atomic_folder(target) as stage:
            (stage / "b.txt").write_text("new\n")
            (stage / "a.txt").write_text("new\n")
    assert snapshot(tmp_path) == before


@pytest.fixture(scope="module")
def rig_log(tmp_path_factory):
    """A rig log that identifies (20 s, 1-3 Hz), with its factor sidecar."""
    folder = tmp_path_factory.mktemp("log")
    args = ["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "20", "--f0", "1", "--f1", "3"]
    from designer_cli.main import run

    assert run([*args, *SIX_FLAGS, "-o", str(folder / "log.csv")]) == 0
    return folder / "log.csv"


@pytest.mark.parametrize("same", ["log.csv", "./link.csv"])
def test_identify_refuses_to_write_over_its_own_log(same, rig_log, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    for name in ("log.csv", "log.json"):
        (tmp_path / name).write_bytes((rig_log.parent / name).read_bytes())
    (tmp_path / "link.csv").symlink_to(tmp_path / "log.csv")
    before = snapshot(tmp_path)
    code, _, err = run_inprocess(["identify", "log.csv", "-o", same], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "log.csv" in err and "input" in err, err
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(
    "command",
    [
        ["clean", "t.csv", "--max-drop", "1", "-o", "t.csv"],
        ["doe", "--augment", "2", "--data", "t.csv", "-o", "t.csv"],
    ],
    ids=["clean", "doe"],
)
def test_table_commands_refuse_to_write_over_their_input(command, tmp_path, monkeypatch, capsys):
    from clitools import bundled_table

    monkeypatch.chdir(tmp_path)
    bundled_table().to_csv(tmp_path / "t.csv", index=False)
    before = snapshot(tmp_path)
    code, _, err = run_inprocess(command, capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "t.csv" in err and "input" in err, err
    assert snapshot(tmp_path) == before
