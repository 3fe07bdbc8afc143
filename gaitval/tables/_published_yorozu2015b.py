"""Published values of Yorozu et al. 2015b (Yorozu et al., Sensors 2015, 15, 11151–11168), Tables 1, 3, 4.

Transcribed from the paper's text (checked against that text by
``tests/test_mtst_tables.py``).  The text's Table 3 is garbled in one cell: Method 3's
success is printed "64.6% (31/44)"; 31/44 would be 70.5 %, and 48 − (14 + 0 + 1 + 2) = 31
with 31/48 = 64.6 %, so the denominator is 48 (as a checklist of the paper reads it).  gaitval shows the printed text and uses 31/48.
"""
from __future__ import annotations

#: Table 1: the radius of the validation region r_val (phase at k−1 × observability)
TABLE1 = {
    ("stance", "observable"): "3/4 w_l + dt |v_k-1|",
    ("stance", "unobservable"): "3/4 w_l + dt H v_st",
    ("swing", "observable"): "w_l + dt |v_k-1|",
    ("swing", "unobservable"): "w_l + dt |v_k-1| + dt H v_sw",
}
V_SW_MPS, V_ST_MPS = 1.1, 0.55

#: Table 3 groups: trials without / with a stick
N_TRIALS = {"no_stick": 42, "stick": 6, "total": 48}

#: Table 3: method -> (lost no stick, false no stick, lost stick, false stick, successes,
#: printed success text)
TABLE3 = {
    "mtst_m1": (6, 5, 3, 0, 34, "70.8% (34/48)"),
    "mtst_m2": (1, 1, 0, 2, 44, "91.7% (44/48)"),
    "mtst_m3": (14, 0, 1, 2, 31, "64.6% (31/44) [sic; 31/48]"),
    "mtst_proposed": (0, 0, 0, 2, 46, "95.8% (46/48)"),
}
TABLE3_DEFINITIONS = {
    "mtst_m1": ("no", "1.5 w_l"), "mtst_m2": ("yes", "1.5 w_l"),
    "mtst_m3": ("yes", "w_l"), "mtst_proposed": ("yes", "variable (Table 1)"),
}

#: Table 4 (46 trials the proposed method tracked): steps and cross steps per group
STEPS = {"no_stick": 381, "stick": 33, "total": 414}
CROSS = {"no_stick": 16, "stick": 3, "total": 19}
#: row -> (non no stick, mis/false no stick, non stick, mis/false stick, success text,
#: mis/false rate text)
TABLE4 = {
    "target_step": (4, 3, 0, 3, "99.0% (410/414)", "1.4% (6/414)"),
    "cross_step": (2, 0, 2, 0, "78.9% (15/19)", "0.0% (0/15)"),
}
CROSS_PER_100 = 100.0 * 19 / 414          # 4.6 (no stick 4.2, stick 9.1)
