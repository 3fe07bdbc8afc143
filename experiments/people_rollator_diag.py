"""Scan-by-scan diagnosis of the people tracker on a rollator trial (issue 36).

    python experiments/people_rollator_diag.py TRIAL {default|window|window_nomap} [OVERRIDES_JSON]

Reads $GAITVAL_RESULTS/ingest/TRIAL/sensor.parquet and $GAITVAL_DATA/subjects.csv (default
results/default, data/default).  ``default``: the people method as configured; ``window``:
births limited to seed 002's user window; ``window_nomap``: also no ego motion, no static
map.  Prints the observations in the window, births, confirmations and, for every
tentative hypothesis on every scan, the first ``m_of_n_moving`` condition that fails
(docs/history/people.md, "In the protocol tables")."""
import os, sys, math, collections, json
import numpy as np, pandas as pd
from gaitval.io.scanlog import read_scanlog
from gaitval.methods import build_method, METHODS
from gaitval.track import lifecycle
from gaitval.detect.base import split_observations

trial = sys.argv[1] if len(sys.argv) > 1 else "rollator_P01_obstacle_r1"
variant = sys.argv[2] if len(sys.argv) > 2 else "window"
RES = os.environ.get("GAITVAL_RESULTS", "results/default")
DATA = os.environ.get("GAITVAL_DATA", "data/default")
D = "%s/ingest/%s/sensor.parquet" % (RES, trial)
scans = read_scanlog(D, trial=trial)
subj = pd.read_csv(DATA + "/subjects.csv").set_index("subject")
sid = trial.split("_")[1]
w = float(subj.loc[sid, "leg_width_m"])
ov = {}
if variant != "default":
    ov["kind__area"] = {"name": "rectangle", "x_m": [0.10, 1.00], "y_m": [-0.40, 0.40]}
if variant == "window_nomap":
    ov["kind__static_map"] = "none"; ov["kind__ego_motion"] = "none"
if len(sys.argv) > 3: ov.update(json.loads(sys.argv[3]))
kind = build_method("people", ov)
obs_df = kind.detector.detect(scans, w)
xy, pats = split_observations(obs_df, scans.n_scans)
n = scans.n_scans
inwin = [sum(1 for p in xy[k] if 0.10 <= p[0] <= 1.0 and -0.4 <= p[1] <= 0.4) for k in range(n)]
c = collections.Counter(inwin)
print(trial, variant, "scans", n, "leg width", w, "dt", float(np.median(np.diff(scans.t))))
print("observations in the user window per scan:", dict(sorted(c.items())))
allx = np.concatenate([np.asarray(x).reshape(-1, 2) for x in xy])
print("all obs:", len(allx), "range quantiles", np.quantile(np.hypot(allx[:, 0], allx[:, 1]), [0, .1, .5, .9]).round(2) if len(allx) else None)

# instrument the confirmer
reasons = collections.Counter(); per = collections.defaultdict(collections.Counter)
stats = collections.defaultdict(list)
orig = lifecycle.MOfNMoving.step
def step(self, person, k):
    ok = orig(self, person, k)
    mem = person.confirm_memory; win = mem["win"]
    if len(win) < self.n: r = "window not full"
    else:
        rs = [r for r in win if r is not None]
        if len(rs) < self.m: r = "M of N"
        else:
            ux, uy = max(rs, key=lambda r: r[0]**2 + r[1]**2); nrm = math.hypot(ux, uy)
            proj = [(a[0]*ux + a[1]*uy)/nrm for a in rs]; wl = self.pass_leg_widths*self.leg_width_m
            span = max(math.hypot(a[0]-b[0], a[1]-b[1]) for a in rs for b in rs)
            stats["span"].append(span); stats["pmin"].append(min(proj)); stats["pmax"].append(max(proj))
            # world travel
            idx = [i for i, cc in enumerate(mem["world"]) if cc is not None]
            if len({cc[0] for cc in mem["world"] if cc is not None}) == 1 and len(idx) > 1:
                cs = np.array([mem["world"][i][1:] for i in idx]); ti = np.array(idx, float)
                A = np.vstack([ti, np.ones_like(ti)]).T
                sol, *_ = np.linalg.lstsq(A, cs, rcond=None)
                trav = float(np.hypot(*(sol[0] * (ti[-1] - ti[0]))))
                res = float(np.sqrt(((cs - A @ sol) ** 2).sum(1).mean()))
                gap = max(b - a - 1 for a, b in zip(idx[:-1], idx[1:]))
                stats["travel"].append(trav); stats["rms"].append(res); stats["gap"].append(gap)
            if min(proj) > -wl or max(proj) < wl: r = "legs do not pass"
            elif ok: r = "confirmed"
            elif span < self.min_relative_travel_m: r = "r span < d_c"
            else: r = "world travel (d_w / RMS / gap)"
    reasons[r] += 1
    return ok
lifecycle.MOfNMoving.step = step
res = kind.run(scans, xy, pats, w)
ppl = res.people
if len(ppl):
    first = ppl.groupby("person_id").k.min()
    print("confirmed persons first reported at scan:", first.to_dict(), "reported scans:", ppl.k.nunique())
    print("reported centre x quantiles:", ppl.x_m.quantile([.1,.5,.9]).round(2).tolist())
print("born", res.n_born, "confirmed", res.n_confirmed)
print("confirmer outcomes over tentative person-scans:", dict(reasons))
for kk, v in stats.items():
    v = np.array(v); print("  %-7s n=%d quantiles 10/50/90/max: %s" % (kk, len(v), np.quantile(v, [.1, .5, .9, 1]).round(3)))
