"""Published values of Chalvatzaki et al. 2017 (Chalvatzaki et al., ICRA 2017), transcribed from the seed text.

Transcribed from the paper's text (and checked against a checklist of it).  Units as
printed: cm and cm/s.

Table I, Scenario 1 is legible.  The PF-MAD column prints several values with one decimal
where two are expected (``ONE_DECIMAL``: compare them at ±0.1).  Table I, Scenario 2 is
garbled in the extraction (the rows are repeated, the columns interleaved); the values here
are the checklist's reconstruction (``RECONSTRUCTED``), with the two readings of subject 1's
y noted (``ALTERNATIVE``), subject 1's v_y KF-MAD 23.09 > its RMSE 16.05 flagged as
inconsistent (a mean absolute error cannot exceed the RMSE), and subject 4's v_y row
illegible (NaN).  Nothing is guessed beyond that reconstruction.

Table II is legible.  Inconsistencies are flagged, not fixed: Scenario 1 subject 2 gives
384 KF error frames = 10.5 % but 107 PF error frames = 2.3 % (different totals), and KF
re-initialisations can exceed its error frames (subject 3: 1473 > 1049).

The paper's axes: x lateral, y forward (the direction of travel); see
:mod:`gaitval.tables.rollator`.
"""
from __future__ import annotations

NAN = float("nan")
PARAMETERS = ("x", "y", "vx", "vy")
SCENARIOS = {1: "straight", 2: "obstacle"}

#: Table I: (scenario, subject) -> parameter -> (KF RMSE, PF RMSE, KF MAD, PF MAD), cm(/s)
TABLE_I = {
    (1, 1): {"x": (9.73, 2.65, 5.63, 1.72), "y": (16.36, 4.32, 10.87, 2.4),
             "vx": (10.44, 6.91, 6.81, 4.6), "vy": (31.98, 15.93, 21.59, 11.2)},
    (1, 2): {"x": (2.62, 2.35, 1.17, 0.8), "y": (4.58, 3.82, 3.07, 1.2),
             "vx": (5.28, 4.54, 3.88, 3.4), "vy": (16.09, 12.57, 12.25, 9.3)},
    (1, 3): {"x": (9.36, 4.57, 6.15, 2.84), "y": (8.73, 6.20, 5.13, 3.5),
             "vx": (4.53, 4.20, 3.37, 2.9), "vy": (10.89, 7.06, 7.95, 5.0)},
    (1, 4): {"x": (6.19, 4.40, 4.85, 2.9), "y": (9.52, 6.78, 8.41, 4.3),
             "vx": (11.34, 9.86, 8.03, 7.6), "vy": (28.41, 20.22, 20.83, 15.3)},
    (2, 1): {"x": (8.14, 2.83, 7.35, 1.5), "y": (10.29, 4.10, 7.53, 1.94),
             "vx": (10.21, 7.00, 7.65, 4.6), "vy": (16.05, 13.30, 23.09, 9.64)},
    (2, 2): {"x": (3.88, 3.59, 2.46, 1.9), "y": (6.55, 5.21, 4.13, 3.24),
             "vx": (6.94, 6.52, 4.93, 4.8), "vy": (18.09, 11.23, 13.33, 8.4)},
    (2, 3): {"x": (2.55, 2.50, 2.17, 1.2), "y": (4.48, 4.96, 3.76, 1.7),
             "vx": (6.61, 6.47, 5.11, 4.9), "vy": (14.33, 13.14, 10.97, 10.1)},
    (2, 4): {"x": (3.89, 3.58, 2.72, 1.72), "y": (7.72, 5.58, 5.08, 1.9),
             "vx": (10.85, 9.06, 7.70, 6.8), "vy": (NAN, NAN, NAN, NAN)},
}

#: Table I cells whose PF-MAD is printed with one decimal (compare at ±0.1)
ONE_DECIMAL = {(1, 1): ("y", "vx", "vy"), (1, 2): ("x", "y", "vx", "vy"),
               (1, 3): ("y", "vx", "vy"), (1, 4): ("x", "y", "vx", "vy"),
               (2, 1): ("x", "vx"), (2, 2): ("x", "vx", "vy"),
               (2, 3): ("x", "y", "vx", "vy"), (2, 4): ("y", "vx")}
#: Table I, Scenario 2 is the checklist's reconstruction of a garbled extraction
RECONSTRUCTED = {2}
#: other readings of garbled cells
ALTERNATIVE = {(2, 1, "y"): "KF RMSE 10.20, PF RMSE 4.16 in another reading"}
#: cells that contradict themselves as printed
INCONSISTENT = {(2, 1, "vy"): "KF MAD 23.09 > KF RMSE 16.05"}
#: cells that cannot be read at all
ILLEGIBLE = {(2, 4, "vy")}

#: Table II: (scenario, subject) -> (time KF s, time PF s, errors KF, errors PF,
#: % KF, % PF, KF re-initialisations)
TABLE_II = {
    (1, 1): (45.79, 56.16, 384, 0, 18.5, 0.0, 313),
    (1, 2): (113.56, 124.04, 384, 107, 10.5, 2.3, 288),
    (1, 3): (65.93, 94.26, 1049, 0, 30.1, 0.0, 1473),
    (1, 4): (44.12, 51.46, 272, 0, 14.3, 0.0, 95),
    (2, 1): (86.21, 142.78, 2095, 0, 39.6, 0.0, 1930),
    (2, 2): (88.34, 101.44, 445, 0, 11.8, 0.0, 72),
    (2, 3): (69.49, 69.49, 0, 0, 0.0, 0.0, 0),
    (2, 4): (84.81, 85.91, 41, 0, 1.3, 0.0, 27),
}
TABLE_II_FLAGS = {(1, 2): "384 KF frames = 10.5 % but 107 PF frames = 2.3 %: different totals",
                  (1, 3): "re-initialisations (1473) exceed the error frames (1049)"}

#: the paper's text (§IV.C.1): average error reduction of the PF over the KF
IMPROVEMENT_PCT = {"rmse": 30.0, "mad": 43.0}
