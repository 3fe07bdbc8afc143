"""Issue 37 scope 3 and 4: ``gaitval init-study FOLDER`` and a study without poles.

Fast tests build small folders (copies of tiny-study files under other names) and check
what init-study pairs, fills and marks.  The slow tests read the session's tiny study run
(tests/conftest.py; its peer-data table aside, which no study's files change), then:

* copy ``data/tiny`` without its trial sheet and subject table, run ``gaitval init-study``,
  fill in exactly the cells it marked ``FILL_IN`` from the original tables (what a lab does
  with its own notes), run the workflow with the config snippet init-study wrote, and
  compare every table with the original's (identical, the study's name aside);
* the same (TUG and MTST files only, for time) with the POLE markers removed from every
  C3D: init-study asks for the sensor pose by hand (``sensor_x_m``, ``sensor_y_m``,
  ``sensor_yaw_deg``), filled from the simulator's true pose to a millimetre and a
  hundredth of a degree (a tape measure would do worse); the workflow runs from the raw
  files to the TUG and MTST tables, registration says ``manual`` for every trial, and the
  tables are the original's (TUG Tables 4-5's errors aside, which move with the pose).
"""
from __future__ import annotations

import csv
import io
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from gaitval.errors import GaitvalError
from gaitval.io.initstudy import init_study
from gaitval.io.initstudy_files import FILL_IN

from conftest import PROFILE, SNAKEMAKE

ROOT = Path(__file__).resolve().parents[1]
GAITVAL = Path(sys.executable).parent / "gaitval"


def snakemake(work: Path, *args) -> subprocess.CompletedProcess:
    """Snakemake in ``work`` with the config files ``args`` (then, after ``"--"``, the
    targets)."""
    args = list(map(str, args))
    files, targets = (args[:args.index("--")], args[args.index("--") + 1:]) if "--" in args \
        else (args, [])
    cmd = [str(SNAKEMAKE), *targets, "--snakefile", str(ROOT / "Snakefile"), "--profile",
           str(PROFILE), "--directory", str(work), "--cores", "2", "--configfile", *files]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=1200)


@pytest.fixture(scope="module")
def tiny(tiny_run) -> Path:
    """The tiny study, simulated and reported once per session in a scratch folder (read
    only here: the tests copy its data)."""
    return tiny_run


def fill_in(new: Path, orig: Path, pose: dict | None = None) -> list[tuple[str, str, str]]:
    """Replace every FILL_IN cell of new/trials.csv and new/subjects.csv by the original
    table's value (the pose columns from ``pose``); returns the cells filled."""
    filled = []
    for name, key in (("trials.csv", "trial"), ("subjects.csv", "subject")):
        with open(orig / name, newline="") as fh:
            o = {r[key]: r for r in csv.DictReader(fh)}
        with open(new / name, newline="") as fh:
            rows = list(csv.DictReader(fh))
        for r in rows:
            for c, v in r.items():
                if v != FILL_IN:
                    continue
                if c in ("sensor_x_m", "sensor_y_m", "sensor_yaw_deg"):
                    x, y, yaw = pose[r[key]]
                    r[c] = {"sensor_x_m": f"{x:.3f}", "sensor_y_m": f"{y:.3f}",
                            "sensor_yaw_deg": f"{math.degrees(yaw):.2f}"}[c]
                else:
                    r[c] = o[r[key]][c]
                filled.append((name, r[key], c))
        with open(new / name, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]), lineterminator="\n")
            w.writeheader()
            w.writerows(rows)
    return filled


def tables(work: Path, run: str) -> dict[str, str]:
    """The run's study tables (not the peer's, which no study's files change) by name."""
    d = work / "reports" / run / "tables"
    return {p.name.replace(f"_{run}.", "."): p.read_text().replace(run, "<study>")
            for p in sorted(d.glob("*.csv")) if p.name != "peer_agreement.csv"}


def copy_without_sheet(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("truth"))
    for name in ("trials.csv", "subjects.csv"):
        (dst / name).unlink()
    return dst


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(GAITVAL), *args], capture_output=True, text=True, timeout=300)


# -- the whole tiny study -----------------------------------------------------------------
@pytest.mark.slow
def test_init_study_on_the_tiny_folder_gives_the_same_tables(tiny, tmp_path):
    orig = tiny / "data" / "tiny"
    study = copy_without_sheet(orig, tmp_path / "lab" / "mystudy")
    res = run_cli("init-study", str(study))
    assert res.returncode == 1, res.stdout           # cells to fill: validate refuses
    assert "gaitval validate: " in res.stdout and FILL_IN in res.stdout
    filled = fill_in(study, orig)
    # what the files cannot say, and only that: the shank width at the sensor's height,
    # the MTST participant's height and stick; every other cell came from the files
    assert sorted({(n, c) for n, _, c in filled}) == [
        ("subjects.csv", "height_m"), ("subjects.csv", "leg_width_m"),
        ("subjects.csv", "stick"), ("trials.csv", "stick")]
    assert {s for n, s, c in filled if c == "leg_width_m"} == {"E01", "P01", "Y01"}
    assert run_cli("validate", str(study / "trials.csv")).returncode == 0
    snippet = study / "gaitval.config.yaml"
    assert yaml.safe_load(snippet.read_text())["run"] == ["mystudy"]
    base = tmp_path / "base.yaml"
    base.write_text(yaml.safe_dump({"peer_results": ""}))
    res = snakemake(tmp_path, base, snippet)
    assert res.returncode == 0, res.stderr[-4000:]
    want, got = tables(tiny, "tiny"), tables(tmp_path, "mystudy")
    assert len(want) >= 20 and set(got) == set(want)
    for name in want:
        assert got[name] == want[name], name


@pytest.mark.slow
def test_a_tiny_study_without_poles_runs_end_to_end_on_a_measured_pose(tiny, tmp_path):
    from gaitval.io.c3d_read import read_c3d
    from gaitval.io.c3d_write import write_c3d

    orig = tiny / "data" / "tiny"
    study = copy_without_sheet(orig, tmp_path / "nopoles")
    # the protocols whose laser stands still and is registered with poles (TUG, MTST);
    # the rollator's laser moves (its markers give its pose) and the ultrasonic protocol
    # has none: their files are left out to keep this test short
    shutil.rmtree(study / "ultrasonic")
    for p in sorted(study.rglob("rollator_*")):
        p.unlink()
    dropped = []
    for p in sorted(study.rglob("*.c3d")):
        m = read_c3d(p)
        keep = [i for i, lb in enumerate(m.labels) if not lb.startswith("POLE")]
        if len(keep) < len(m.labels):
            write_c3d(p, [m.labels[i] for i in keep], m.xyz[:, keep, :], m.rate_hz,
                      events=m.events if len(m.events) else None, first_frame=m.first_frame)
            dropped.append(p.stem)
    assert len(dropped) == 3                         # the TUG and MTST captures
    result = init_study(study)
    truth = pd.read_csv(orig / "truth" / "sensor_pose.csv").set_index("trial")
    pose = {t: (r["x_m"], r["y_m"], r["yaw_rad"]) for t, r in truth.iterrows()}
    filled = fill_in(study, orig, pose)
    asked = sorted({t for n, t, c in filled if c == "sensor_x_m"})
    assert asked == ["mtst_E01_t1", "tug_Y01_t1", "tug_Y01_t2"]
    assert any("POLE1/POLE2" in t for t in result.todo)
    base = tmp_path / "base.yaml"
    base.write_text(yaml.safe_dump({"peer_results": ""}))
    names = ["tug_table3", "tug_table4", "tug_table5", "mtst_table1", "mtst_table3",
             "mtst_table4", "study_registration_nopoles"]
    res = snakemake(tmp_path, base, study / "gaitval.config.yaml", "--",
                    *(f"reports/nopoles/tables/{n}.csv" for n in names))
    assert res.returncode == 0, res.stderr[-4000:]
    reg = pd.read_csv(tmp_path / "results" / "nopoles" / "registration.csv").set_index("trial")
    assert sorted(reg.index) == asked
    assert (reg["pose_source"] == "manual").all() and reg["pole_residual_m"].isna().all()
    want, got = tables(tiny, "tiny"), tables(tmp_path, "nopoles")
    # TUG Tables 4-5 (RMSE against a ground truth projected with the pose) may move by
    # the pose's millimetres; the counts of Table 3 and the MTST tables are identical
    for name in ("tug_table3.csv", "mtst_table1.csv", "mtst_table3.csv", "mtst_table4.csv"):
        assert got[name] == want[name], name
    # Tables 4-5 count leg-steps inside the ground truth's span, and the clock offset is
    # estimated from the legs projected with the pose (here 73 us apart on tug_Y01_t2):
    # a scan at either end of a trial's span may come or go: at most one per leg and end
    # of each TUG trial (Table 5 sums the phases: the same bound)
    n_tug = len(asked) - 1
    for name in ("tug_table4.csv", "tug_table5.csv"):
        a = pd.read_csv(io.StringIO(got[name]))
        b = pd.read_csv(io.StringIO(want[name]))
        assert a.shape == b.shape and len(a) > 0
        counts = [c for c in a.columns if (c.startswith("n_") or c == "time_steps")
                  and c != "n_success_trials" and not c.endswith("_published")]
        assert counts, name
        assert (a[counts] - b[counts]).abs().to_numpy().max() <= 2 * 2 * n_tug, name
        pub = [c for c in a.columns if c.endswith("_published")]
        pd.testing.assert_frame_equal(a[pub], b[pub])
        if "n_success_trials" in a:
            assert a["n_success_trials"].equals(b["n_success_trials"]), name


# -- small folders --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def tiny_files(tiny_simulated) -> Path:
    """The tiny preset's files (its TUG and MTST trials are used here), simulated without
    running the workflow, once per session (tests/conftest.py); the tests copy them."""
    return tiny_simulated


def test_files_of_other_names_are_paired_by_time_and_reported(tiny_files, tmp_path):
    lab = tmp_path / "lab"
    (lab / "vicon").mkdir(parents=True)
    (lab / "laser").mkdir()
    shutil.copy(tiny_files / "mocap" / "tug_Y01_t1.c3d", lab / "vicon" / "Walk 01.c3d")
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t1.scan.parquet",
                lab / "laser" / "tug_Y01_t1.scan.parquet")
    shutil.copy(tiny_files / "mocap" / "tug_Y01_t2.c3d", lab / "vicon" / "Walk 02.c3d")
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t2.scan.parquet",
                lab / "laser" / "tug_Y01_t2.scan.parquet")
    t0 = 1_700_000_000
    os.utime(lab / "vicon" / "Walk 01.c3d", (t0, t0))
    os.utime(lab / "laser" / "tug_Y01_t1.scan.parquet", (t0 + 4, t0 + 4))
    os.utime(lab / "vicon" / "Walk 02.c3d", (t0 + 600, t0 + 600))
    os.utime(lab / "laser" / "tug_Y01_t2.scan.parquet", (t0 + 590, t0 + 590))
    res = init_study(lab, study="lab")
    sheet = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False)
    assert dict(zip(sheet["trial"], sheet["mocap_file"])) == {
        "tug_Y01_t1": "vicon/Walk 01.c3d", "tug_Y01_t2": "vicon/Walk 02.c3d"}
    assert list(sheet["protocol"]) == ["tug", "tug"]
    assert list(sheet["subject"]) == ["Y01", "Y01"]
    assert list(sheet["repetition"]) == ["1", "2"]
    assert list(sheet["sensor_height_m"]) == ["0.27", "0.27"]   # the scan log's metadata
    assert sum("by time" in n for n in res.notes) == 2
    # only the leg width is missing: validate names its row and column
    assert [p for p in res.problems if "leg_width_m" in p] == res.problems != []
    # a sheet is not replaced without --force
    with pytest.raises(GaitvalError, match="exists"):
        init_study(lab)
    # too far apart in time: not paired, and said
    os.utime(lab / "vicon" / "Walk 02.c3d", (t0 + 5000, t0 + 5000))
    res = init_study(lab, force=True, max_time_gap_s=60)
    sheet = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False)
    assert sheet.set_index("trial").loc["tug_Y01_t2", "mocap_file"] == ""
    assert any("Walk 02.c3d" in u for u in res.unpaired)
    assert any("tug_Y01_t2" in u and "no C3D" in u for u in res.unpaired)


def test_subject_from_the_c3d_and_the_mtst_study_yaml(tiny_files, tmp_path):
    from gaitval.io.c3d_read import read_c3d
    from gaitval.io.c3d_write import write_c3d

    lab = tmp_path / "lab"
    lab.mkdir()
    m = read_c3d(tiny_files / "mocap" / "mtst_E01_t1.c3d")
    # Nexus writes the subject's name into SUBJECTS:NAMES and prefixes the labels
    write_c3d(lab / "mtst_stick_3.c3d", m.labels, m.xyz, m.rate_hz, subject_prefix="Anna")
    shutil.copy(tiny_files / "lrs" / "mtst_E01_t1.scan.parquet", lab / "mtst_stick_3.scan.parquet")
    shutil.copy(tiny_files / "annotations" / "mtst_E01_t1.annotations.csv",
                lab / "mtst_stick_3.annotations.csv")
    (lab / "layouts").mkdir()
    shutil.copy(tiny_files / "targets" / "mtst_E01_t1.targets.csv",
                lab / "layouts" / "mtst_stick_3.targets.csv")
    res = init_study(lab)
    row = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False).iloc[0]
    assert (row["protocol"], row["subject"], row["stick"], row["repetition"]) == (
        "mtst", "Anna", "True", "3")
    assert row["annotation_file"] == "mtst_stick_3.annotations.csv"
    cal = yaml.safe_load((lab / "study.yaml").read_text())
    assert cal["mtst"]["targets"] == "layouts/{trial}.targets.csv"
    subj = pd.read_csv(lab / "subjects.csv", dtype=str, keep_default_na=False).iloc[0]
    assert (subj["height_m"], subj["leg_width_m"], subj["stick"]) == (FILL_IN,) * 3
    assert any("height_m" in t for t in res.todo)
    assert any("subject ids from the C3D's SUBJECTS:NAMES: 1 trial" in n for n in res.notes)


def test_the_file_name_names_the_subject_before_the_c3d(tiny_files, tmp_path):
    """As the README says, ids come from the file names; Vicon's SUBJECTS:NAMES (often a
    session's, "Treadmill") only where the name has no subject word; the summary says
    which."""
    from gaitval.io.c3d_read import read_c3d
    from gaitval.io.c3d_write import write_c3d

    lab = tmp_path / "lab"
    lab.mkdir()
    m = read_c3d(tiny_files / "mocap" / "mtst_E01_t1.c3d")
    write_c3d(lab / "mtst_E07_stick_3.c3d", m.labels, m.xyz, m.rate_hz,
              subject_prefix="Treadmill")
    shutil.copy(tiny_files / "lrs" / "mtst_E01_t1.scan.parquet",
                lab / "mtst_E07_stick_3.scan.parquet")
    res = init_study(lab)
    row = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False).iloc[0]
    assert row["subject"] == "E07"
    assert any("subject ids from the file name: 1 trial (mtst_E07_stick_3)" in n
               for n in res.notes), res.notes
    assert "subject ids from the file name" in res.text()


def test_plug_in_gait_anthropometrics_are_read_from_the_c3d(realdata, tiny_files, tmp_path):
    lab = tmp_path / "lab"
    lab.mkdir()
    shutil.copy(realdata / "c3d" / "FunctionalWalk.c3d", lab / "tug_S7_t1.c3d")
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t1.scan.parquet", lab / "tug_S7_t1.scan.parquet")
    res = init_study(lab)
    subj = pd.read_csv(lab / "subjects.csv").set_index("subject").loc["S7"]
    # PROCESSING: Height 1680 mm, Bodymass 60 kg, knee widths 99 mm, ankle widths 65 mm,
    # leg lengths 885 and 880 mm
    assert (subj["height_m"], subj["mass_kg"]) == (1.68, 60.0)
    assert (subj["knee_width_m"], subj["ankle_width_m"]) == (0.099, 0.065)
    assert subj["leg_length_m"] == pytest.approx(0.8825)
    assert any("Plug-in-Gait" in n for n in res.notes)
    assert any("knee width is 0.099" in t for t in res.todo)
    # the real walk has no poles: its pose is asked for
    row = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False).iloc[0]
    assert row["sensor_yaw_deg"] == FILL_IN


def test_names_become_safe_ids_and_links_out_of_the_folder_are_skipped(tiny_files, tmp_path):
    lab = tmp_path / "lab"
    lab.mkdir()
    name = "tug_Y01_$(id)"
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t1.scan.parquet", lab / f"{name}.scan.parquet")
    shutil.copy(tiny_files / "mocap" / "tug_Y01_t1.c3d", lab / f"{name}.c3d")
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t2.scan.parquet", outside / "x.scan.parquet")
    (lab / "link.scan.parquet").symlink_to(outside / "x.scan.parquet")
    init_study(lab)
    sheet = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False)
    assert list(sheet["trial"]) == ["tug_Y01___id_"]
    assert list(sheet["scenario"]) == ["__id_"]
    assert list(sheet["sensor_file"]) == [f"{name}.scan.parquet"]   # a file name, quoted
    # the config snippet names this folder's sheet, nothing else
    cfg = yaml.safe_load((lab / "gaitval.config.yaml").read_text())
    assert cfg["studies"]["lab"]["trial_sheet"] == str((lab / "trials.csv").resolve())


def test_an_empty_folder_is_one_clear_error(tmp_path):
    with pytest.raises(GaitvalError, match="no recording"):
        init_study(tmp_path)
    res = run_cli("init-study", str(tmp_path / "missing"))
    assert res.returncode != 0 and "is not a folder" in res.stderr


def test_external_tracks_named_by_trial_become_an_external_method(tiny_files, tmp_path):
    from gaitval.io.tracks.write import write_tracks

    lab = tmp_path / "lab"
    lab.mkdir()
    for t in ("tug_Y01_t1", "tug_Y01_t2"):
        shutil.copy(tiny_files / "lrs" / f"{t}.scan.parquet", lab / f"{t}.scan.parquet")
        shutil.copy(tiny_files / "mocap" / f"{t}.c3d", lab / f"{t}.c3d")
    (lab / "mytracker").mkdir()
    rows = pd.DataFrame({"t_s": [0.0, 0.0], "side": ["L", "R"], "x": [1.0, 1.0],
                         "y": [0.1, -0.1]})
    write_tracks(rows, lab / "mytracker" / "tug_Y01_t1.tracks.csv")
    res = run_cli("init-study", str(lab))
    # declared in the study's own study.yaml, not in the workflow config snippet
    cal = yaml.safe_load((lab / "study.yaml").read_text())
    assert cal["external_methods"] == {"ext_mytracker": {
        "path": "mytracker/{trial}.tracks.csv", "protocols": ["tug"]}}
    assert "tracking" not in yaml.safe_load((lab / "gaitval.config.yaml").read_text())
    # tug_Y01_t2 has no file: said as a cell to fill, and refused as validate refuses it
    assert "external_methods.ext_mytracker: no file for trial(s) tug_Y01_t2" in res.stdout
    assert "1 of 2 trials' track files are missing" in res.stdout, res.stdout
    assert res.returncode == 1


@pytest.mark.slow
def test_init_study_external_methods_pass_validate(tiny_files, tmp_path):
    """Every trial with its track file: the study.yaml init-study writes declares the
    tracker, and `gaitval validate --deep` (schema, files, every file read) accepts it once
    the one cell the files cannot give (the leg width) is filled in; the workflow's own
    start-up check (gaitval.pipeline.steps.declarations.external_declarations) returns the
    entry."""
    from gaitval.io.tracks.write import write_tracks
    from gaitval.pipeline.steps.declarations import external_declarations

    lab = tmp_path / "lab"
    (lab / "tracks").mkdir(parents=True)
    rows = pd.DataFrame({"t_s": [0.0, 0.0, 0.1, 0.1], "side": ["L", "R", "L", "R"],
                         "x": [1.0, 1.0, 1.02, 1.0], "y": [0.1, -0.1, 0.1, -0.1]})
    for t in ("tug_Y01_t1", "tug_Y01_t2"):
        shutil.copy(tiny_files / "lrs" / f"{t}.scan.parquet", lab / f"{t}.scan.parquet")
        shutil.copy(tiny_files / "mocap" / f"{t}.c3d", lab / f"{t}.c3d")
        write_tracks(rows, lab / "tracks" / f"{t}.tracks.csv")
    res = run_cli("init-study", str(lab))
    assert "study.yaml external_methods.ext_tracks: tracks/{trial}.tracks.csv" in res.stdout
    assert "external_methods" not in res.stdout.split("gaitval validate:")[1], res.stdout
    subj = pd.read_csv(lab / "subjects.csv", dtype=str, keep_default_na=False)
    assert list(subj["leg_width_m"]) == [FILL_IN]
    subj["leg_width_m"] = "0.11"
    subj.to_csv(lab / "subjects.csv", index=False)
    val = run_cli("validate", "--deep", str(lab / "trials.csv"))
    assert val.returncode == 0, val.stderr
    got = external_declarations({}, {"lab": lab / "trials.csv"}, {"tug_m1"})
    assert got == {"lab": {"ext_tracks": {"path": "tracks/{trial}.tracks.csv",
                                          "protocols": ["tug"]}}}
    # the same validation as a hand-written entry: a file that does not read is named
    (lab / "tracks" / "tug_Y01_t2.tracks.csv").write_text(
        (lab / "tracks" / "tug_Y01_t2.tracks.csv").read_text().replace("units: m",
                                                                       "units: cm"))
    val = run_cli("validate", "--deep", str(lab / "trials.csv"))
    assert val.returncode == 1
    for w in ("external_methods.ext_tracks", "tug_Y01_t2.tracks.csv", "'units' is 'cm'"):
        assert w in val.stderr, (w, val.stderr)


def test_a_kept_study_yaml_is_not_rewritten_its_missing_methods_are_listed(tiny_files,
                                                                          tmp_path):
    from gaitval.io.tracks.write import write_tracks

    lab = tmp_path / "lab"
    (lab / "tracks").mkdir(parents=True)
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t1.scan.parquet", lab / "tug_Y01_t1.scan.parquet")
    shutil.copy(tiny_files / "mocap" / "tug_Y01_t1.c3d", lab / "tug_Y01_t1.c3d")
    write_tracks(pd.DataFrame({"t_s": [0.0], "side": ["L"], "x": [1.0], "y": [0.1]}),
                 lab / "tracks" / "tug_Y01_t1.tracks.csv")
    (lab / "study.yaml").write_text("registration: {pole_diameter_m: 0.06}\n")
    res = init_study(lab)
    assert (lab / "study.yaml").read_text() == "registration: {pole_diameter_m: 0.06}\n"
    assert any(t.startswith("study.yaml (kept): add under external_methods: ext_tracks: ")
               and "tracks/{trial}.tracks.csv" in t for t in res.todo), res.todo
    assert not any("external_methods" in n for n in res.notes), res.notes


def test_an_unreadable_file_is_reported_not_fatal(tiny_files, tmp_path):
    lab = tmp_path / "lab"
    lab.mkdir()
    shutil.copy(tiny_files / "lrs" / "tug_Y01_t1.scan.parquet", lab / "tug_Y01_t1.scan.parquet")
    (lab / "tug_Y01_t1.c3d").write_bytes(b"not a c3d file")
    res = init_study(lab)
    assert any(u.startswith("tug_Y01_t1.c3d: ") and "C3D" in u for u in res.unpaired)
    assert (lab / "trials.csv").is_file()


def test_a_tracker_recorded_in_the_sensor_bags_is_offered_commented(tiny_files, tmp_path):
    from test_io_tracks_bag import make_bag

    lab = tmp_path / "lab"
    (lab / "bags").mkdir(parents=True)
    make_bag(lab / "bags" / "tug_Y01_t1.bag")
    shutil.copy(tiny_files / "mocap" / "tug_Y01_t1.c3d", lab / "tug_Y01_t1.c3d")
    res = init_study(lab)
    row = pd.read_csv(lab / "trials.csv", dtype=str, keep_default_na=False).iloc[0]
    assert (row["sensor_file"], row["sensor_topic"], row["sensor_height_m"]) == (
        "bags/tug_Y01_t1.bag", "/scan", FILL_IN)        # a bag: no height in its metadata
    text = (lab / "study.yaml").read_text()
    assert "external_methods" not in (yaml.safe_load(text) or {})   # commented: the legs
    assert "\n# external_methods:\n#   ext_" in text
    assert ('\n#   ext_people_tracked: {path: "bags/{trial}.bag", topic: "/people_tracked", '
            "protocols: ['tug'], legs: {L: FILL_IN, R: FILL_IN}}\n") in text
    assert any("/people_tracked" in t and "uncomment" in t for t in res.todo)
    # the bag's leg detections (LegArray): an active external_detections: entry (no legs
    # to map), on the sensor bags themselves
    assert yaml.safe_load(text)["external_detections"] == {"det_detected_leg_clusters": {
        "path": "bags/{trial}.bag", "topic": "/detected_leg_clusters", "protocols": ["tug"]}}
    assert "tracking" not in yaml.safe_load((lab / "gaitval.config.yaml").read_text())
    # filled in and uncommented, the entry is what the workflow's start-up check accepts
    entry = text.split("#   ext_people_tracked: ")[1].splitlines()[0].replace(
        "L: FILL_IN, R: FILL_IN", "L: '1', R: '2'")
    (lab / "study.yaml").write_text(text + f"external_methods:\n  ext_people_tracked: {entry}\n")
    from gaitval.configcheck import check_study_file
    check_study_file(yaml.safe_load((lab / "study.yaml").read_text()), lab / "study.yaml")


def test_heel_trajectories_named_by_trial_become_a_treadmill_method(tiny_files, tmp_path):
    """A foot-tracking system's *.foot.csv beside treadmill recordings: init-study declares
    it with protocols [treadmill] (docs/formats_external.md, Foot trajectories)."""
    from gaitval.io.foot import write_foot

    lab = tmp_path / "lab"
    (lab / "feet").mkdir(parents=True)
    rows = pd.DataFrame({"t_s": np.arange(12) * 0.02, "x": np.linspace(0, 1, 12),
                         "y": 0.0, "z": 0.1})
    for t in ("us_US01_normal", "us_US01_fast"):
        shutil.copy(tiny_files / "ultrasonic" / f"{t}.us.parquet", lab / f"{t}.us.parquet")
        shutil.copy(tiny_files / "ultrasonic" / f"{t}.c3d", lab / f"{t}.c3d")
        write_foot(rows, lab / "feet" / f"{t}.foot.csv")
    res = run_cli("init-study", str(lab))
    cal = yaml.safe_load((lab / "study.yaml").read_text())
    assert cal["external_methods"] == {"ext_feet": {
        "path": "feet/{trial}.foot.csv", "protocols": ["treadmill"]}}, res.stdout
    assert "external_methods.ext_feet: feet/{trial}.foot.csv (treadmill trials)" in res.stdout
