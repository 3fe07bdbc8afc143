"""Files that load quietly but say something impossible, ids that break a later step,
values that reached a script unquoted: each now gives one clear message.

Built on the real files of ``../shared/realdata/`` (a walking subject's C3D, a ROS bag)
where a real file is the point, and on the fuzz harness's small generated logs
(``tests/fuzz/fuzz_seeds.py``) otherwise.
"""
from __future__ import annotations

import logging
import resource
import shutil
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from gaitval.errors import ConfigError, FileFormatError, TrialSheetError

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "fuzz"))
import fuzz_mutators as M  # noqa: E402
import fuzz_seeds  # noqa: E402

WALK = "c3d/opensim_walking2.c3d"


def _c3d_with_units(realdata: Path, tmp_path: Path, unit: str) -> Path:
    ezc3d = pytest.importorskip("ezc3d")
    c = ezc3d.c3d(str(realdata / WALK))
    c["parameters"]["POINT"]["UNITS"]["value"] = [unit]
    out = tmp_path / f"walk_{unit or 'blank'}.c3d"
    c.write(str(out))
    return out


@pytest.mark.parametrize("unit, fits", [("m", "mm"), ("cm", "mm")])
def test_markers_against_the_declared_unit(realdata, tmp_path, unit, fits):
    from gaitval.io.c3d import read_c3d

    path = _c3d_with_units(realdata, tmp_path, unit)
    with pytest.raises(FileFormatError) as exc:
        read_c3d(path)
    msg = str(exc.value)
    assert str(path) in msg and f"POINT:UNITS {unit!r}" in msg
    assert "the declared unit is wrong" in msg and f"set POINT:UNITS to {fits!r}" in msg


def test_blank_units_are_reported_as_assumed(realdata, tmp_path):
    from gaitval.io.c3d import describe_c3d, read_c3d
    from gaitval.io.inspect import format_description

    path = _c3d_with_units(realdata, tmp_path, "")
    tr = read_c3d(path)
    assert tr.meta["units_assumed"] and any("POINT:UNITS is blank" in w
                                            for w in tr.meta["warnings"])
    text = format_description(describe_c3d(path))
    assert "mm assumed" in text and "mm in the file" not in text
    ok = read_c3d(realdata / WALK)              # the real file: no such warning
    assert not ok.meta["units_assumed"] and not ok.meta["warnings"]


def test_a_gigabyte_of_zeros_named_bag_fails_fast_and_small(tmp_path, realdata):
    """The bag library read the whole file (2.25 GB, 16 s) before gaitval's header check:
    now the check comes first.  A sparse 1 GB file; the read under a 600 MB address-space
    limit beyond the interpreter's own."""
    bag = tmp_path / "zeros.bag"
    with open(bag, "wb") as fh:
        fh.truncate(1 << 30)
    code = (
        "import resource, sys, time\n"
        "from gaitval.io.rosbag import read_rosbag_scans\n"
        "from gaitval.errors import FileFormatError\n"
        "soft, hard = resource.getrlimit(resource.RLIMIT_AS)\n"
        "import psutil\n"
        "limit = psutil.Process().memory_info().vms + 600 * 2**20\n"
        "resource.setrlimit(resource.RLIMIT_AS, (limit, hard))\n"
        "t0 = time.monotonic()\n"
        f"try:\n    read_rosbag_scans({str(bag)!r}, None)\n"
        "except FileFormatError as e:\n    print('ERR', round(time.monotonic() - t0, 2), e)\n")
    pytest.importorskip("psutil")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert res.stdout.startswith("ERR"), res.stdout + res.stderr[-2000:]
    seconds = float(res.stdout.split()[1])
    assert seconds < 5.0 and str(bag) in res.stdout
    assert "does not start with '#ROSBAG V2.0'" in res.stdout


def test_a_real_bag_still_reads(realdata):
    from gaitval.io.rosbag import read_rosbag_scans

    scans = read_rosbag_scans(realdata / "lrs" / "positive_1.bag", None)
    assert scans.n_scans > 100


def _scanlog(tmp_path: Path, ranges=None, meta_update=None, t=None) -> Path:
    import pyarrow as pa

    cols, key, meta = fuzz_seeds.parquet_parts("scanlog")
    nb = int(meta["n_beams"])
    if ranges is not None:
        cols["ranges"] = pa.FixedSizeListArray.from_arrays(
            pa.array(np.asarray(ranges, dtype=np.float32).ravel()), nb)
    if t is not None:
        cols["t_s"] = t
    meta.update(meta_update or {})
    out = tmp_path / "m.scan.parquet"
    M._write_parquet(out, cols, key, meta)
    return out


def test_scans_x_beams_bounded_before_the_log_is_read(tmp_path):
    """A small file announcing more ranges than the bound is refused from its footer
    (the audit's 6 MB log of 2 M scans needed > 8 GB), under a tight memory limit."""
    from gaitval.io.scanlog import MAX_RANGE_VALUES

    n = 20
    path = _scanlog(tmp_path, meta_update={"n_beams": 100_000,
                                           "angle_increment_rad": 1e-5})
    assert n * 100_000 < MAX_RANGE_VALUES        # 20 scans: fine by the bound
    # the same footer check with many rows: a table of 1300 rows x 100,000 beams declared
    import pyarrow as pa
    import pyarrow.parquet as pq
    cols, key, meta = fuzz_seeds.parquet_parts("scanlog")
    meta.update(n_beams=100_000, angle_increment_rad=1e-5)
    rows = 1300
    table = pa.table({"t_s": 1000.0 + 0.025 * np.arange(rows),
                      "ranges": pa.FixedSizeListArray.from_arrays(
                          pa.array(np.zeros(rows, dtype=np.float32)), 1)})
    import json
    big = tmp_path / "big.scan.parquet"
    pq.write_table(table.replace_schema_metadata({key: json.dumps(meta)}), big)
    assert big.stat().st_size < 100_000
    from gaitval.io.scanlog import read_scanlog
    with pytest.raises(FileFormatError, match=r"1,300 scans x 100,000 beams") as exc:
        read_scanlog(big)
    assert str(big) in str(exc.value)
    with pytest.raises(FileFormatError):          # the 20-scan one: its column is wrong
        read_scanlog(path)


def test_all_negative_or_out_of_limit_ranges_are_refused(tmp_path):
    from gaitval.io.scanlog import read_scanlog

    cols, _, meta = fuzz_seeds.parquet_parts("scanlog")
    good = np.asarray(cols["ranges"].flatten(), dtype=np.float32).reshape(20, -1)
    assert read_scanlog(_scanlog(tmp_path, good)).n_scans == 20
    with pytest.raises(FileFormatError, match="every one of the 620 ranges is negative"):
        read_scanlog(_scanlog(tmp_path, -good))
    with pytest.raises(FileFormatError, match="none of the 620 ranges lies within"):
        read_scanlog(_scanlog(tmp_path, good * 1000.0))


def test_whole_second_stamps_give_no_infinite_rate(tmp_path):
    """An ultrasonic log stamped in whole seconds: rate_hz was inf, with numpy's raw
    RuntimeWarning; now one error naming the file."""
    from gaitval.io.ultrasonic import read_ultrasonic

    cols, key, meta = fuzz_seeds.parquet_parts("ultrasonic")
    n = 200                                   # 5 s at 40 Hz, stamped in whole seconds
    cols = {c: np.resize(np.asarray(v, dtype=float), n) for c, v in cols.items()}
    cols["t_s"] = np.floor(1000.0 + 0.025 * np.arange(n))
    out = tmp_path / "m.us.parquet"
    M._write_parquet(out, cols, key, meta)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(FileFormatError, match="no sampling rate follows") as exc:
            read_ultrasonic(out)
    assert str(out) in str(exc.value) and "advances in only 4 of its 199 steps" in \
        str(exc.value)


def test_bag_library_asserts_are_named():
    from gaitval.io.rosbag import _exc_text

    assert "consistency check failed (AssertionError)" in _exc_text(AssertionError())
    assert _exc_text(KeyError("x")) == "KeyError: 'x'"


def test_write_c3d_refuses_zero_frames(tmp_path):
    from gaitval.io.c3d import write_c3d

    with pytest.raises(ValueError, match="at least one frame and one marker"):
        write_c3d(tmp_path / "x.c3d", ["A"], np.zeros((0, 1, 3)), 100.0)


# -- ids ----------------------------------------------------------------------------------
def test_id_rules():
    from gaitval.configcheck import id_problem, path_value_problem

    assert "starts with '-'" in id_problem("-rf")
    assert id_problem("a{b}") and id_problem("$(id)") and id_problem("..")
    assert id_problem("tug_Y01-t1.v2") is None
    assert "brace" in path_value_problem("m/{trial}.c3d")
    assert path_value_problem("/home/me/my data/x.c3d") is None      # spaces are fine
    assert path_value_problem("../reports", strict=True) is None
    assert "'rep$(touch x)'" in path_value_problem("rep$(touch x)", strict=True)


def _sheet(tmp_path: Path, rows: list[str]) -> Path:
    sheet, subjects = fuzz_seeds.sheet_texts()
    head = sheet.splitlines()[0]
    for rel in ("m/a.c3d", "m/b.c3d", "m/{x}.c3d", "l/a.scan.parquet", "l/b.scan.parquet",
                "l/a.bag", "a.annotations.csv"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(b"")
    (tmp_path / "trials.csv").write_text("\n".join([head, *rows]) + "\n")
    (tmp_path / "subjects.csv").write_text(subjects)
    return tmp_path / "trials.csv"


def test_sheet_ids_and_paths(tmp_path):
    from gaitval.io.trialsheet import load_trial_sheet

    row = "s,tug,S01,{trial},lrs,{mocap},{sensor},,,0.27,,fast,1.1,false,,1"
    ok = row.format(trial="t1", mocap="m/a.c3d", sensor="l/a.scan.parquet")
    with pytest.raises(TrialSheetError, match="starts with '-'"):
        load_trial_sheet(_sheet(tmp_path, [row.format(trial="-rf", mocap="m/a.c3d",
                                                      sensor="l/a.scan.parquet")]))
    with pytest.raises(TrialSheetError, match="brace"):
        load_trial_sheet(_sheet(tmp_path, [row.format(trial="t1", mocap="m/{x}.c3d",
                                                      sensor="l/a.scan.parquet")]))
    with pytest.raises(TrialSheetError, match="differ only in case"):
        load_trial_sheet(_sheet(tmp_path, [ok, row.format(trial="T1", mocap="m/b.c3d",
                                                          sensor="l/b.scan.parquet")]))
    assert list(load_trial_sheet(_sheet(tmp_path, [ok])).index) == ["t1"]


def test_rows_reusing_one_recording_are_warned_about(tmp_path, caplog):
    from gaitval.io.trialsheet import load_trial_sheet

    row = "s,tug,S01,{trial},lrs,m/a.c3d,l/{s}.scan.parquet,,,0.27,,fast,1.1,false,,1"
    with caplog.at_level(logging.WARNING, logger="gaitval"):
        load_trial_sheet(_sheet(tmp_path, [row.format(trial="t1", s="a"),
                                           row.format(trial="t2", s="b")]))
    assert "mocap_file 'm/a.c3d' is named by 2 rows (2, 3)" in caplog.text


def test_init_study_makes_no_option_like_or_case_twin_ids(tmp_path, realdata):
    from gaitval.io.initstudy_files import as_id, unique_id

    assert as_id("-rf", "trial") == "rf" and as_id("--", "trial") == "trial"
    taken: set[str] = set()
    assert unique_id(["Walk"], taken) == "Walk"
    assert unique_id(["walk", "walk"], taken) == "walk_2"
    # a folder with a file named -rf.c3d and its sensor log: the trial id is no option
    from gaitval.io.initstudy import init_study
    folder = tmp_path / "study"
    folder.mkdir()
    shutil.copy(realdata / WALK, folder / "-rf.c3d")
    (folder / "-rf.scan.parquet").write_bytes(_scanlog(tmp_path).read_bytes())
    init_study(folder, validate=False)
    text = (folder / "trials.csv").read_text()
    assert ",rf," in text and ",-rf," not in text


# -- config values --------------------------------------------------------------------------
def test_config_values_naming_folders_are_checked(tmp_path):
    from gaitval.configcheck import raise_problems, run_problems

    cfg = {"run": ["$(touch x)"], "studies": {"$(touch x)": {}, "../../up": {},
                                               "Tiny": {}, "tiny": {}},
           "reports_dir": "rep$(touch PWNED)", "data_dir": "d{x}"}
    probs = [p.message for p in run_problems(cfg)]
    text = "\n".join(probs)
    assert "run[0]: the study name '$(touch x)' has the character(s)" in text
    assert "studies: the study name '../../up'" in text
    assert "'tiny' and 'Tiny' differ only in case" in text or \
        "'Tiny' and 'tiny' differ only in case" in text
    assert "reports_dir: 'rep$(touch PWNED)' has the folder name" in text
    assert "data_dir: 'd{x}' holds a brace" in text
    with pytest.raises(ConfigError):
        raise_problems(run_problems(cfg))
    assert run_problems({"run": ["tiny"], "studies": {"tiny": {}},
                         "reports_dir": "/scratch/me/reports"}) == []


def test_a_study_file_key_of_the_config_says_where_it_belongs():
    from gaitval.configcheck import check_study_file

    with pytest.raises(ConfigError) as exc:
        check_study_file({"reports_dir": "x"}, "data/s/study.yaml")
    assert "did you mean" not in str(exc.value)
    assert "reports_dir is a key of the workflow config" in str(exc.value)


# -- generated scripts ----------------------------------------------------------------------
def test_reproduce_script_quotes_every_value_and_holds_no_absolute_path(tmp_path):
    from gaitval.report.provenance import REPO, rebuild_command, reproduce_script

    hostile = "rep$(touch PWNED1)`touch PWNED2`;touch PWNED3 \"x\" 'y'/tiny"
    command = rebuild_command([], {"reports_dir": hostile.rsplit("/", 1)[0],
                                   "peer_results": str(REPO / "pyproject.toml")},
                              REPO)
    assert str(REPO) not in command and "peer_results=pyproject.toml" in command
    script = reproduce_script({"git_commit": "abc123", "repository": str(REPO),
                               "command": command}, hostile, "../../..")
    assert str(REPO) not in script
    assert 'git rev-parse --show-toplevel' in script
    # the last line alone, run by bash: prints the value, runs nothing
    last = script.rstrip("\n").splitlines()[-1]
    res = subprocess.run(["bash", "-c", "DEST=out; " + last], cwd=tmp_path,
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip().endswith(f"(out/{hostile})")
    assert not list(tmp_path.glob("PWNED*"))
    (tmp_path / "r.sh").write_text(script)
    assert subprocess.run(["bash", "-n", str(tmp_path / "r.sh")]).returncode == 0
    with_url = reproduce_script({"git_commit": "abc", "repository":
                                 "https://example.org/gaitval.git"}, "reports/tiny")
    assert "REPO=${1:-https://example.org/gaitval.git}" in with_url


def test_step_records_and_the_config_record_hold_no_absolute_path(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from gaitval.report.provenance import REPO, command_line, write_workflow_record

    monkeypatch.chdir(tmp_path)
    peer = str(REPO / "pyproject.toml")
    cmd = command_line(["gaitval", "peer", peer, "--out-stem", "reports/t/x"])
    import shlex
    assert not any(w.startswith("/") for w in shlex.split(cmd)), cmd
    assert cmd.endswith("pyproject.toml --out-stem reports/t/x")
    prov = tmp_path / "reports" / "t" / "provenance"
    out = SimpleNamespace(config=prov / "config.yaml", inputs=prov / "inputs.txt",
                          rebuild=prov / "rebuild.json")
    write_workflow_record({"run": ["t"], "peer_results": peer, "note": "/not/a/file"}, [],
                          out, str(tmp_path / "log"), command="python3 run.py report",
                          chash="abc")
    text = out.config.read_text()
    assert f"peer_results: {peer}" not in text and "pyproject.toml" in text
    assert "/not/a/file" in text                   # not a path of this machine: kept
