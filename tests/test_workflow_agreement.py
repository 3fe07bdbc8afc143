"""Issue 37: a study's own paired results (config ``agreement_files``: per walk or stride,
a system's value beside its reference's) become an agreement table ``peer_<name>`` of the
report; a file that is not there stops the run at start with one ConfigError."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from conftest import copy_run, tiny_workflow

TARGET = "reports/tiny/tables/peer_vendor.csv"


@pytest.mark.slow
def test_declared_paired_results_give_their_agreement_table(tiny_run, tmp_path):
    work = tmp_path / "w"
    copy_run(tiny_run / "data", work / "data")
    rng = np.random.default_rng(37)
    rows = []
    for s in range(6):                      # 6 subjects x 8 strides, bias 0.02 m
        for _ in range(8):
            gt = rng.normal(1.3, 0.1)
            rows.append({"subject": f"S{s}", "gt_stride_length": gt,
                         "sys_stride_length": gt + 0.02 + rng.normal(0, 0.01)})
    pd.DataFrame(rows).to_csv(tmp_path / "vendor.csv", index=False)
    cf = tmp_path / "cf.yaml"
    cf.write_text(yaml.safe_dump({"agreement_files": {"vendor": {
        "path": str(tmp_path / "vendor.csv"), "system": "sys_", "reference": "gt_",
        "units": {"stride_length": "m"}}}}))
    res = tiny_workflow(work, "--configfile", str(cf), targets=[TARGET])
    assert res.returncode == 0, res.stderr[-3000:]
    t = pd.read_csv(work / TARGET).set_index("parameter")
    r = t.loc["stride_length"]
    assert r["unit"] == "m" and r["n"] == 48 and r["n_subjects"] == 6
    d = pd.DataFrame(rows)
    want = (d["sys_stride_length"] - d["gt_stride_length"]).mean()
    assert r["bias"] == pytest.approx(want, rel=1e-5)
    assert abs(r["bias"] - 0.02) < 0.005
    # an edited entry is a param: the dry run plans its table again, nothing else of note
    cf.write_text(yaml.safe_dump({"agreement_files": {"vendor": {
        "path": str(tmp_path / "vendor.csv"), "system": "sys_", "reference": "gt_"}}}))
    dry = tiny_workflow(work, "--configfile", str(cf), "-n", targets=[TARGET])
    assert dry.returncode == 0 and "rule agreement_file:" in dry.stdout + dry.stderr
    # a path that does not exist stops at start
    cf.write_text(yaml.safe_dump({"agreement_files": {"vendor": {
        "path": str(tmp_path / "nothere.csv")}}}))
    bad = tiny_workflow(work, "--configfile", str(cf), "-n", targets=[TARGET])
    out = bad.stdout + bad.stderr
    assert bad.returncode != 0 and out.count("ConfigError") == 1
    assert "agreement_files.vendor.path" in out and "nothere.csv" in out
