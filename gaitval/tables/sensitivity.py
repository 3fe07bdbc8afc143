"""Sensitivity of the verdicts to the simulated replica's free choices.

The papers leave some set-up choices open (``docs/simulator.md``, "Free choices of the
twin"); the simulated default study makes one choice for each.  For the two that matter
most for MTST (where the sensor stands; on which side the attendant walks) a study preset
per alternative (``config/studies/mtst_*.yaml``: the default study with that one choice
changed, same seed, subjects and trials) is run through the whole pipeline.  This table
puts each verdict of the default report beside the same verdict under each alternative
(``reports/<study>/verdicts.csv``), and says which flip: a conclusion that flips with an
unstated choice is reported as such, not as a finding about the methods.

Usage::

    gaitval sensitivity reports/default reports/mtst_sensor_beside \\
        reports/mtst_attendant_left reports/tug_sit_turn_right \\
        --out reports/default/tables/sensitivity

(the first report is the reference; ``--out`` is a stem: ``.csv``, ``.md``, ``.tex``).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.errors import ConfigError
from gaitval.tables.render import write_table

KEY = ["study", "comparison", "source"]


def _verdicts(report_dir: Path) -> pd.DataFrame:
    f = Path(report_dir) / "verdicts.csv"
    if not f.is_file():
        raise ConfigError(f"no verdicts.csv in {report_dir}", path=f,
                          hint="build that study's report first (python3 run.py report)")
    v = pd.read_csv(f, keep_default_na=False)
    if "outcome" not in v and "reproduced_in_direction" in v:     # a report before issue 35
        v = v.rename(columns={"reproduced_in_direction": "outcome"})
    missing = [c for c in KEY + ["reproduced", "outcome"] if c not in v]
    if missing:
        raise ConfigError(f"verdicts.csv lacks columns {missing}", path=f)
    return v


def sensitivity_table(reports: list[Path], names: list[str] | None = None,
                      protocols: tuple[str, ...] | None = None) -> pd.DataFrame:
    """One row per verdict of the reference report (``reports[0]``): its reproduced value
    and verdict, then per alternative report the same, ``flips_under`` (the alternatives
    whose verdict differs) and ``absent_in`` (the alternatives that do not compute it,
    e.g. a preset without the ultrasonic protocol: shown "absent", not a flip).
    ``protocols`` keeps only those ``study`` values (None: all)."""
    names = names or [Path(r).name for r in reports]
    ref = _verdicts(reports[0])
    if protocols:
        ref = ref[ref["study"].isin(protocols)]
    out = ref[KEY].copy()
    out[f"{names[0]}_reproduced"] = ref["reproduced"].to_numpy()
    out[f"{names[0]}_verdict"] = ref["outcome"].to_numpy()
    flips = [[] for _ in range(len(out))]
    absent = [[] for _ in range(len(out))]
    for rep, name in zip(reports[1:], names[1:]):
        alt = _verdicts(rep).drop_duplicates(KEY).set_index(KEY)
        idx = pd.MultiIndex.from_frame(out[KEY])
        got = alt.reindex(idx)
        out[f"{name}_reproduced"] = got["reproduced"].astype(object).fillna("absent").to_numpy()
        verdict = got["outcome"].astype(object).fillna("absent").to_numpy()
        out[f"{name}_verdict"] = verdict
        for k, (a, b) in enumerate(zip(out[f"{names[0]}_verdict"], verdict)):
            if b == "absent":
                absent[k].append(name)
            elif a != b:
                flips[k].append(name)
    out["flips_under"] = ["; ".join(f) for f in flips]
    out["absent_in"] = ["; ".join(f) for f in absent]
    return out.reset_index(drop=True)


def write_sensitivity(reports: list[Path], out_stem: Path, names: list[str] | None = None,
                      protocols: tuple[str, ...] | None = None) -> list[Path]:
    """Write :func:`sensitivity_table` with :func:`~gaitval.tables.render.write_table`."""
    df = sensitivity_table(reports, names, protocols)
    names = names or [Path(r).name for r in reports]
    n_flip = int((df["flips_under"] != "").sum())
    n_abs = int((df["absent_in"] != "").sum())
    caption = (f"Verdicts of the {names[0]} study beside the same verdicts under each "
               f"alternative free choice of the simulated replica ({', '.join(names[1:])}); "
               f"{n_flip} of {len(df) - n_abs} verdicts computed under every alternative "
               f"flip" + (f" ({n_abs} not computed in some alternative)." if n_abs else "."))
    notes = ["Each alternative is the default study with one set-up choice the paper leaves "
             "open changed (config/studies/<name>.yaml; docs/simulator.md, 'Free choices "
             "of the simulated replica'); same seed, subjects and trials.",
             "A verdict that flips depends on an unstated choice of the set-up: it is not "
             "evidence for or against a method."]
    return write_table(df, out_stem, caption=caption, notes=notes)
