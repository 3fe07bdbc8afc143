"""Do the rollator's rear frame tubes explain the PF's error frames in every twin with
the laser mounted far forward? (issue 54; docs/robustness.md, *Rollator*)

Last session looked at one trial of one twin (rob_08, P01 straight r1): the PF's right
leg sat on a rear frame tube.  This script asks the same of every rollator trial of every
twin of the ensemble, from its per-frame results (``results/<twin>/rollator/
rollator_{kf,pf}/<trial>/frames.parquet``) and the design (``reports/robustness/
design.csv``, the mount ``rollator_mount_x_m``).

The tubes in the laser frame: the laser sits on the rollator's rear cross-bar at
(mount_x, 0) facing the user (yaw π); the rear tubes stand at frame (−0.30, ±0.28)
(``gaitval.simulate.rollator.RLT_CORNERS``), so at laser (0.30 + mount_x, ∓0.28).

Question and criterion (written before the script ran):
  an error frame is "on a tube" when either leg's estimate lies within 0.12 m (two leg
  radii) of a tube centre.  If, in each twin with mount −0.20 to −0.15 m (the six twins
  docs/robustness.md names), at least 90 % of the
  PF's error frames are on a tube, the tubes explain the PF's failures there; otherwise
  something else does too, and the script says how many are not.

Usage (after ``python3 run.py robustness``; reports/ and results/ are not in git)::

    .venv/bin/python experiments/rollator_pf_frame_tubes.py [THRESHOLD_M]
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def tubes(mount_x: float) -> np.ndarray:
    from gaitval.simulate.rollator import RLT_CORNERS
    pts = [RLT_CORNERS["RLT_RL"], RLT_CORNERS["RLT_RR"]]
    # laser frame = rotation by −π about the mount: (x, y) → (mount_x − x, −y)
    return np.array([(mount_x - x, -y) for x, y in pts])


def on_tube(fr: pd.DataFrame, tb: np.ndarray, thr: float) -> np.ndarray:
    near = np.zeros(len(fr), bool)
    for s in ("L", "R"):
        p = fr[[f"x_m_{s}", f"y_m_{s}"]].to_numpy()
        d = np.hypot(p[:, None, 0] - tb[None, :, 0], p[:, None, 1] - tb[None, :, 1]).min(1)
        near |= d < thr
    return near


def main(thr: float = 0.12) -> None:
    design = pd.read_csv(ROOT / "reports" / "robustness" / "design.csv").set_index("twin")
    rows = []
    for twin, d in design.iterrows():
        mx = float(d["rollator_mount_x_m"])
        tb = tubes(mx)
        for tracker in ("rollator_kf", "rollator_pf"):
            for f in sorted((ROOT / "results" / twin / "rollator" / tracker).glob(
                    "*/frames.parquet")):
                fr = pd.read_parquet(f)
                ev = fr[fr["status"] != "outside_capture"]
                err = ev[ev["error"]]
                rows.append({"twin": twin, "mount_x_m": round(mx, 3),
                             "tube_ahead_m": round(float(tb[0, 0]), 3), "tracker": tracker,
                             "trial": f.parent.name, "frames": len(ev), "error": len(err),
                             "error_on_tube": int(on_tube(err, tb, thr).sum()),
                             "ok_on_tube": int(on_tube(ev[~ev["error"]], tb, thr).sum())})
    t = pd.DataFrame(rows)
    per = t.groupby(["twin", "mount_x_m", "tube_ahead_m", "tracker"], as_index=False)[
        ["frames", "error", "error_on_tube", "ok_on_tube"]].sum()
    per["share_on_tube"] = (per["error_on_tube"] / per["error"].where(per["error"] > 0)).round(3)
    pd.set_option("display.width", 200)
    print(per.sort_values(["tracker", "mount_x_m"]).to_string(index=False))
    far = per[(per["mount_x_m"] >= -0.20) & (per["tracker"] == "rollator_pf")]
    ok = bool((far["share_on_tube"] >= 0.9).all())
    print(f"\nPF, mount -0.20 to -0.15 m: {len(far)} twins; error frames {int(far['error'].sum())}, "
          f"on a tube {int(far['error_on_tube'].sum())}; every twin >= 90 % on a tube: {ok}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 0.12)
