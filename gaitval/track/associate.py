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

import math
from typing import Callable

from gaitval.errors import ConfigError
from gaitval.gait.phases import UNLIKELY_TRANSITIONS
from gaitval.registry import Registry

ASSOCIATORS = Registry("associator")

D_MAX_DEFAULT = math.sqrt(13.82)
_NO_PHASES: frozenset = frozenset()


_COSTS = ("mahalanobis", "mahalanobis2")


class Associator:
    """Role base.

    Parameters
    ----------
    d_max : float
        Cost of leaving a leg without an observation (seed000 eq. (9)–(10)).
    cost : {"mahalanobis", "mahalanobis2"}
        d = λ (seed 000) or d = λ² (seed 001).
    """

    #: ``select`` calls ``phase_of`` (False: the tracker may pass None and skip its cache)
    uses_phase = True

    def __init__(self, d_max: float = D_MAX_DEFAULT, cost: str = "mahalanobis"):
        if cost not in _COSTS:
            raise ConfigError(f"unknown association cost {cost!r}",
                              hint=f"choose one of: {', '.join(_COSTS)}")
        self.d_max = d_max
        self.cost = cost

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


@ASSOCIATORS.register("gnn")
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


@ASSOCIATORS.register("gait_phase")
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


@ASSOCIATORS.register("gnn_assignment")
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

    Parameters
    ----------
    cost : {"mahalanobis2", "mahalanobis"}
        d = λ² (seed 001, default) or λ.
    """

    uses_phase = False

    def __init__(self, cost: str = "mahalanobis2"):
        super().__init__(d_max=math.inf, cost=cost)

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
