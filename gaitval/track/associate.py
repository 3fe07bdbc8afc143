"""Data associators: which observation (if any) each leg takes at a scan.

Role ``associator``: ``select(cand_l, cand_r, prev_phase, phase_of) -> (a, b)``.

``cand_l`` / ``cand_r`` list the gated observations of each leg as ``(j, λ²)`` with
j = 1..J (1-based, as in the paper) and λ² the squared Mahalanobis distance of seed000
seed000 eq. (11), as the gate role returns them; the associator's ``cost`` turns λ² into its
distance d: ``"mahalanobis"`` d = λ (seed000 eq. (9)–(10)) or ``"mahalanobis2"`` d = λ²
(seed001 eq. (6)–(8), "squared, no root");
``phase_of(a, b)`` returns the gait phase the legs would be in after correcting the left
leg with observation a and the right with b (0 = no observation, a false alarm).
The result (a, b) uses the same numbering; a = b only when both are 0.

Notes
-----
Cost of an association, seed000 eq. (9)–(10): c_{a,b} = d_{L,a} + d_{R,b} with
d_{f,j} = λ_{f,j}
inside the gate and d_max outside it or for j = 0.  Only gated observations are offered:
§5.2 builds the gate "to eliminate unlikely observation-to-track associations", so an
observation outside a leg's gate is never associated with it (d_max only prices that
case like a false alarm).  The literal alternative — enumerating out-of-gate
observations at cost d_max when every gated association is an unlikely phase change
(0.3 % of steps) — was tried on the default study: Method 2 went from 4 to 2 and
Method 3 from 7 to 1 successful trials (far observations taken → swaps), so it is not
used.  d_max defaults to √G = √13.82 (the
gate's edge in λ units), so taking any gated observation costs less than leaving it.

GNN (Method 1) picks the least-cost association.  The gait-phase association (Methods 2,
3, seed 000 §5.2) picks the least-cost association whose phase change from k−1 is not
in the list of unlikely transitions; when every association is unlikely it falls back to
the least-cost one (the paper does not say; this keeps tracking rather than dropping both
legs).  Ties are broken by enumeration order (a, then b, ascending), so results are
deterministic.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), §5.2.
Konstantinova, P.; Udvarev, A.; Semerdjiev, T. A Study of a Target Tracking Algorithm Using
Global Nearest Neighbor Approach. CompSysTech 2003.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

from gaitval.errors import ConfigError
from gaitval.gait.phases import UNLIKELY_TRANSITIONS
from gaitval.registry import Registry
from gaitval.track.params import declared, param

ASSOCIATORS = Registry("associator", table="gaitval.track.roles")

D_MAX_DEFAULT = math.sqrt(13.82)
_NO_PHASES: frozenset = frozenset()


_COSTS = ("mahalanobis", "mahalanobis2")


@dataclass(eq=False)
class Associator:
    """Role base."""

    #: ``select`` calls ``phase_of`` (False: the tracker may pass None and skip its cache)
    uses_phase = True
    d_max: float = param(D_MAX_DEFAULT, "λ (or λ² with cost mahalanobis2)",
                         "seed000 eq. (9)–(10); √G, the χ² gate's edge (gaitval's choice)",
                         "cost of leaving a leg without an observation")
    cost: str = param("mahalanobis", "-", "seed000 eq. (10) (λ); seed001 eq. (8) (λ²)",
                      "mahalanobis (d = λ) or mahalanobis2 (d = λ²)")

    def __post_init__(self):
        if self.cost not in _COSTS:
            raise ConfigError(f"unknown association cost {self.cost!r}",
                              hint=f"choose one of: {', '.join(_COSTS)}")

    def distances(self, cand: list[tuple[int, float]]) -> list[tuple[int, float]]:
        """``(j, d)`` from the gate's ``(j, λ²)``."""
        if self.cost == "mahalanobis":
            return [(j, math.sqrt(lam2)) for j, lam2 in cand]
        return cand

    def obvious(self, cand_l, cand_r) -> tuple[int, int]:
        """The least-cost association when it is obvious, else (-1, -1).

        With at most one gated observation per leg, different ones, and each one's cost
        below d_max, taking them costs less than any alternative (the same result as the
        full ranking).  Tested on the gate's ``(j, λ²)``, each cost computed on the spot.
        """
        if len(cand_l) > 1 or len(cand_r) > 1:
            return -1, -1
        a = cand_l[0][0] if cand_l else 0
        b = cand_r[0][0] if cand_r else 0
        if a and a == b:
            return -1, -1
        d_max = self.d_max
        if self.cost == "mahalanobis":
            sqrt = math.sqrt
            if ((cand_l and sqrt(cand_l[0][1]) >= d_max)            # d = λ, seed000 eq. (10)
                    or (cand_r and sqrt(cand_r[0][1]) >= d_max)):
                return -1, -1
        elif (cand_l and cand_l[0][1] >= d_max) or (cand_r and cand_r[0][1] >= d_max):
            return -1, -1
        return a, b

    def select(self, cand_l: list[tuple[int, float]], cand_r: list[tuple[int, float]],
               prev_phase: int, phase_of: Callable[[int, int], int]) -> tuple[int, int]:
        raise NotImplementedError

    def kernel(self, run):
        """``(associate, update)`` for one run
        (:class:`~gaitval.track.trackingrun.TrackingRun`).

        ``associate(k, prior, obs, cand_l, cand_r) -> (a, b)`` selects the association at
        scan k (seed000 eq. (9)–(10)); ``update(prior, obs, a, b) -> (post_l, post_r,
        phase)`` corrects both legs with it (seed000 eq. (14)–(16)) and names their gait
        phase (seed000 eq. (3)–(5)).  An associator that compares candidates' phases
        (``uses_phase``) computes them through one :class:`Hypotheses` per run, and
        ``update`` reads the chosen one from it.
        """
        select, phase = self.select, run.phase
        correct, identify = run.filter.correct, run.phase_model.identify
        if not self.uses_phase:
            def associate(k, prior, obs, cand_l, cand_r):
                return select(cand_l, cand_r, phase[k - 1], None)

            def update(prior, obs, a, b):
                pl, pr = prior
                if a:
                    z = obs[a - 1]
                    pl = correct(pl, z[0], z[1])              # seed000 eq. (14)–(16)
                if b:
                    z = obs[b - 1]
                    pr = correct(pr, z[0], z[1])
                return pl, pr, identify(pl, pr)               # seed000 eq. (3)–(5)
            return associate, update
        hyp = Hypotheses(correct, identify)
        reset, phase_of, outcome = hyp.reset, hyp.phase_of, hyp.outcome

        def associate(k, prior, obs, cand_l, cand_r):
            reset(prior, obs)
            return select(cand_l, cand_r, phase[k - 1], phase_of)

        def update(prior, obs, a, b):
            return outcome(a, b)
        return associate, update


class Hypotheses:
    """Corrected states and gait phases of one scan's candidate associations, computed
    on demand and cached (the gait-phase associator asks for several, seed 000 §5.2).

    ``corrected(f, j)``: leg f corrected with observation j (0: the prediction);
    ``phase_of(a, b)``: the phase after left ← a, right ← b (seed000 eq. (3)–(5)).
    One object serves a whole run: :meth:`reset` starts each scan.
    """

    __slots__ = ("correct", "identify", "prior", "obs", "cache", "pcache")

    def __init__(self, correct, identify):
        self.correct, self.identify = correct, identify
        self.cache: tuple[dict, dict] = ({}, {})
        self.pcache: dict = {}

    def reset(self, prior, obs) -> None:
        """Start a scan: the pair of predicted states and the scan's observations."""
        self.prior, self.obs = prior, obs
        c0, c1 = self.cache
        c0.clear()
        c1.clear()
        c0[0], c1[0] = prior
        self.pcache.clear()

    def corrected(self, f: int, j: int):
        c = self.cache[f]
        s = c.get(j)
        if s is None:
            o = self.obs[j - 1]
            s = c[j] = self.correct(self.prior[f], o[0], o[1])   # seed000 eq. (14)–(16)
        return s

    def phase_of(self, a: int, b: int) -> int:
        ph = self.pcache.get((a, b))
        if ph is None:
            # corrected(0, a), corrected(1, b) written out: this runs several times a scan
            c0, c1 = self.cache
            sl = c0.get(a)
            if sl is None:
                o = self.obs[a - 1]
                sl = c0[a] = self.correct(self.prior[0], o[0], o[1])  # seed000 eq. (14)–(16)
            sr = c1.get(b)
            if sr is None:
                o = self.obs[b - 1]
                sr = c1[b] = self.correct(self.prior[1], o[0], o[1])
            ph = self.pcache[(a, b)] = self.identify(sl, sr)       # seed000 eq. (3)–(5)
        return ph

    def outcome(self, a: int, b: int):
        """``(left state, right state, phase)`` after left ← a, right ← b."""
        ph = self.phase_of(a, b)
        return self.cache[0][a], self.cache[1][b], ph


def ranked_associations(cand_l, cand_r, d_max: float) -> list[tuple[float, int, int]]:
    """All joint associations as ``(c_{a,b}, a, b)``, cheapest first (seed000 eq. (9)–(10)).
    """
    out = [(d_max + d_max, 0, 0)]
    add = out.append
    for b, db in cand_r:
        add((d_max + db, 0, b))                         # seed000 eq. (9), a = 0
    for a, da in cand_l:
        add((da + d_max, a, 0))
        for b, db in cand_r:
            if b != a:
                add((da + db, a, b))                    # seed000 eq. (9)
    # ties in c: a, then b, ascending -- the enumeration order, since the candidates come
    # in ascending j; plain tuple order does that without a Python key function
    out.sort()
    return out


@declared
@dataclass(eq=False)
class GNNAssociator(Associator):
    """Global nearest neighbour: least total cost (seed 000 Method 1, seed 001)."""

    uses_phase = False

    def select(self, cand_l, cand_r, prev_phase, phase_of):
        a, b = self.obvious(cand_l, cand_r)
        if a >= 0:
            return a, b
        cand_l, cand_r = self.distances(cand_l), self.distances(cand_r)
        _, a, b = ranked_associations(cand_l, cand_r, self.d_max)[0]
        return a, b


@declared
@dataclass(eq=False)
class GaitPhaseAssociator(Associator):
    """Least-cost association with a likely gait-phase change (seed 000 §5.2)."""

    def select(self, cand_l, cand_r, prev_phase, phase_of):
        unlikely = UNLIKELY_TRANSITIONS.get(prev_phase, _NO_PHASES)
        a, b = self.obvious(cand_l, cand_r)
        if a >= 0 and phase_of(a, b) not in unlikely:
            return a, b                      # the cheapest association is likely: done
        cand_l, cand_r = self.distances(cand_l), self.distances(cand_r)
        ranked = ranked_associations(cand_l, cand_r, self.d_max)
        for _, a, b in ranked:
            if phase_of(a, b) not in unlikely:
                return a, b
        return ranked[0][1], ranked[0][2]


@declared
@dataclass(eq=False)
class AssignmentGNN(Associator):
    """Seed 001's GNN: the assignment problem on the 2 × J cost matrix D (eq. (6)–(8)).

    d_{f,j} = λ²_{f,j} (``cost="mahalanobis2"``, seed001 eq. (8): "squared, no root")
    inside leg f's validation region and ∞ outside it (seed001 eq. (7)); "the data
    association is achieved so that the summed total distance of D can be minimized".  An
    assignment of D pairs each leg with a different observation; an ∞ entry cannot be
    taken, and a leg left without a finite entry gets none (UO, §2.4.3).  So "no
    observation" has no price of its own: among the feasible associations gaitval takes
    one with the most legs associated, and among those the least total cost — the
    rectangular assignment problem with infeasible (∞) cells.  (The ``gnn`` associator
    instead prices "none" at a finite d_max, so a leg may be left unassociated when its
    only candidate is expensive; with λ² costs that would need a d_max on the λ² scale
    that the paper does not give.)  Ties keep enumeration order (a, then b, ascending).
    """

    uses_phase = False
    d_max: float = dataclasses.field(default=math.inf, init=False)   # "none" has no price
    cost: str = param("mahalanobis2", "-", "seed001 eq. (8) (\"squared, no root\")",
                      "mahalanobis2 (d = λ²) or mahalanobis (d = λ)")

    def select(self, cand_l, cand_r, prev_phase, phase_of):
        if len(cand_l) <= 1 and len(cand_r) <= 1:
            a = cand_l[0][0] if cand_l else 0
            b = cand_r[0][0] if cand_r else 0
            if not (a and a == b):
                return a, b                               # nothing to resolve
        cand_l, cand_r = self.distances(cand_l), self.distances(cand_r)
        best = (0, 0.0, 0, 0)                             # (−assigned, cost, a, b)
        for a, da in [(0, 0.0)] + cand_l:
            for b, db in [(0, 0.0)] + cand_r:
                if a and a == b:
                    continue
                key = (-(a > 0) - (b > 0), da + db, a, b)  # seed001 eq. (6): min Σ d
                if key < best:
                    best = key
        return best[2], best[3]
