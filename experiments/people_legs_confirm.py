"""Confirm a standing person online by how its legs look (issue 55, scope 3).

The online ``people`` method confirms a pair only once it walks, so a person who stands is
never confirmed (docs/people.md, *Known limits*).  The change measured here: the
``legs_confirm`` appearance role (gaitval/track/appearance.py) with a leg classifier
trained on data no test uses (gaitval/crowd/legdata.py: the twin's rendered scenes with
training seeds 1001-1008, and leg_tracker's six positive bags, their leg clusters and
their other clusters; **not** negative_2.bag, the empty-room test): a tentative pair whose
two legs both score P(leg) ≥ θ on K consecutive scans (observed, two separate objects a
leg width apart) is confirmed even when standing.  No pair is refused or ended for its
looks.

Data
----
* Development (looked at, values chosen on it): the crowd benchmark's dev scenes (seed 11,
  five kinds), the dev-only ``following`` scenes (gaitval/crowd/scenes.py
  ``draw_following``, seeds 11-15: a robot following a person who stands, walks, stands
  and walks on), the twin's dev clusters (the crowd dev scenes' clusters labelled by the
  renderer) and leave-one-bag-out over the six positive bags (a forest trained on the
  twin and five bags scores the sixth bag's clusters).
* Test (measured once, after this docstring is committed): the outdoor following bag,
  the crowd test split (seed 23), negative_2.bag on its three lasers read forwards and
  backwards, the tiny study's reference tables.

Choice of θ and K (stated before the dev sweep was run)
-------------------------------------------------------
* θ ∈ {0.5, 0.6, 0.7, 0.8, 0.9} is admissible when the held-out non-leg rate (share of
  non-leg clusters scoring ≥ θ) is ≤ 1e-3 both pooled over the six left-out bags and on
  the twin's dev clusters.  A pair of real clutter clusters that both look like legs on
  K scans is the empty-room failure; one in a thousand clusters is about one a scan in a
  furnished room from a robot (≈ 40 clusters a scan), and two of them within 0.8 m of
  each other on K consecutive scans much rarer.
* K ∈ {3, 5, 8} scans (0.3-0.8 s at 10 Hz, all under the static map's 1.4 s, after which a
  standing pair's legs are static and cannot be confirmed).
* Among admissible (θ, K): the highest sum of the dev MOTA of ``people`` over the six dev
  kinds (five crowd kinds, seed 11; ``following``, seeds 11-15 summed); a tie within 0.5
  points goes to the larger θ, then the larger K (fewer confirmations of furniture).

Candidate B (written after candidate A's dev run found no admissible θ; see the git log)
-------------------------------------------------------------------------------------
Candidate A's per-cluster rule is a proxy: the rule confirms *pairs*.  After it failed,
the pair-level rate was looked at (dev data, left-out bags): scans of the positive bags
with two non-leg clusters 0.077-0.8 m apart (the birth's bounds at w_l 0.11) both scoring
≥ θ: θ 0.7 26 of 1,204 scans, θ 0.9 1 of 1,204.  So candidate B is chosen knowing
these two numbers, which is said here, not hidden:

* θ: the smallest of {0.7, 0.8, 0.9} whose pooled left-out pair rate is ≤ 1e-3 per scan
  (``pairs`` stage);
* K ∈ {3, 5, 8}: the highest summed dev MOTA at that θ, a tie within 0.5 points to the
  larger K.

The test criteria below are unchanged and are what decides adoption.

Criteria (test; adopt into ``people`` only if all hold)
-------------------------------------------------------
1. negative_2.bag, /left_scan, /rear_scan, /right_scan, read forwards and backwards: 0
   persons confirmed by ``people`` and 0 reported by ``people_offline`` with the rule
   (and the existing slow tests pass once adopted).
2. Crowd test split (seed 23): ``people``'s MOTA with the rule above both leg_tracker-rule
   rows on every scene kind.
3. The tiny study: the papers' methods' rows of tests/data/tiny_reference unchanged (only
   the people rows may move).
4. ``person_following_outdoor_1.bag`` (/scan_base2, following mode, online ``people``):
   matched ≥ 6,073, ID switches ≤ 21, MOTP ≤ 0.09 m.

Usage (from the checkout, with a leg_tracker checkout or a folder of its positive bags)::

    .venv/bin/python experiments/people_legs_confirm.py forest LEG_TRACKER_DIR OUT_DIR
    .venv/bin/python experiments/people_legs_confirm.py dev LEG_TRACKER_DIR OUT_DIR
    .venv/bin/python experiments/people_legs_confirm.py pairs LEG_TRACKER_DIR OUT_DIR
    .venv/bin/python experiments/people_legs_confirm.py info OUT_DIR THETA K
    .venv/bin/python experiments/people_legs_confirm.py test OUT_DIR THETA K

``forest`` trains ``OUT_DIR/twin_and_bags.npz``; ``dev`` prints the cluster rates and the
sweep and the chosen (θ, K); ``info`` the dev scores of a given (θ, K), for information
only (not a choice); ``test`` prints the four criteria's numbers.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "experiments"))

THETAS = (0.5, 0.6, 0.7, 0.8, 0.9)
KS = (3, 5, 8)
FOLLOWING_DEV_SEEDS = (11, 12, 13, 14, 15)
MAX_NONLEG_RATE = 1e-3
TIE_POINTS = 0.5


def look(forest, theta, k):
    return {"kind__appearance": {"name": "legs_confirm", "forest": str(forest),
                                 "min_score": float(theta), "n_scans": int(k)}}


def forest_stage(lt_dir, out):
    from gaitval.crowd.legdata import train_forest, training_set
    data = training_set(lt_dir)
    out.mkdir(parents=True, exist_ok=True)
    train_forest(data).save(out / "twin_and_bags.npz")
    print({k: len(v) for k, v in data.items()})


def dev_clusters():
    """The crowd dev scenes' clusters, labelled by the renderer (leg, non-leg)."""
    from gaitval.crowd.legdata import SCAN_STEP, scan_labelled_clusters
    from gaitval.crowd.scenes import DEV_SEEDS, KINDS, draw_scene, render
    pos, neg = [], []
    for seed in DEV_SEEDS:
        for kind in KINDS:
            walks, furn, room, pose, t, rng, _ = draw_scene(kind, seed)
            hits: dict = {}
            scans, _ = render(walks, furn, room, pose, t, rng, hits)
            R = np.ascontiguousarray(scans.ranges, dtype=float)
            for k in range(0, R.shape[0], SCAN_STEP):
                f, lab = scan_labelled_clusters(R[k], hits["id"][k], scans)
                pos.append(f[lab == 1])
                neg.append(f[lab == -1])
    return np.vstack(pos), np.vstack(neg)


def cluster_rates(lt_dir, forest):
    """Per θ: leg and non-leg rates ≥ θ, leave-one-bag-out (real) and on the dev twin."""
    from gaitval.crowd.legdata import bag_clusters, twin_clusters
    from gaitval.track.legforest import POSITIVE_BAGS, load_forest, train
    root = Path(lt_dir)
    sub = root / "rosbags" / "training_scans_res=0.33"
    root = sub if sub.is_dir() else root
    bags = {b: bag_clusters(root / b) for b in POSITIVE_BAGS}
    tp, tn = twin_clusters()
    sp, sn = [], []
    for b in POSITIVE_BAGS:
        others = [v for o, v in bags.items() if o != b]
        f = train(np.vstack([tp, *[v[0] for v in others]]),
                  np.vstack([tn, *[v[1] for v in others]]))
        sp.append(f.votes(bags[b][0]))
        sn.append(f.votes(bags[b][1]))
    sp, sn = np.concatenate(sp), np.concatenate(sn)
    dp, dn = dev_clusters()
    F = load_forest(str(forest))
    vp, vn = F.votes(dp), F.votes(dn)
    rows = {}
    print(f"clusters: bags (left out) {len(sp)} legs / {len(sn)} others; twin dev "
          f"{len(dp)} legs / {len(dn)} others")
    for th in THETAS:
        rows[th] = {"bags_leg": float(np.mean(sp >= th)), "bags_nonleg": float(np.mean(sn >= th)),
                    "twin_leg": float(np.mean(vp >= th)), "twin_nonleg": float(np.mean(vn >= th))}
        print(f"theta {th}: " + ", ".join(f"{k} {v:.4f}" for k, v in rows[th].items()))
    return rows


def dev_scores(overrides):
    """Summed counts of ``people`` per dev kind: crowd dev (seed 11) and following."""
    import pandas as pd

    from gaitval.crowd import bench
    from gaitval.crowd.scenes import FOLLOWING, make_scene
    rows = []
    scenes = [(kind, seed) for _, kind, seed in bench.scenes("dev")] + \
        [(FOLLOWING, s) for s in FOLLOWING_DEV_SEEDS]
    for kind, seed in scenes:
        sc = make_scene(kind, seed)
        res = bench.tracker("people", overrides).track(sc.scans, bench.LEG_WIDTH_M)
        rows.append({"split": "dev", "kind": kind, "seed": seed, "method": "people",
                     **bench.score(sc.truth, bench.hypotheses(res), sc.scans.n_scans)})
    return bench.by_kind(pd.DataFrame(rows))


def pair_rates(lt_dir, thetas=(0.7, 0.8, 0.9), lo=0.077, hi=0.8):
    """Per θ: the share of the left-out positive bags' scans with two non-leg clusters
    ``lo``-``hi`` apart both scoring ≥ θ (each bag scored by the forest trained on the
    twin and the other five bags)."""
    from gaitval.crowd.legdata import bag_clusters, twin_clusters
    from gaitval.track.legforest import (POSITIVE_BAGS, RECIPE, _bag_messages, _clusters,
                                         train)
    root = Path(lt_dir)
    sub = root / "rosbags" / "training_scans_res=0.33"
    root = sub if sub.is_dir() else root
    bags = {b: bag_clusters(root / b) for b in POSITIVE_BAGS}
    tp, tn = twin_clusters()
    n, hits = 0, dict.fromkeys(thetas, 0)
    for b in POSITIVE_BAGS:
        others = [v for o, v in bags.items() if o != b]
        f = train(np.vstack([tp, *[v[0] for v in others]]),
                  np.vstack([tn, *[v[1] for v in others]]))
        poses = np.zeros((0, 2))
        for topic, m in _bag_messages(root / b, ("/training_scan", "/leg_cluster_positions")):
            if topic == "/leg_cluster_positions":
                poses = np.array([[p.position.x, p.position.y]
                                  for p in m.poses]).reshape(-1, 2)
                continue
            if not len(poses):
                continue
            n += 1
            cen, feats = _clusters(m, RECIPE)
            other = np.array([np.hypot(*(poses - c).T).min() >= 1e-4 for c in cen], bool)
            if other.sum() < 2:
                continue
            cen, v = cen[other], f.votes(feats[other])
            for th in thetas:
                c = cen[v >= th]
                d = np.hypot(*(c[:, None] - c[None]).transpose(2, 0, 1))
                hits[th] += bool(((d >= lo) & (d <= hi)).any())
    for th in thetas:
        print(f"theta {th}: {hits[th]} of {n} scans ({hits[th] / n:.4f})")
    return {th: hits[th] / n for th in thetas}


def dev_stage(lt_dir, out):
    forest = out / "twin_and_bags.npz"
    rates = cluster_rates(lt_dir, forest)
    ok = [th for th in THETAS if rates[th]["bags_nonleg"] <= MAX_NONLEG_RATE
          and rates[th]["twin_nonleg"] <= MAX_NONLEG_RATE]
    print("admissible theta:", ok)
    base = dev_scores({})
    print("without the rule:\n" + base[["kind", "gt", "matched", "fp", "idsw_ref",
                                        "mota_pct"]].to_string(index=False))
    results = []
    for th in ok:
        for k in KS:
            t = dev_scores(look(forest, th, k))
            total = float(t["mota_pct"].sum())
            results.append((total, th, k))
            print(f"theta {th} K {k}: sum MOTA {total:.1f}  " + "  ".join(
                f"{r.kind} {r.mota_pct:.1f} (fp {r.fp})" for r in t.itertuples()))
    if not results:
        print("no admissible theta")
        return
    best = max(r[0] for r in results)
    chosen = max((r for r in results if r[0] >= best - TIE_POINTS), key=lambda r: (r[1], r[2]))
    print(f"chosen: theta {chosen[1]} K {chosen[2]} (sum MOTA {chosen[0]:.1f}; best {best:.1f})")


def empty_room_and_crowd_test(over):
    """Criteria 1 and 2 of a candidate's test, printed: negative_2.bag's three lasers read
    forwards and backwards (people confirmed and re-found, people_offline's persons), and
    the crowd test split's MOTA per kind and method (people methods with ``over``)."""
    from gaitval.track.passes import reversed_scans

    from gaitval.crowd import bench
    from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans
    from gaitval.methods import build_method
    bag = ROOT.parent / "shared" / "realdata" / "lrs" / "negative_2.bag"
    for topic in describe_rosbag(bag)["scans"]:
        scans = read_rosbag_scans(bag, topic)
        back = reversed_scans(scans)
        for way, s in (("forwards", scans), ("backwards", back)):
            on = build_method("people", over).track(s, 0.10)
            off = build_method("people_offline", over).track(s, 0.10)
            print(f"1. negative_2 {topic} {way}: people confirmed {on.n_confirmed} "
                  f"re-found {on.n_refound}; people_offline persons "
                  f"{off.people['person_id'].nunique()}")
    rows = bench.run("test", overrides={"people": over, "people_offline": over})
    t = bench.by_kind(rows)
    print("2. crowd test:\n" + t.pivot(index="kind", columns="method",
                                      values="mota_pct").round(1).to_string())


def test_stage(out, theta, k):
    from outdoor_score import score_outdoor
    over = look(out / "twin_and_bags.npz", theta, k)
    # 1. the empty room, three lasers, forwards and backwards;
    # 2. the crowd test split against the leg_tracker-rule rows
    empty_room_and_crowd_test(over)
    # 4. the outdoor bag (3: the tiny study, by its slow test once adopted)
    print("4. outdoor:", score_outdoor(over))


if __name__ == "__main__":
    stage = sys.argv[1]
    if stage == "forest":
        forest_stage(sys.argv[2], Path(sys.argv[3]))
    elif stage == "dev":
        dev_stage(sys.argv[2], Path(sys.argv[3]))
    elif stage == "pairs":       # candidate B: the pair rates, then the K sweep
        rates = pair_rates(sys.argv[2])
        ok = [th for th, r in rates.items() if r <= MAX_NONLEG_RATE]
        if ok:
            th = min(ok)
            res = []
            for k in KS:
                t = dev_scores(look(Path(sys.argv[3]) / "twin_and_bags.npz", th, k))
                res.append((float(t["mota_pct"].sum()), k))
                print(f"theta {th} K {k}: sum MOTA {res[-1][0]:.1f}  " + "  ".join(
                    f"{r.kind} {r.mota_pct:.1f} (fp {r.fp})" for r in t.itertuples()))
            best = max(r[0] for r in res)
            k = max(r[1] for r in res if r[0] >= best - TIE_POINTS)
            print(f"candidate B: theta {th} K {k}")
        else:
            print("candidate B: no admissible theta")
    elif stage == "info":        # dev scores of given (θ, K): information, not a choice
        t = dev_scores(look(Path(sys.argv[2]) / "twin_and_bags.npz", float(sys.argv[3]),
                            int(sys.argv[4])))
        print(t[["kind", "gt", "matched", "fp", "idsw_ref", "mota_pct"]].to_string(index=False))
    elif stage == "test":
        test_stage(Path(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]))
