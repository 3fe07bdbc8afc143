"""Report spine: atomic outputs, table rendering, provenance in the index, CLI errors."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from gaitval.cli import main
from gaitval.io.atomic import atomic_path, write_text
from gaitval.report.index import build_index
from gaitval.report.provenance import config_hash, stamp
from gaitval.tables import write_table


def test_interrupted_write_leaves_nothing_that_looks_complete(tmp_path):
    target = tmp_path / "t.csv"
    write_text(target, "old\n")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half a fi")
            raise RuntimeError("killed")
    assert target.read_text() == "old\n"          # previous complete file untouched
    assert list(tmp_path.iterdir()) == [target]    # no temporary file left behind


def test_write_table_three_formats_agree_and_are_deterministic(tmp_path):
    df = pd.DataFrame({"method": ["Method 1", "Method 2"], "rmse_x_m": [0.0512, np.nan],
                       "rmse_x_m_published": [0.051, 0.047], "n": [3, 4]})
    a = write_table(df, tmp_path / "a" / "tug_table9", caption="Test caption", notes=["a note"])
    b = write_table(df, tmp_path / "b" / "tug_table9", caption="Test caption", notes=["a note"])
    for pa, pb in zip(a, b):
        assert pa.read_bytes() == pb.read_bytes()
    back = pd.read_csv(a[0])
    assert list(back.columns) == list(df.columns)
    assert back["rmse_x_m"].iloc[0] == pytest.approx(0.0512)
    md = a[1].read_text()
    assert "| Method 1 | 0.051 | 0.051 | 3 |" in md and "a note" in md
    assert "| Method | RMSE x (m) | RMSE x (m), published | n |" in md      # labels
    tex = a[2].read_text()
    assert "RMSE x (m)" in tex and "rmse" not in tex.lower().replace("rmse x", "")


def test_index_lists_items_with_provenance_and_missing_tables(tmp_path):
    rd = tmp_path / "reports"
    paths = write_table(pd.DataFrame({"a": [1]}), rd / "tables" / "tug_table4",
                        caption="Occlusion rate and RMSE")
    h = config_hash({"run": ["tiny"]})
    stamp("tug_tables", paths, rd, config_hash_=h, command="gaitval tables tug")
    md, html = build_index(rd, study_names=["tiny"])
    text = md.read_text()
    assert "### tug_table4" in text and "Occlusion rate and RMSE" in text
    assert f"config {h}" in text and "made by step `tug_tables`" in text
    assert "[record](provenance/tug_tables.json)" in text
    assert "gaitval tables tug" not in text             # the command is in the record
    assert "Not produced yet: tug_table2, tug_table3, tug_table5" in text
    assert "tug_table4" in html.read_text()
    rec = json.loads((rd / "provenance" / "tug_tables.json").read_text())
    assert rec["items"] == ["tables/tug_table4.csv", "tables/tug_table4.md",
                            "tables/tug_table4.tex"]


def test_cli_user_error_is_one_line_per_problem_and_exit_1(tmp_path, capsys):
    """Exit codes (README): 1 for a data error, 2 for a usage error (issue 15)."""
    sheet = tmp_path / "trials.csv"
    sheet.write_text("study,protocol\nx,tug\n")
    rc = main(["validate", str(sheet)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and err[-1].endswith("2 problems")      # every problem, then the count
    assert all(e.startswith("gaitval: error: [file ") for e in err[:-1])
    assert "missing required column" in err[0] and "subject table not found" in err[1]
    with pytest.raises(SystemExit) as exc:
        main(["validate"])
    assert exc.value.code == 2


def test_captions_and_notes_name_columns_by_their_headers(tmp_path):
    """A caption or note that names a column by its machine name (bare or in backticks)
    shows the header the reader sees instead; method names and other words are kept."""
    df = pd.DataFrame({"method": ["tug_m1"], "ft_forward": [1], "diff_mean_m": [0.1]})
    _, md, tex = write_table(df, tmp_path / "tug_table9",
                             caption="Counts; ft_forward has no published counterpart.",
                             notes=["`diff_mean_m` is system minus reference for tug_m1"])
    text = md.read_text()
    assert "_False tracking, forward_ has no published" in text
    assert "- _Difference mean (m)_ is system minus reference for tug_m1" in text
    assert "ft_forward" not in tex.read_text() and "diff" not in tex.read_text().lower() \
        .replace("difference", "")


def test_a_report_with_the_crowd_table_says_its_scenes_are_simulated(tmp_path):
    """The legbench run's data are real recordings, but its crowd table's scenes are
    rendered by the twin: the data lines at the top say so, and only when that table is
    there."""
    rd = tmp_path / "reports" / "legbench"
    write_table(pd.DataFrame({"kind": ["crossing_static"], "mota_pct": [40.0]}),
                rd / "tables" / "legbench_clearmot", caption="CLEAR-MOT")
    build_index(rd, study_names=["legbench"])
    assert "simulated scenes" not in (rd / "index.md").read_text()
    write_table(pd.DataFrame({"kind": ["crossing_static"], "mota_pct": [40.0]}),
                rd / "tables" / "legbench_crowd", caption="Crowd")
    build_index(rd, study_names=["legbench"])
    for name in ("index.md", "index.html"):
        text = (rd / name).read_text()
        assert "legbench_crowd" in text and "simulated scenes" in text, name
