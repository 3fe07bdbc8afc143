"""Does a tighter 180° turn make the rollator KF fail? (issue 54: Table II untestable)

Seed 002 says the KF "tracks the user successfully in straight paths, but almost always
loses track of the user in turns when the legs are occluded" (§IV-B); its Table II has
4,670 KF error frames and 107 PF.  The twin's default scenario 1 turns on a 0.6 m pelvis
radius (no source) and neither tracker loses a frame (docs/rollator.md).  The turn radius
is now a preset key (``rollator.path.turn_radius_m``); this script runs the default
study's 16 rollator trials (4 patients x 2 scenarios x 2 repetitions, seed 20150904; the
other protocols at the tiny sizes, not read) at 0.3, 0.6 and 0.9 m and prints Table II's
error frames per tracker and scenario.

Question (written before it ran): at 0.3 m, does the KF lose frames in scenario 1's turn
(KF error frames > 1 % of scenario 1's frames) while the PF stays under it?  A diagnostic
of whether the radius can make Table II testable; the default radius is not changed on
its result (that would be tuning the twin towards the paper's robustness claim).

Usage::

    .venv/bin/python experiments/rollator_turn_radius.py WORKDIR [RADIUS ...]
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
PRESETS = ROOT / "config" / "studies" / "robustness_turncheck"    # not tracked (.gitignore)


def preset(radius: float) -> dict:
    base = yaml.safe_load((ROOT / "config" / "studies" / "default.yaml").read_text())
    tiny = yaml.safe_load((ROOT / "config" / "studies" / "tiny.yaml").read_text())
    for proto in ("tug", "mtst", "ultrasonic"):
        base[proto] = tiny[proto]
    base["rollator"]["path"] = {"turn_radius_m": float(radius)}
    base["study"] = f"turn{int(round(radius * 100)):03d}"
    return base


def main(work: Path, radii: list[float]) -> None:
    import pandas as pd

    PRESETS.mkdir(parents=True, exist_ok=True)
    studies, names = {}, []
    for r in radii:
        p = preset(r)
        name = p["study"]
        (PRESETS / f"{name}.yaml").write_text(yaml.safe_dump(p, sort_keys=False))
        studies[name] = {"simulate": {"preset": f"robustness_turncheck/{name}",
                                      "seed": 20150904}}
        names.append(name)
    work.mkdir(parents=True, exist_ok=True)
    for n in names:                       # one run per study: a run's tables pool its studies
        cfg = work / f"{n}.yaml"
        cfg.write_text(yaml.safe_dump({"studies": studies, "run": [n], "peer_results": "",
                                       "rollator": {"methods": ["rollator_kf",
                                                                "rollator_pf"]}}))
        cmd = [str(ROOT / ".venv" / "bin" / "snakemake"),
               f"reports/{n}/tables/rollator_table2.csv", "--snakefile",
               str(ROOT / "Snakefile"), "--profile",
               str(ROOT / "workflow" / "profiles" / "default"), "--directory", str(work),
               "--configfile", str(cfg)]
        res = subprocess.run(cmd, capture_output=True, text=True)
        if res.returncode:
            sys.exit(res.stderr[-3000:])
    pd.set_option("display.width", 200)
    for r, n in zip(radii, names):
        t = pd.read_csv(work / "reports" / n / "tables" / "rollator_table2.csv")
        print(f"\nturn radius {r} m ({n}):")
        print(t.to_string(index=False))


if __name__ == "__main__":
    main(Path(sys.argv[1]).resolve(), [float(x) for x in sys.argv[2:]] or [0.3, 0.6, 0.9])
