"""Issue 37, cause 6 (the headers part): a runs table as spreadsheets write it. `k_x [N/mm]` and
`length [mm]` headers (promised by `load_table`'s docstring) were refused, `k_x [N/m]` got "no
coefficient columns" instead of the unit, and Excel's `sep=,` first line got "missing factor
column(s)". Through `calibrate`, the command a user feeds their own spreadsheet."""

from __future__ import annotations

import json

import pytest
from clitools import assert_clean_failure, run_inprocess

ROW = "60,24,4.5,9,0.16,0,0.8,0.002\n"
PLAIN = "density,length,width,height,layer,raster,k_x,c_x\n" + ROW


@pytest.fixture(scope="module")
def plain_report(tmp_path_factory):
    from designer.model.calibration import calibrate, report
    from designer.model.surrogate import Surrogate

    p = tmp_path_factory.mktemp("plain") / "runs.csv"
    p.write_text(PLAIN)
    return report(calibrate(Surrogate.load(), p))


@pytest.mark.parametrize(
    "text",
    [
        "density [%],length [mm],width [mm],height [mm],layer [mm],raster [deg],k_x [N/mm],c_x [N.s/mm]\n"
        + ROW,
        "density,length [mm],width,height,layer,raster,k_x [N/mm],c_x\n" + ROW,
        "sep=,\n" + PLAIN,
        "\ufeffsep=,\r\n" + PLAIN.replace("\n", "\r\n"),
    ],
    ids=["brackets", "some brackets", "excel sep", "excel sep bom crlf"],
)
def test_spreadsheet_headers_read_as_the_plain_table(text, plain_report, tmp_path, capsys):
    (tmp_path / "runs.csv").write_bytes(text.encode())
    code, out, err = run_inprocess(["calibrate", tmp_path / "runs.csv", "--json"], capsys)
    assert code == 0, err
    got = json.loads(out)["responses"]["k_x"]["printer_factor"]
    assert got == pytest.approx(plain_report["responses"]["k_x"]["printer_factor"])


def test_a_header_in_another_unit_is_named(tmp_path, capsys):
    (tmp_path / "runs.csv").write_text(PLAIN.replace("k_x,", "k_x [N/m],").replace("0.8,", "800,"))
    code, _, err = run_inprocess(["calibrate", tmp_path / "runs.csv"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "'N/m'" in err and "N/mm" in err, err
