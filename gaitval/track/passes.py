"""How many times the people tracker reads a recording: online, or forwards and backwards.

Role ``passes`` of the ``people`` kind (docs/people.md, "Two passes";
``experiments/people_gate.py`` has the criteria it was judged by).

``forward`` (the default)
    The tracker reads the scans once, in time order: what a robot can do, and what
    leg_tracker does.  A person is reported only from the scan on which it is confirmed.
``forward_backward``
    gaitval analyses recordings that are complete before it starts.  A person who stands
    and walks only later (a TUG subject on the chair, a person who steps into view and
    waits) is confirmed by an online tracker only once it walks; read backwards in time the
    same person walks *first* and stands afterwards, and a confirmed person needs
    observations, not motion, to stay confirmed.  The tracker is run a second time on the
    scans in reverse order (same roles and values, no initialiser), and the two passes are
    joined (:func:`join_passes`).  This uses future scans: an offline method, not
    comparable with an online tracker such as leg_tracker.

With ``extend_only`` a backward person that joins no forward person is dropped: the
backward pass only extends the persons the forward (online) pass confirmed, back to their
first appearance and across their gaps (on the reversed empty room the backward pass
alone confirms furniture the forward pass does not).

The join (per pair of persons, forward f and backward b, reported on common scans)::

    d(f, b) = median over the scans both report of |c_f(k) − c_b(k)|   (c: body centre)
    f ~ b   ⇔  d(f, b) ≤ g(0)      (leg_tracker's person gate with no unobserved scan,
                                    lifecycle.leg_tracker_person_gate; 0.83 m at 10 Hz and 7.5 Hz)

Links are taken nearest first (smallest d, then the forward id, then the backward id);
two groups are joined only if the result holds at most one forward person on any scan,
and at most one backward person on any scan unless the backward person joins alone
(linked to no forward person yet: the outdoor bag's backward pass holds its followed
person twice for a while, and only the earlier track reaches back before the forward
pass confirmed them).  A group is reported with the smallest forward id it holds (a backward-only person
gets an id after every forward id); on each scan it takes the forward pass's rows where a
forward member is reported, otherwise the backward pass's (the member with more legs
observed on that scan, then the smaller id).  A backward member's left/right labels are
swapped when that brings its legs nearer to the forward members' on the scans both
report (summed distance).  The subject (the person the studies evaluate) and its
left/right labels are the forward pass's: the group holding the forward pass's subject,
labelled as the forward pass labelled it (``PeopleTracker.run``).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.registry import Registry
from gaitval.track.lifecycle import leg_tracker_person_gate

PASSES = Registry("passes")


class Passes:
    """Role base: ``backward`` says whether a reversed pass is run; :meth:`join` joins the
    two passes' reported rows (forward-time scan indices)."""

    backward = False

    def join(self, fwd: pd.DataFrame, bwd: pd.DataFrame, dt: float
             ) -> tuple[pd.DataFrame, dict]:
        """The joined rows and the id each forward person is reported with."""
        return fwd, {}


@PASSES.register("forward")
class Forward(Passes):
    """One pass in time order (online)."""


@PASSES.register("forward_backward")
class ForwardBackward(Passes):
    """A forward and a backward pass, joined (module notes).  The link gate is
    leg_tracker's person gate g(0) with its defaults (``max_std`` 0.9 m,
    ``confidence_percentile`` 0.90, observation std 0.1 m, +0.4 m for association)."""

    backward = True

    def __init__(self, max_std_m: float = 0.9, percentile: float = 0.90,
                 std_obs_m: float = 0.1, assoc_extra_m: float = 0.4,
                 extend_only: bool = False, splice_window_s: float | None = None):
        self.extend_only = bool(extend_only)
        self.splice_window_s = splice_window_s
        self.max_std_m = max_std_m
        self.percentile = percentile
        self.std_obs_m = std_obs_m
        self.assoc_extra_m = assoc_extra_m

    def link_gate(self, dt: float) -> float:
        return float(leg_tracker_person_gate(dt, self.max_std_m, self.percentile,
                                             self.std_obs_m, self.assoc_extra_m)[0])

    def join(self, fwd, bwd, dt):
        n = (None if self.splice_window_s is None
             else max(1, int(round(self.splice_window_s / dt))))
        return join_passes(fwd, bwd, self.link_gate(dt), self.extend_only, n)


def reversed_scans(scans):
    """The scans read backwards: scan k ↦ n − 1 − k, the times mirrored into the same span
    (t ↦ t₀ + t_end − t, so they still increase)."""
    from dataclasses import replace

    t = np.asarray(scans.t, dtype=float)
    return replace(scans, t=(t[0] + t[-1]) - t[::-1],
                   ranges=np.ascontiguousarray(scans.ranges[::-1]))


def reverse_rows(rows: pd.DataFrame, t: np.ndarray) -> pd.DataFrame:
    """A backward pass's rows in forward time: scan k ↦ n − 1 − k, its time t[k], and the
    velocities negated."""
    out = rows.copy()
    n = len(t)
    k = (n - 1 - out["k"].to_numpy()).astype(np.int64)
    out["k"] = k
    out["t_sensor_s"] = np.asarray(t, float)[k]
    out["vx_mps"] = -out["vx_mps"].to_numpy(float)
    out["vy_mps"] = -out["vy_mps"].to_numpy(float)
    return out


def _centres(rows: pd.DataFrame) -> pd.DataFrame:
    """Body centre per (person, scan): the mean of the two legs."""
    return rows.groupby(["person_id", "k"], sort=True)[["x_m", "y_m"]].mean().reset_index()


def join_passes(fwd: pd.DataFrame, bwd: pd.DataFrame, gate_m: float,
                extend_only: bool = False, splice_scans: int | None = None
                ) -> tuple[pd.DataFrame, dict]:
    """Join the forward pass's reported rows ``fwd`` and the backward pass's ``bwd`` (both in
    forward time, :func:`reverse_rows`) into one table of persons (module notes), and the
    id each forward person is reported with.  ``extend_only``: a backward person that joins
    no forward person is dropped.  ``splice_scans``: align each run of backward rows by the
    scans within this many of it (None: by the whole overlap)."""
    cols = list(fwd.columns) if len(fwd.columns) else list(bwd.columns)
    if bwd.empty:
        return fwd, {}
    top = int(fwd["person_id"].max()) if len(fwd) else 0
    cf, cb = _centres(fwd), _centres(bwd)
    # the scans each person is reported on
    kf = {int(p): set(g["k"].tolist()) for p, g in cf.groupby("person_id")}
    kb = {int(p): set(g["k"].tolist()) for p, g in cb.groupby("person_id")}
    members = _groups(kf, kb, _links(cf, cb, gate_m))
    fid = {p: min(q for s, q in m if s == "f") for m in members for s0, p in m
           if s0 == "f"}
    parts = [fwd.assign(person_id=fwd["person_id"].map(fid))]
    for mem in members:
        rows = _backward_rows(mem, fwd, bwd, kf, top, extend_only, splice_scans)
        if rows is not None:
            parts.append(rows)
    res = pd.concat(parts, ignore_index=True)[cols]
    res = res.sort_values(["k", "person_id", "side"], kind="stable").reset_index(drop=True)
    return res.astype({"k": np.int64, "person_id": np.int64, "phase": np.int64,
                       "observed": bool}), fid


def _links(cf: pd.DataFrame, cb: pd.DataFrame, gate_m: float) -> list:
    """(median centre distance, forward id, backward id) of the pairs of persons whose
    median distance over the scans both report is within ``gate_m``, nearest first."""
    both = cf.merge(cb, on="k", suffixes=("_f", "_b"))
    if not len(both):
        return []
    both["d"] = np.hypot(both["x_m_f"] - both["x_m_b"], both["y_m_f"] - both["y_m_b"])
    med = both.groupby(["person_id_f", "person_id_b"], sort=True)["d"].median()
    return sorted((float(d), int(f), int(b)) for (f, b), d in med.items() if d <= gate_m)


def _groups(kf: dict, kb: dict, links: list) -> list[list]:
    """Union of the linked persons, nearest links first, each group holding at most one
    forward person on any scan, and at most one backward person on any scan unless the
    backward person joins it alone (linked to no forward person yet): the groups' members
    ``("f"|"b", id)``, in order."""
    group = {("f", p): ("f", p) for p in kf} | {("b", p): ("b", p) for p in kb}
    members = {g: [g] for g in group}

    def root(x):
        while group[x] != x:
            x = group[x]
        return x

    def scans(g, side):
        sets = [kf[p] if s == "f" else kb[p] for s, p in members[g] if s == side]
        return set().union(*sets) if sets else set()

    for _, f, b in links:
        a, c = root(("f", f)), root(("b", b))
        # a backward person no forward person has taken may share scans with the group's
        # backward members: the group reports one of them per scan (_backward_rows)
        lone = all(s == "b" for s, _ in members[c])
        sides = ("f",) if lone else ("f", "b")
        if a == c or any(scans(a, side) & scans(c, side) for side in sides):
            continue
        group[c] = a
        members[a] += members.pop(c)
    return [m for _, m in sorted(members.items())]


def _backward_rows(mem, fwd, bwd, kf, top, extend_only, splice_scans):
    """A group's backward rows on the scans its forward members do not report (one
    backward member per scan: more legs observed, then the smaller id), labelled with the
    group's id and aligned with its forward legs; None when it adds nothing."""
    bs = sorted(q for s, q in mem if s == "b")
    fs = sorted(q for s, q in mem if s == "f")
    if not bs or (not fs and extend_only):
        return None
    rows = bwd[bwd["person_id"].isin(bs)]
    if fs:
        rows = rows[~rows["k"].isin(set().union(*(kf[q] for q in fs)))]
    if rows.empty:
        return None
    seen = rows.groupby(["k", "person_id"], sort=True)["observed"].sum().reset_index()
    seen = seen.sort_values(["k", "observed", "person_id"], ascending=[True, False, True],
                            kind="stable").drop_duplicates("k")
    rows = rows.merge(seen[["k", "person_id"]], on=["k", "person_id"])
    if fs:
        rows = _align_sides(rows, fwd[fwd["person_id"].isin(fs)],
                            bwd[bwd["person_id"].isin(bs)], splice_scans)
    return rows.assign(person_id=fs[0] if fs else top + bs[0])


def _align_sides(rows: pd.DataFrame, fwd: pd.DataFrame, bwd_all: pd.DataFrame,
                 splice_scans: int | None = None) -> pd.DataFrame:
    """Swap backward rows' L/R labels when that brings the backward member's legs nearer to
    the forward members' (summed distance): per run of consecutive scans of one member, on
    the scans both report within ``splice_scans`` before and after the run; a run with
    none such, or ``splice_scans`` None, by every scan both report."""
    fl = fwd.pivot_table(index="k", columns="side", values=["x_m", "y_m"], aggfunc="first")
    parts = []
    for pid, g in rows.groupby("person_id", sort=True):
        b = bwd_all[bwd_all["person_id"] == pid].pivot_table(
            index="k", columns="side", values=["x_m", "y_m"], aggfunc="first")
        common = fl.index.intersection(b.index)
        whole = _swapped(fl, b, common)
        if splice_scans is None:
            runs = [(g, whole)]
        else:
            ks = np.sort(g["k"].unique())
            cuts = np.flatnonzero(np.diff(ks) != 1) + 1
            runs = []
            for run in np.split(ks, cuts):
                a, z = int(run[0]), int(run[-1])
                near = common[((common >= a - splice_scans) & (common < a))
                              | ((common > z) & (common <= z + splice_scans))]
                runs.append((g[g["k"].between(a, z)], _swapped(fl, b, near) if len(near)
                             else whole))
        for part, swap in runs:
            if swap:
                part = part.assign(side=part["side"].map({"L": "R", "R": "L"}))
            parts.append(part)
    return pd.concat(parts, ignore_index=True) if parts else rows


def _swapped(F: pd.DataFrame, B: pd.DataFrame, ks) -> bool:
    """On scans ``ks``, are B's legs nearer to F's with L and R exchanged (summed distance)?"""
    if not len(ks):
        return False
    F, B = F.loc[ks], B.loc[ks]

    def dist(s1, s2):
        return float(np.hypot(F[("x_m", s1)] - B[("x_m", s2)],
                              F[("y_m", s1)] - B[("y_m", s2)]).sum())

    return dist("L", "R") + dist("R", "L") < dist("L", "L") + dist("R", "R")
