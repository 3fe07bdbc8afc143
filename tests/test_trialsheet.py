"""Trial sheet and subject table: a typo or a missing file gives one clear message."""
from __future__ import annotations

from pathlib import Path

import pytest

from gaitval.errors import TrialSheetError
from gaitval.io.trialsheet import load_trial_sheet

HEADER = ("study,protocol,subject,trial,sensor_kind,mocap_file,sensor_file,sensor_topic,"
          "annotation_file,sensor_height_m,clock_offset_s,speed,speed_mps,stick,scenario,"
          "repetition\n")
ROW = "s,tug,S01,tug_S01_1,lrs,m/a.c3d,l/a.scan.parquet,,,0.27,,,,false,,1\n"
SUBJECTS = "subject,group,leg_width_m,knee_width_m\nS01,young,0.10,0.10\n"


def make_study(tmp_path: Path, rows: str = ROW, subjects: str = SUBJECTS,
               header: str = HEADER) -> Path:
    for rel in ("m/a.c3d", "l/a.scan.parquet", "m/b.c3d", "l/b.bag"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(b"")
    (tmp_path / "subjects.csv").write_text(subjects)
    (tmp_path / "trials.csv").write_text(header + rows)
    return tmp_path / "trials.csv"


def test_valid_sheet_types_and_paths(tmp_path):
    df = load_trial_sheet(make_study(tmp_path))
    row = df.loc["tug_S01_1"]
    assert row["sensor_height_m"] == pytest.approx(0.27)
    assert row["stick"] is False or row["stick"] == False  # noqa: E712 (numpy bool)
    assert Path(row["mocap_path"]) == (tmp_path / "m/a.c3d").resolve()
    assert row["annotation_path"] == ""
    assert str(df["clock_offset_s"].dtype) == "float64"


@pytest.mark.parametrize("rows, expect", [
    (ROW.replace(",tug,", ",tugg,"), ["row 2", "trial 'tug_S01_1'", "'protocol'", "tugg"]),
    (ROW.replace("m/a.c3d", "m/zz.c3d"), ["row 2", "'mocap_file'", "m/zz.c3d", "not found"]),
    (ROW.replace(",0.27,", ",tall,"), ["row 2", "'sensor_height_m'", "tall"]),
    (ROW.replace(",false,", ",maybe,"), ["row 2", "'stick'", "maybe"]),
    (ROW.replace(",S01,", ",S99,"), ["row 2", "'subject'", "S99"]),
    (ROW + ROW, ["tug_S01_1", "rows [2, 3]", "unique"]),
    (ROW.replace("l/a.scan.parquet", "l/b.bag"), ["'sensor_topic'", "LaserScan topic"]),
    (ROW.replace(",lrs,", ",,"), ["row 2", "'sensor_kind'"]),
])
def test_bad_rows_name_row_and_column(tmp_path, rows, expect):
    with pytest.raises(TrialSheetError) as ei:
        load_trial_sheet(make_study(tmp_path, rows=rows))
    msg = str(ei.value)
    assert "trials.csv" in msg
    for piece in expect:
        assert piece in msg, msg


def test_column_typo_suggests_the_right_name(tmp_path):
    with pytest.raises(TrialSheetError, match=r"unknown column 'protocl'; did you mean 'protocol'"):
        load_trial_sheet(make_study(tmp_path, header=HEADER.replace("protocol", "protocl")))


def test_subject_table_errors(tmp_path):
    with pytest.raises(TrialSheetError, match=r"subjects.csv.*row 2 \(subject 'S01'\), column 'leg_width_m'"):
        load_trial_sheet(make_study(tmp_path, subjects=SUBJECTS.replace("0.10,0.10", "wide,0.10")))
    with pytest.raises(TrialSheetError, match="leg_width_m"):
        load_trial_sheet(make_study(tmp_path, subjects="subject,group\nS01,young\n"))


def test_one_trial_job_checks_its_own_row_not_the_others(tmp_path):
    """A per-trial job (steps.trial_and_subject) validates its trial's row, its subject's
    row and the headers: a bad cell in another trial's row is the whole-sheet check's
    problem, a bad cell in its own row stops it with the row and column named."""
    from gaitval.pipeline.steps.trials import trial_and_subject

    other = ROW.replace("tug_S01_1", "tug_S01_2").replace(",0.27,", ",tall,")
    sheet = make_study(tmp_path, rows=ROW + other)
    with pytest.raises(TrialSheetError, match="row 3"):
        load_trial_sheet(sheet)
    row, subj = trial_and_subject(sheet, tmp_path / "subjects.csv", "tug_S01_1")
    assert row["sensor_height_m"] == pytest.approx(0.27)
    assert subj["leg_width_m"] == pytest.approx(0.10)
    with pytest.raises(TrialSheetError, match=r"row 3 \(trial 'tug_S01_2'\), column "
                                              r"'sensor_height_m'"):
        trial_and_subject(sheet, tmp_path / "subjects.csv", "tug_S01_2")
    with pytest.raises(TrialSheetError, match="unknown column 'protocl'"):
        trial_and_subject(make_study(tmp_path, header=HEADER.replace("protocol", "protocl")),
                          tmp_path / "subjects.csv", "tug_S01_1")


def test_a_process_running_many_jobs_sees_every_edit_of_the_sheet(tmp_path):
    """A warm worker remembers validated rows by the files' contents: an edit that breaks
    the row (sheet or subject table) is caught by the next job, a fixed file passes again,
    and a job changing the dict it got does not change what the next job gets."""
    from gaitval.pipeline.steps.trials import trial_and_subject

    sheet = make_study(tmp_path)
    subjects = tmp_path / "subjects.csv"
    row, subj = trial_and_subject(sheet, subjects, "tug_S01_1")
    row["sensor_height_m"] = -1.0
    subj["leg_width_m"] = -1.0
    row2, subj2 = trial_and_subject(sheet, subjects, "tug_S01_1")
    assert row2["sensor_height_m"] == pytest.approx(0.27)
    assert subj2["leg_width_m"] == pytest.approx(0.10)
    good_sheet, good_subjects = sheet.read_text(), subjects.read_text()
    sheet.write_text(good_sheet.replace(",0.27,", ",tall,"))
    with pytest.raises(TrialSheetError, match="column 'sensor_height_m'"):
        trial_and_subject(sheet, subjects, "tug_S01_1")
    sheet.write_text(good_sheet)
    subjects.write_text(good_subjects.replace("0.10,0.10", "wide,0.10"))
    with pytest.raises(TrialSheetError, match="column 'leg_width_m'"):
        trial_and_subject(sheet, subjects, "tug_S01_1")
    subjects.write_text(good_subjects)
    assert trial_and_subject(sheet, subjects, "tug_S01_1")[0]["subject"] == "S01"


def test_one_trial_row_names_a_missing_trial(tmp_path):
    from gaitval.io.trialsheet import load_trial_row

    sheet = make_study(tmp_path)
    assert load_trial_row(sheet, None, "tug_S01_1")["subject"] == "S01"
    with pytest.raises(TrialSheetError, match="'tug_S01_9' is not in the trial sheet"):
        load_trial_row(sheet, None, "tug_S01_9")


def test_one_trial_row_from_a_remembered_sheet_keeps_per_row_errors(tmp_path):
    """load_trial_row validates the whole sheet once and then picks rows from it; a
    problem on another row, or a file deleted after that validation, still gives the
    same per-row answers as checking the row alone."""
    from gaitval.io.trialsheet import load_trial_row

    row2 = ROW.replace("tug_S01_1", "tug_S01_2").replace("m/a.c3d", "m/b.c3d")
    sheet = make_study(tmp_path, rows=ROW + row2)
    def same(a, b):                                     # NaN where empty: compare reprs
        return {k: repr(v) for k, v in a.items()} == {k: repr(v) for k, v in b.items()}

    first = load_trial_row(sheet, None, "tug_S01_1")
    assert load_trial_row(sheet, None, "tug_S01_2")["mocap_path"].endswith("b.c3d")
    (tmp_path / "m/b.c3d").unlink()                     # same sheet: remembered as clean
    assert same(load_trial_row(sheet, None, "tug_S01_1"), first)
    assert load_trial_row(sheet, None, "tug_S01_2", check_files=False)["subject"] == "S01"
    with pytest.raises(TrialSheetError, match=r"row 3 \(trial 'tug_S01_2'\).*not found"):
        load_trial_row(sheet, None, "tug_S01_2")
    sheet.write_text(HEADER + ROW + row2.replace(",0.27,", ",tall,"))   # row 3 now bad
    assert same(load_trial_row(sheet, None, "tug_S01_1"), first)
    with pytest.raises(TrialSheetError, match="row 3.*'sensor_height_m'"):
        load_trial_row(sheet, None, "tug_S01_2", check_files=False)


# -- issue 33: ids that name folders, rows that lost cells, values no sheet should hold ----
@pytest.mark.parametrize("trial, expect", [
    ("..", "parent folder"),
    (".", "own or parent folder"),
    ("t" * 5000, "5000 characters long (at most 128)"),
    ("a b", "' '"),
    ("x$(id)", "'$'"),
    ("a/b", "'/'"),
])
def test_trial_ids_that_cannot_name_a_folder_are_refused(tmp_path, trial, expect):
    with pytest.raises(TrialSheetError) as ei:
        load_trial_sheet(make_study(tmp_path, rows=ROW.replace("tug_S01_1", trial)))
    msg = str(ei.value)
    assert "row 2" in msg and "column 'trial'" in msg and expect in msg, msg
    assert len(msg) < 600, "a 5,000-character id is not echoed whole"


def test_a_128_character_id_is_fine(tmp_path):
    trial = "t" * 128
    assert list(load_trial_sheet(make_study(tmp_path, rows=ROW.replace("tug_S01_1", trial)))
                .index) == [trial]


def test_rows_missing_trailing_cells_are_refused_with_their_rows(tmp_path):
    short = ROW.rsplit(",", 3)[0] + "\n"                      # the last three cells lost
    with pytest.raises(TrialSheetError) as ei:
        load_trial_sheet(make_study(tmp_path, rows=ROW.replace("tug_S01_1", "b") + short))
    msg = str(ei.value)
    assert "row 3: 13 cells" in msg and "header's 16" in msg, msg


def test_a_header_only_sheet_is_refused(tmp_path):
    with pytest.raises(TrialSheetError, match="header but no trials"):
        load_trial_sheet(make_study(tmp_path, rows=""))


def test_an_implausible_count_is_refused(tmp_path):
    with pytest.raises(TrialSheetError, match=r"column 'repetition': '1e308' is not a plausible"):
        load_trial_sheet(make_study(tmp_path, rows=ROW.replace(",1\n", ",1e308\n")))


def test_a_nul_byte_in_a_cell_is_refused(tmp_path):
    rows = ROW.replace("l/a.scan.parquet,,", "l/b.bag,/scan\0x,")
    with pytest.raises(TrialSheetError) as ei:
        load_trial_sheet(make_study(tmp_path, rows=rows))
    assert "column 'sensor_topic': holds control character(s) '\\x00'" in str(ei.value)


# -- issue 33: `validate --deep` opens what it checks --------------------------------------
def _deep(tmp_path, rows, *extra):
    import subprocess
    import sys
    sheet = make_study(tmp_path, rows=rows)
    return subprocess.run([sys.executable, "-m", "gaitval", "validate", str(sheet),
                           "--allow-outside-paths", "--deep", *extra],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.realdata
@pytest.mark.slow
def test_deep_validate_opens_real_files_and_names_each_that_does_not_load(tmp_path,
                                                                          realdata):
    c3d = realdata / "c3d" / "FunctionalWalk.c3d"
    bag = realdata / "lrs" / "positive_1.bag"
    good = (f"s,tug,S01,good,lrs,{c3d},{bag},right_scan,,0.27,,,,false,,1\n")
    empty = "s,tug,S01,empty,lrs,m/a.c3d,l/b.bag,right_scan,,0.27,,,,false,,1\n"
    topic = f"s,tug,S01,topic,lrs,{c3d},{bag},no_such_topic,,0.27,,,,false,,1\n"
    res = _deep(tmp_path, good, "--jobs", "1")
    assert res.returncode == 0, res.stderr
    assert "1 trials OK" in res.stdout and "every file opened" in res.stdout
    res = _deep(tmp_path, good + empty + topic)
    assert res.returncode == 1
    err = res.stderr
    assert "3 problems" in err, err                           # each file said once
    assert "row 3 (trial 'empty'), column 'mocap_file'" in err
    assert "row 3 (trial 'empty'), column 'sensor_file'" in err
    assert "row 4 (trial 'topic'), column 'sensor_file'" in err and "no_such_topic" in err
    assert "row 2" not in err and "Traceback" not in err
