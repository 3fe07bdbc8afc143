"""gaitval compare-tables: numbers within a relative tolerance, counts and text exactly
(gaitval/report/compare.py, docs/numerics.md)."""
from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from gaitval.cli import main
from gaitval.errors import GaitvalError
from gaitval.report.compare import compare_folders, compare_frames

HEAD = "method,n_trials,rmse_m,outcome\n"


def _frame(text: str) -> pd.DataFrame:
    from io import StringIO

    return pd.read_csv(StringIO(text), dtype=str, keep_default_na=False)


def _cmp(a: str, b: str, **kw):
    return compare_frames("t.csv", _frame(HEAD + a), _frame(HEAD + b), **{"rtol": 1e-9, **kw})


def test_identical_tables_agree():
    d = _cmp("m1,12,0.0123456,reproduced\n", "m1,12,0.0123456,reproduced\n")
    assert d.ok and d.n_numbers == 1 and d.n_differ == 0 and d.worst == 0.0


def test_numbers_within_and_beyond_the_relative_tolerance():
    near = _cmp("m1,12,1.00000000001e-3,x\n", "m1,12,1e-3,x\n")
    assert near.ok and near.n_differ == 1 and 0 < near.worst < 1e-9
    far = _cmp("m1,12,0.0123,x\n", "m1,12,0.0124,x\n")
    assert not far.ok and far.worst == pytest.approx(0.0001 / 0.0124)
    assert "rmse_m: 0.0123 vs 0.0124" in far.where
    assert _cmp("m1,12,0.0123,x\n", "m1,12,0.0124,x\n", rtol=0.01).ok


def test_one_unit_in_the_sixth_printed_digit_is_rounding():
    """Two values closer than rtol print one unit apart when they straddle a rounding
    boundary of the tables' 6 significant digits; --strict-digits fails them."""
    d = _cmp("m1,12,0.0123457,x\n", "m1,12,0.0123456,x\n")
    assert d.ok and d.n_last_digit == 1
    assert not _cmp("m1,12,0.0123457,x\n", "m1,12,0.0123456,x\n", last_digit=False).ok
    assert not _cmp("m1,12,0.0123458,x\n", "m1,12,0.0123456,x\n").ok     # two units


def test_counts_text_and_empty_cells_must_be_equal():
    count = _cmp("m1,12,0.5,x\n", "m1,13,0.5,x\n", rtol=0.5)
    assert not count.ok and "n_trials (count): '12' vs '13'" in count.exact[0]
    text = _cmp("m1,12,0.5,reproduced\n", "m1,12,0.5,not reproduced\n")
    assert not text.ok and "outcome (text)" in text.exact[0]
    empty = _cmp("m1,12,,x\n", "m1,12,0.5,x\n", rtol=1.0)
    assert not empty.ok and "rmse_m" in empty.exact[0]
    assert _cmp("m1,12,,x\n", "m1,12,,x\n").ok


def test_shape_and_columns_are_checked():
    d = compare_frames("t.csv", _frame(HEAD + "m1,1,0.5,x\nm2,1,0.5,x\n"),
                       _frame(HEAD + "m1,1,0.5,x\n"), rtol=1e-9)
    assert not d.ok and "2 rows vs 1" in d.exact
    d = compare_frames("t.csv", _frame("a,b\n1,2\n"), _frame("a,c\n1,2\n"), rtol=1e-9)
    assert not d.ok and d.exact[0].startswith("columns differ")


def _folder(root: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)
    return root


def test_folders_cli_exit_status_and_ignore(tmp_path, capsys):
    a = _folder(tmp_path / "a", {"tables/t1.csv": HEAD + "m1,12,0.0123,x\n",
                                 "verdicts.csv": "study,outcome\ntug,reproduced\n",
                                 "tables/only_a.csv": "x\n1\n"})
    b = _folder(tmp_path / "b", {"tables/t1.csv": HEAD + "m1,12,0.0123000001,x\n",
                                 "verdicts.csv": "study,outcome\ntug,reproduced\n"})
    diffs = {d.name: d for d in compare_folders(a, b, rtol=1e-6)}
    assert diffs["tables/t1.csv"].ok and diffs["verdicts.csv"].ok
    assert not diffs["tables/only_a.csv"].ok
    assert main(["compare-tables", str(a), str(b), "--rtol", "1e-6"]) == 1
    out = capsys.readouterr().out
    assert "2 of 3 tables agree within rtol 1e-06" in out and "only_a.csv" in out
    assert main(["compare-tables", str(a), str(b), "--rtol", "1e-6",
                 "--ignore", "tables/only_a.csv"]) == 0
    assert main(["compare-tables", str(a), str(b), "--rtol", "1e-12",
                 "--ignore", "tables/only_a.csv"]) == 0            # below the 6th digit
    assert main(["compare-tables", str(a), str(b), "--rtol", "1e-12", "--strict-digits",
                 "--ignore", "tables/only_a.csv"]) == 1


def test_a_missing_folder_is_one_clear_error(tmp_path, capsys):
    with pytest.raises(GaitvalError, match="not a folder"):
        compare_folders(tmp_path / "nope", tmp_path, rtol=1e-9)
    assert main(["compare-tables", str(tmp_path / "nope"), str(tmp_path)]) == 1
    assert "nope" in capsys.readouterr().err
