"""2-D laser range sensor model: vectorised ray casting, noise, mixed pixels, dropouts.

Every beam is cast at sensor height against every object of the scene (ellipses for
shanks, circles for chair legs, poles, the turn marker, the stick, rollator tubes; line
segments for walls).  Occlusion follows from the geometry only: a beam returns the first
surface it meets.

Each beam has a finite footprint; it is modelled by ``n_sub`` sub-rays spread over one
angular increment.  When the sub-rays of a beam hit surfaces at different depths (a leg
edge in front of a wall), the sensor reports their mean: a **mixed pixel** lying between
foreground and background (the "disturbed distance data" of seed 000 §5.2).  Then
Gaussian range noise, 1 mm quantisation, random dropouts and the valid range are applied.

References
----------
Hokuyo Automatic Co. Scanning laser range finder UTM-30LX/LN specification (accuracy
0.1–10 m: ±30 mm, repeatability σ < 10 mm, 0.25°, 270°, 25 ms/scan).
Hokuyo Automatic Co. UBG-04LX-F01 specification (240°, 0.36°, 28 ms/scan, 20–5600 mm,
accuracy ±10 mm to 1 m, ±1 % beyond).
Tang P, Huber D, Akinci B. A comparative analysis of depth-discontinuity and mixed-pixel
detection algorithms. 3DIM 2007 (mixed pixels at depth discontinuities).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NO_HIT = -1


@dataclass(frozen=True)
class LaserSpec:
    """A scanner's geometry and error model (SI units)."""

    model: str
    angle_min: float
    angle_increment: float
    n_beams: int
    scan_period_s: float
    range_min: float
    range_max: float
    sigma_m: float              # range noise standard deviation (absolute part)
    sigma_rel: float            # relative part (fraction of range)
    dropout_prob: float         # random loss of a return per beam
    n_sub: int = 3              # sub-rays across the beam footprint
    mixed_jump_m: float = 0.03  # sub-ray depth spread that makes a mixed pixel

    @property
    def angles(self) -> np.ndarray:
        return self.angle_min + self.angle_increment * np.arange(self.n_beams)

    def sub_angles(self) -> np.ndarray:
        """(n_beams * n_sub,) sub-ray angles, beam-major."""
        off = (np.arange(self.n_sub) - (self.n_sub - 1) / 2) * (self.angle_increment / self.n_sub)
        return (self.angles[:, None] + off[None, :]).ravel()


def utm30lx(**kw) -> LaserSpec:
    """Hokuyo UTM-30LX: 270°, 0.25°, 1081 beams, 40 Hz, 0.1–30 m, σ 10 mm (repeatability)."""
    inc = np.deg2rad(0.25)
    return LaserSpec(model="Hokuyo UTM-30LX", angle_min=-540 * inc, angle_increment=inc,
                     n_beams=1081, scan_period_s=0.025, range_min=0.1, range_max=30.0,
                     sigma_m=0.010, sigma_rel=0.0, dropout_prob=kw.get("dropout_prob", 0.002))


def ubg04lx(**kw) -> LaserSpec:
    """Hokuyo UBG-04LX-F01: 240°, 360°/1024 ≈ 0.352°, 683 beams, 28 ms, 0.02–5.6 m.

    Accuracy ±10 mm up to 1 m and ±1 % beyond, taken as 2σ: σ = max(5 mm, 0.5 % r).
    """
    inc = 2 * np.pi / 1024
    return LaserSpec(model="Hokuyo UBG-04LX-F01", angle_min=-341 * inc, angle_increment=inc,
                     n_beams=683, scan_period_s=0.028, range_min=0.02, range_max=5.6,
                     sigma_m=0.005, sigma_rel=0.005, dropout_prob=kw.get("dropout_prob", 0.002))


SENSORS = {"utm30lx": utm30lx, "ubg04lx": ubg04lx}


def ray_ellipses(ang: np.ndarray, cx, cy, a, b, psi) -> np.ndarray:
    """Range along rays ``ang`` (from the origin) to ellipses; inf where missed.

    All inputs broadcast together.  The ellipse has semi-axis ``a`` along direction
    ``psi`` and ``b`` across it.  Solves ``|o' + r d'|² = 1`` in the frame where the
    ellipse is the unit circle (``o' = -c`` and ``d = (cos ang, sin ang)`` scaled by the
    axes) and keeps the nearer positive root.
    """
    c, s = np.cos(psi), np.sin(psi)
    dx, dy = np.cos(ang), np.sin(ang)
    du = (dx * c + dy * s) / a
    dv = (-dx * s + dy * c) / b
    ou = (-cx * c - cy * s) / a
    ov = (cx * s - cy * c) / b
    A = du * du + dv * dv
    B = 2 * (ou * du + ov * dv)
    Cc = ou * ou + ov * ov - 1
    disc = B * B - 4 * A * Cc
    with np.errstate(invalid="ignore"):
        sq = np.sqrt(disc)
        r = (-B - sq) / (2 * A)
    ok = (disc >= 0) & (r > 0) & (Cc > 0)
    return np.where(ok, r, np.inf)


def ray_segments(ang: np.ndarray, x0, y0, x1, y1) -> np.ndarray:
    """Range along rays ``ang`` (from the origin) to line segments; inf where missed."""
    dx, dy = np.cos(ang), np.sin(ang)
    ex, ey = x1 - x0, y1 - y0
    den = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (x0 * ey - y0 * ex) / den
        u = (x0 * dy - y0 * dx) / den
    ok = (np.abs(den) > 1e-12) & (r > 0) & (u >= 0) & (u <= 1)
    return np.where(ok, r, np.inf)


@dataclass
class Scene:
    """Objects in the **sensor frame**, per scan.

    ``ell`` : ndarray (n_scans, n_obj, 5) ``cx, cy, a, b, psi`` (NaN rows = absent);
    ``ell_id`` : (n_obj,) int object ids (0 = left leg, 1 = right leg, others ≥ 2);
    ``seg`` : (n_scans or 1, n_seg, 4) ``x0, y0, x1, y1`` walls; ``seg_id`` : (n_seg,).
    """

    ell: np.ndarray
    ell_id: np.ndarray
    seg: np.ndarray
    seg_id: np.ndarray


def cast(scene: Scene, spec: LaserSpec, static_ranges: tuple[np.ndarray, np.ndarray] | None = None
         ) -> tuple[np.ndarray, np.ndarray]:
    """True sub-ray ranges and hit ids for every scan.

    Parameters
    ----------
    scene : Scene
    spec : LaserSpec
    static_ranges : (ranges, ids), optional
        Precomputed (n_rays,) background of a fixed sensor (walls, poles, chair, ...),
        used for every scan instead of ``scene.seg``.

    Returns
    -------
    ranges : ndarray (n_scans, n_beams * n_sub), inf = nothing hit
    ids : ndarray int16 (n_scans, n_beams * n_sub), ``NO_HIT`` = nothing hit

    Notes
    -----
    Ellipses are culled per scan by their angular extent: only the sub-rays inside
    ``atan2(cy, cx) ± asin(R / ρ)`` (R the larger semi-axis) are intersected, so the cost
    grows with the number of beams that can hit an object, not beams × objects.
    """
    ang = spec.sub_angles()
    n_rays = ang.size
    ns, no, _ = scene.ell.shape
    if static_ranges is not None:
        rng0, id0 = static_ranges
        R = np.broadcast_to(rng0, (ns, n_rays)).copy()
        I = np.broadcast_to(id0, (ns, n_rays)).astype(np.int16).copy()
    else:
        R = np.full((ns, n_rays), np.inf)
        I = np.full((ns, n_rays), NO_HIT, dtype=np.int16)
        if scene.seg.shape[1]:
            seg = np.broadcast_to(scene.seg, (ns,) + scene.seg.shape[1:])
            for k in range(seg.shape[1]):
                r = ray_segments(ang[None, :], seg[:, k, 0:1], seg[:, k, 1:2],
                                 seg[:, k, 2:3], seg[:, k, 3:4])
                closer = r < R
                R = np.where(closer, r, R)
                I = np.where(closer, np.int16(scene.seg_id[k]), I)
    if no == 0:
        return R, I
    e = scene.ell.reshape(ns * no, 5)
    ok = np.all(np.isfinite(e), axis=1)
    cx, cy, a, b, psi = e.T
    rho = np.hypot(cx, cy)
    rad = np.maximum(a, b)
    inside = rho <= rad
    half = np.where(inside, np.pi, np.arcsin(np.clip(rad / np.maximum(rho, 1e-9), 0, 1)))
    phic = np.where(ok, np.arctan2(cy, cx), 0.0)
    half = np.where(ok, half, 0.0)
    step = spec.angle_increment / spec.n_sub
    a0 = ang[0]
    lo = np.ceil((phic - half - a0) / step).astype(np.int64)
    hi = np.floor((phic + half - a0) / step).astype(np.int64)
    lo = np.clip(lo, 0, n_rays)
    hi = np.clip(hi, -1, n_rays - 1)
    cnt = np.where(ok & ~inside, np.maximum(hi - lo + 1, 0), 0)
    tot = int(cnt.sum())
    if tot == 0:
        return R, I
    obj = np.repeat(np.arange(ns * no), cnt)
    start = np.repeat(np.cumsum(cnt) - cnt, cnt)
    ray = lo[obj] + (np.arange(tot) - start)
    r = ray_ellipses(ang[ray], cx[obj], cy[obj], a[obj], b[obj], psi[obj])
    scan = obj // no
    flat = scan * n_rays + ray
    Rf = R.ravel()
    If = I.ravel()
    hit = r < Rf[flat]
    flat, r, objh = flat[hit], r[hit], obj[hit]
    # nearest object per ray: sort by (ray, range) and keep the first of each ray
    order = np.lexsort((r, flat))
    flat, r, objh = flat[order], r[order], objh[order]
    first = np.ones(flat.size, dtype=bool)
    first[1:] = flat[1:] != flat[:-1]
    Rf[flat[first]] = r[first]
    If[flat[first]] = scene.ell_id[objh[first] % no]
    return Rf.reshape(ns, n_rays), If.reshape(ns, n_rays)


def measure(R: np.ndarray, I: np.ndarray, spec: LaserSpec, rng: np.random.Generator
            ) -> dict[str, np.ndarray]:
    """Turn true sub-ray ranges into what the sensor reports.

    Returns
    -------
    dict with
        ``ranges`` (n_scans, n_beams) metres, quantised to 1 mm, NaN = no return;
        ``true`` (n_scans, n_beams) the central sub-ray's true range (inf = no surface);
        ``id`` (n_scans, n_beams) object hit by the central sub-ray;
        ``mixed`` (n_scans, n_beams) bool, the beam's footprint straddled a depth jump;
        ``dropout`` (n_scans, n_beams) bool, a surface was there but nothing returned.

    Notes
    -----
    Mixed pixel: ``r = mean(r_sub)`` when the sub-rays hit *different* surfaces whose
    depths differ by more than ``mixed_jump_m`` (a smooth wall seen obliquely is not a
    depth discontinuity); a beam whose footprint is less than half on a surface returns
    nothing.  Noise ``σ = sigma_m + sigma_rel·r``; quantisation
    ``r_q = round(r / 1 mm) · 1 mm``.
    """
    ns = R.shape[0]
    nb, k = spec.n_beams, spec.n_sub
    c = k // 2
    Rs = R.reshape(ns, nb, k)
    Is = I.reshape(ns, nb, k)
    centre = Rs[:, :, c]
    cid = Is[:, :, c]
    # only beams whose sub-rays disagree on the surface need the footprint model
    differ = np.zeros((ns, nb), dtype=bool)
    for j in range(k):
        if j != c:
            differ |= Is[:, :, j] != cid
    true = centre.copy()
    mixed = np.zeros((ns, nb), dtype=bool)
    idx = np.nonzero(differ)
    if idx[0].size:
        sub = Rs[idx]                                        # (m, k)
        fin = np.isfinite(sub)
        nfin = fin.sum(axis=1)
        mean = np.where(fin, sub, 0.0).sum(axis=1) / np.maximum(nfin, 1)
        spread = np.where(fin, sub, -np.inf).max(axis=1) - np.where(fin, sub, np.inf).min(axis=1)
        majority = nfin * 2 > k
        mix = majority & fin.all(axis=1) & (spread > spec.mixed_jump_m)
        # partly on a surface: the majority's mean (the centre ray may have missed)
        val = np.where(mix, mean, np.where(np.isfinite(sub[:, c]), sub[:, c], mean))
        true[idx] = np.where(majority, val, np.inf)
        mixed[idx] = mix
    sigma = spec.sigma_m + spec.sigma_rel * np.where(np.isfinite(true), true, 0.0)
    noisy = true + sigma * rng.standard_normal(true.shape)
    drop = np.isfinite(true) & (rng.random(true.shape) < spec.dropout_prob)
    out = np.where(drop | ~np.isfinite(noisy), np.nan, np.rint(noisy * 1000.0) / 1000.0)
    with np.errstate(invalid="ignore"):
        out = np.where((out < spec.range_min) | (out > spec.range_max), np.nan, out)
    return {"ranges": out, "true": centre, "id": Is[:, :, k // 2], "mixed": mixed,
            "dropout": drop}
