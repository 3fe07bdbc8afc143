"""What every paper's verdicts share (:mod:`gaitval.report.verdicts`): one verdict row,
the Wilson interval of a proportion, the ranking of methods and its broken pairs, and the
criteria's thresholds."""
from __future__ import annotations

import math

import numpy as np

SHORT = {"tug_m1": "M1", "tug_m2": "M2", "tug_m3": "M3", "mtst_m1": "M1", "mtst_m2": "M2",
         "mtst_m3": "M3", "mtst_proposed": "proposed"}
#: A 95 % interval wider than this (as a proportion) is too wide to test a published
#: value with: the comparison is "not comparable: too small".
MAX_CI_WIDTH = 0.5
#: Fewer tracking-success trials than this: an RMSE compares single walks (TUG Tables 4-5).
MIN_SUCCESS_TRIALS = 2
#: Fewer subjects than this: a paired t-test (ultrasonic Table 8) has under 2 degrees of
#: freedom, a "most subject × scenario cells" majority (rollator Table I) is one subject's.
MIN_SUBJECTS_T = 3
MIN_SUBJECTS_CELLS = 2
#: What a table's notes say when its numbers are not comparable with the paper's.
NOT_COMPARABLE_NOTE = {"ultrasonic_table7": "not comparable",
                       "ultrasonic_tableC1": "not consistent with subjects as groups",
                       "ultrasonic_table8": "divide by the number of strides n"}



def wilson(k: float, n: float, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score 95% interval of the proportion ``k/n`` (NaN, NaN when ``n`` is 0)."""
    if not n:
        return (np.nan, np.nan)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (c - h, c + h)


def _row(study, comparison, source, published, reproduced, criterion, ok, why, table,
         not_comparable: str | None = None) -> dict:
    """One verdict; ``ok`` None or ``not_comparable`` set → ``not comparable``."""
    if not_comparable:
        outcome, why = "not comparable", not_comparable
    elif ok is None or (isinstance(ok, float) and math.isnan(ok)):
        outcome = "not comparable"
    else:
        outcome = "reproduced" if bool(ok) else "not reproduced"
    return {"study": study, "data": "", "comparison": comparison, "source": source,
            "published": published, "reproduced": reproduced, "criterion": criterion,
            "outcome": outcome, "why": why, "alternative": "", "table": table}


def _pct(x: float) -> str:
    return f"{100 * x:.1f}%"


def _ci(lo: float, hi: float) -> str:
    return f"95% CI {100 * lo:.1f}–{100 * hi:.1f}%"


def _proportion_verdict(k, n, published_frac):
    """(reproduced text, ok or None, too-small reason or None) of a proportion ``k/n``
    against a published proportion, by the Wilson interval."""
    lo, hi = wilson(k, n)
    if not n:
        return "no trials", None, "too small: no trials to compare"
    text = f"{_pct(k / n)} ({int(k)}/{int(n)}); {_ci(lo, hi)}"
    if hi - lo > MAX_CI_WIDTH:
        return text, None, (f"too small: with {int(n)} trial{'s' * (int(n) != 1)} the 95% "
                            f"CI spans {100 * (hi - lo):.0f} percentage points, too wide "
                            "to test the paper's value")
    return text, lo <= published_frac <= hi, None


def _order(values: dict[str, float], higher_first: bool = True) -> list[str]:
    keys = list(values)
    return sorted(keys, key=lambda m: ((-values[m] if higher_first else values[m]),
                                       keys.index(m)))


def _ranking(values: dict[str, float], fmt, higher_first=True) -> str:
    """``"M3 96.4 % > M2 89.3 % = M1 89.3 %"`` (ties, at the printed precision, as ``=``)."""
    order = _order(values, higher_first)
    out = ""
    for i, m in enumerate(order):
        if i:
            tie = fmt(values[m]) == fmt(values[order[i - 1]])
            out += " = " if tie else (" > " if higher_first else " < ")
        out += f"{SHORT.get(m, m)} {fmt(values[m])}"
    return out


def _same_ranking(pub: dict[str, float], rep: dict[str, float]) -> bool:
    """Every pair the paper ranks strictly is ranked the same way, strictly."""
    ms = [m for m in pub if m in rep]
    return all(np.sign(pub[a] - pub[b]) == np.sign(rep[a] - rep[b])
               for i, a in enumerate(ms) for b in ms[i + 1:] if pub[a] != pub[b])


def _broken_pairs(pub: dict[str, float], rep: dict[str, float], fmt) -> str:
    ms = [m for m in pub if m in rep]
    bad = [(a, b) for i, a in enumerate(ms) for b in ms[i + 1:] if pub[a] != pub[b]
           and np.sign(pub[a] - pub[b]) != np.sign(rep[a] - rep[b])]
    out = []
    for a, b in bad:
        hi, lo = (a, b) if pub[a] > pub[b] else (b, a)
        out.append(f"{SHORT.get(hi, hi)} {fmt(rep[hi])} is not above "
                   f"{SHORT.get(lo, lo)} {fmt(rep[lo])}")
    return "; ".join(out)
