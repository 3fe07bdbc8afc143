"""The UKF's per-sample arithmetic, compiled with numba (seed 003 §3.2, eq. 5–13).

Imported only by :func:`gaitval.track.ukf.run_toa_ukf` (lazily), so that no other job pays
numba's import.  :func:`ukf_steps` runs the filter's predict–update–reflect cycle over a
stretch of samples and stops where the filter must be (re-)initialised by trilateration,
which stays in Python (:func:`gaitval.track.ukf.trilaterate`: a few hundred calls in a
study against ~700,000 updates).  The kernel is ``@njit(cache=True)`` without
``fastmath`` (IEEE arithmetic, no reassociation, no fused multiply-adds), its machine code
cached beside this file (``__pycache__`` or ``NUMBA_CACHE_DIR``).

**Same numbers as the numpy formulation, bit for bit.**  ``alpha = 1e-3`` gives
``W_0 ≈ -10^6`` (eq. 12), which amplifies round-off, so a track's last digits depend on
the order of every sum.  The kernel therefore performs the numpy formulation's operations
(:func:`gaitval.track.ukf.run_toa_ukf` before the kernel, gaitval ≤ 055770d; kept as
``tests/ukf_numpy_reference.py``) in the same order, and the products and
factorisations in the same library routines with the same arguments: numpy's ``@`` on
these shapes calls its OpenBLAS (``cblas_dgemm``/``dgemv``/``ddot``; the calls were
traced with an ``LD_PRELOAD`` shim and are noted below at each call), and the Cholesky
factor and the SPD solve are scipy's LAPACK (``dpotrf``, ``dposv``).  Their addresses
come from the loaded numpy and scipy (:func:`blas_pointers`) and reach the kernel as
arguments, so the cached machine code holds no address.  OpenBLAS picks its kernels for
the CPU at load time, so the numbers are the numpy formulation's on the machine at hand.
The element-wise steps are written as numpy evaluates them (``sum(axis=…)`` left to right,
``dt ** 4`` as ``pow``).  Where numpy or scipy do not export the scipy-openblas symbols
(another BLAS build), the same routines run as plain loops (``pointers[0] == 0``): equal to
round-off, not bit for bit.

Two cases the numpy formulation left to LAPACK's undefined output are explicit here: a
covariance that stays indefinite after symmetrising and the jitter of eq. (7), or an
innovation covariance ``Pyy`` that is not positive definite, skips the update and marks
the filter lost (it re-initialises at the next sample).  Neither occurred in the default
study (0 of 677,301 updates, counted on 2026-11-27).
"""
from __future__ import annotations

import ctypes
import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

N = 6
#: CBLAS enumerations (cblas.h).
ROW, COL, NOTRANS, TRANS = 101, 102, 111, 112
#: Entries of the pointer table :func:`blas_pointers` returns.
GEMM, GEMV, DOT, POTRF, POSV = range(5)
#: The symbols, in that order, in numpy's (ILP64 CBLAS) and scipy's (LP64 LAPACK)
#: scipy-openblas builds (the PyPI wheels).
NUMPY_SYMBOLS = ("scipy_cblas_dgemm64_", "scipy_cblas_dgemv64_", "scipy_cblas_ddot64_")
SCIPY_SYMBOLS = ("scipy_dpotrf_", "scipy_dposv_")

_I8, _I32, _I64, _DBL = ir.IntType(8), ir.IntType(32), ir.IntType(64), ir.DoubleType()
_DP = _DBL.as_pointer()


def blas_pointers() -> np.ndarray:
    """Addresses of numpy's CBLAS ``dgemm``, ``dgemv``, ``ddot`` and scipy's LAPACK
    ``dpotrf``, ``dposv`` (int64, in :data:`GEMM` … :data:`POSV` order), looked up in the
    libraries numpy's and scipy's extension modules are linked to; all zero when one is
    missing (then the kernel runs its loops)."""
    out = np.zeros(5, dtype=np.int64)
    try:
        try:
            from numpy._core import _multiarray_umath as npcore
        except ImportError:                     # numpy 1.x
            from numpy.core import _multiarray_umath as npcore
        from scipy.linalg import _flapack as flapack

        np_lib, sp_lib = ctypes.CDLL(npcore.__file__), ctypes.CDLL(flapack.__file__)
        syms = [getattr(np_lib, s) for s in NUMPY_SYMBOLS]
        syms += [getattr(sp_lib, s) for s in SCIPY_SYMBOLS]
    except (ImportError, AttributeError, OSError):
        return out
    out[:] = [ctypes.cast(s, ctypes.c_void_p).value for s in syms]
    return out


def _data(context, builder, aryty, val):
    return builder.bitcast(context.make_array(aryty)(context, builder, val).data, _DP)


def _int_slot(builder, val, ty=_I32):
    """A pointer to ``val`` as ``ty`` (Fortran passes scalars by reference); the slot is
    allocated once in the function's entry block, not at each call in a loop."""
    return cgutils.alloca_once_value(
        builder, builder.trunc(val, ty) if val.type.width > ty.width else val)


@intrinsic
def _cblas_dgemm(typingctx, fp, order, ta, tb, M, N_, K, A, lda, B, ldb, C, ldc):
    """``C = op(A) op(B)`` by ``cblas_dgemm`` (alpha 1, beta 0, ILP64) at address ``fp``."""
    sig = types.void(fp, order, ta, tb, M, N_, K, A, lda, B, ldb, C, ldc)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.VoidType(), [_I32, _I32, _I32, _I64, _I64, _I64, _DBL, _DP,
                                               _I64, _DP, _I64, _DBL, _DP, _I64])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        a = signature.args
        builder.call(f, [builder.trunc(args[1], _I32), builder.trunc(args[2], _I32),
                         builder.trunc(args[3], _I32), args[4], args[5], args[6],
                         ir.Constant(_DBL, 1.0), _data(context, builder, a[7], args[7]),
                         args[8], _data(context, builder, a[9], args[9]), args[10],
                         ir.Constant(_DBL, 0.0), _data(context, builder, a[11], args[11]),
                         args[12]])
        return context.get_dummy_value()
    return sig, codegen


@intrinsic
def _cblas_dgemv(typingctx, fp, order, trans, M, N_, A, lda, X, Y):
    """``Y = op(A) X`` by ``cblas_dgemv`` (alpha 1, beta 0, unit strides, ILP64)."""
    sig = types.void(fp, order, trans, M, N_, A, lda, X, Y)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.VoidType(), [_I32, _I32, _I64, _I64, _DBL, _DP, _I64,
                                               _DP, _I64, _DBL, _DP, _I64])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        a, one = signature.args, ir.Constant(_I64, 1)
        builder.call(f, [builder.trunc(args[1], _I32), builder.trunc(args[2], _I32),
                         args[3], args[4], ir.Constant(_DBL, 1.0),
                         _data(context, builder, a[5], args[5]), args[6],
                         _data(context, builder, a[7], args[7]), one,
                         ir.Constant(_DBL, 0.0), _data(context, builder, a[8], args[8]), one])
        return context.get_dummy_value()
    return sig, codegen


@intrinsic
def _cblas_ddot(typingctx, fp, n, X, Y):
    """``X · Y`` by ``cblas_ddot`` (unit strides, ILP64)."""
    sig = types.float64(fp, n, X, Y)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(_DBL, [_I64, _DP, _I64, _DP, _I64])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        a, one = signature.args, ir.Constant(_I64, 1)
        return builder.call(f, [args[1], _data(context, builder, a[2], args[2]), one,
                                _data(context, builder, a[3], args[3]), one])
    return sig, codegen


@intrinsic
def _lapack_dpotrf(typingctx, fp, uplo, n, A, lda):
    """LAPACK ``dpotrf(uplo, n, A, lda, info)`` (LP64); returns ``info``."""
    sig = types.int64(fp, uplo, n, A, lda)

    def codegen(context, builder, signature, args):
        ip = _I32.as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [_I8.as_pointer(), ip, _DP, ip, ip, _I64])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        info = _int_slot(builder, ir.Constant(_I32, 0))
        builder.call(f, [_int_slot(builder, args[1], _I8), _int_slot(builder, args[2]),
                         _data(context, builder, signature.args[3], args[3]),
                         _int_slot(builder, args[4]), info, ir.Constant(_I64, 1)])
        return builder.sext(builder.load(info), _I64)
    return sig, codegen


@intrinsic
def _lapack_dposv(typingctx, fp, uplo, n, nrhs, A, lda, B, ldb):
    """LAPACK ``dposv(uplo, n, nrhs, A, lda, B, ldb, info)`` (LP64); returns ``info``."""
    sig = types.int64(fp, uplo, n, nrhs, A, lda, B, ldb)

    def codegen(context, builder, signature, args):
        ip = _I32.as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [_I8.as_pointer(), ip, ip, _DP, ip, _DP, ip,
                                               ip, _I64])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        a = signature.args
        info = _int_slot(builder, ir.Constant(_I32, 0))
        builder.call(f, [_int_slot(builder, args[1], _I8), _int_slot(builder, args[2]),
                         _int_slot(builder, args[3]), _data(context, builder, a[4], args[4]),
                         _int_slot(builder, args[5]), _data(context, builder, a[6], args[6]),
                         _int_slot(builder, args[7]), info, ir.Constant(_I64, 1)])
        return builder.sext(builder.load(info), _I64)
    return sig, codegen


# --- the same routines as loops (no scipy-openblas symbols); matrices are flat buffers --

@njit(cache=True)
def _at(A, order, trans, ld, i, k):
    """Element ``(i, k)`` of ``op(A)``, ``A`` stored in ``order`` with leading dim ``ld``."""
    r, c = (k, i) if trans == TRANS else (i, k)
    return A[r * ld + c] if order == ROW else A[r + c * ld]


@njit(cache=True)
def gemm(fp, order, ta, tb, M, N_, K, A, lda, B, ldb, C, ldc):
    """``C = op(A) op(B)`` (``M×K`` by ``K×N_``), cblas conventions."""
    if fp[GEMM] != 0:
        _cblas_dgemm(fp[GEMM], order, ta, tb, M, N_, K, A, lda, B, ldb, C, ldc)
        return
    for i in range(M):
        for j in range(N_):
            v = 0.0
            for k in range(K):
                v += _at(A, order, ta, lda, i, k) * _at(B, order, tb, ldb, k, j)
            if order == ROW:
                C[i * ldc + j] = v
            else:
                C[i + j * ldc] = v


@njit(cache=True)
def gemv(fp, order, trans, M, N_, A, lda, X, Y):
    """``Y = op(A) X`` for the ``M×N_`` matrix ``A``, cblas conventions."""
    if fp[GEMV] != 0:
        _cblas_dgemv(fp[GEMV], order, trans, M, N_, A, lda, X, Y)
        return
    rows, cols = (N_, M) if trans == TRANS else (M, N_)
    for i in range(rows):
        v = 0.0
        for k in range(cols):
            v += _at(A, order, trans, lda, i, k) * X[k]
        Y[i] = v


@njit(cache=True)
def dot(fp, n, X, Y):
    """``X[:n] · Y[:n]``."""
    if fp[DOT] != 0:
        return _cblas_ddot(fp[DOT], n, X, Y)
    v = 0.0
    for i in range(n):
        v += X[i] * Y[i]
    return v


@njit(cache=True)
def _cholesky_loops(n, A):
    """Lower Cholesky factor of the column-major ``n×n`` ``A`` in place (its lower
    triangle read and written); LAPACK's ``info``: 0, or ``j + 1`` at a pivot ≤ 0 or NaN."""
    for j in range(n):
        s = A[j + j * n]
        for c in range(j):
            s -= A[j + c * n] * A[j + c * n]
        if not s > 0.0:
            return j + 1
        d = math.sqrt(s)
        A[j + j * n] = d
        for i in range(j + 1, n):
            v = A[i + j * n]
            for c in range(j):
                v -= A[i + c * n] * A[j + c * n]
            A[i + j * n] = v / d
    return 0


@njit(cache=True)
def potrf_lower(fp, n, A):
    """Lower Cholesky factor of the column-major ``n×n`` ``A`` in place (its lower
    triangle read), the upper triangle zeroed (scipy's ``dpotrf(lower=1, clean=1)``);
    True when positive definite."""
    if fp[POTRF] != 0:
        info = _lapack_dpotrf(fp[POTRF], ord("L"), n, A, n)
    else:
        info = _cholesky_loops(n, A)
    for j in range(n):
        for i in range(j):
            A[i + j * n] = 0.0
    return info == 0


@njit(cache=True)
def posv_upper(fp, n, nrhs, A, B):
    """Solve ``A X = B`` for the SPD column-major ``n×n`` ``A`` (upper triangle read) and
    the column-major ``n×nrhs`` ``B``, ``X`` into ``B`` (LAPACK ``dposv('U')``; ``A`` is
    overwritten by a factor); True when ``A`` is positive definite."""
    if fp[POSV] != 0:
        return _lapack_dposv(fp[POSV], ord("U"), n, nrhs, A, n, B, n) == 0
    for j in range(n):                          # the upper triangle mirrored: A = L L^T
        for i in range(j + 1, n):
            A[i + j * n] = A[j + i * n]
    if _cholesky_loops(n, A) != 0:
        return False
    for r in range(nrhs):
        b = r * n
        for i in range(n):                      # L y = b
            v = B[b + i]
            for j in range(i):
                v -= A[i + j * n] * B[b + j]
            B[b + i] = v / A[i + i * n]
        for i in range(n - 1, -1, -1):          # L^T x = y
            v = B[b + i]
            for j in range(i + 1, n):
                v -= A[j + i * n] * B[b + j]
            B[b + i] = v / A[i + i * n]
    return True


@njit(cache=True)
def ukf_steps(k0, force, fp, t, d, n_finite, anchors, S, Wm, Wc, scale, Vm, Q4, Q3, Q2,
              gate2, use_gate, max_reject, min_anchors, reinit_after, normal, centre,
              has_normal, x, P, starved_box, out_x, out_P, used, rejected, reflected):
    """Run the filter from sample ``k0`` (the state ``x``, ``P`` is the a-posteriori one
    of sample ``k0 - 1``) until the filter must be re-initialised or the log ends.

    Returns the index of the first sample that needs a re-initialisation (``starved ≥
    reinit_after`` at its start), or ``len(t)``; ``force``: run sample ``k0`` even if so
    (the caller's trilateration failed there).  ``fp``: :func:`blas_pointers`.  ``S``
    (13×6, flat): ``[0; I; -I]``, the sigma-point pattern of eq. (7); ``P`` (36, flat,
    row-major).  Updates ``x``, ``P``, ``starved_box[0]`` and the output rows ``out_x``,
    ``out_P`` (a-posteriori state and covariance diagonal), ``used``, ``rejected`` and
    ``reflected`` in place.  Per sample (module notes of :mod:`gaitval.track.ukf`):
    predict (eq. 8 closed form), the measurement sigma points and statistics (eq. 7, 9,
    10), the per-anchor gate, the update from the anchors kept (eq. 10–11), the mirror
    reflection.  Buffers are flat with the numpy formulation's memory layout; each BLAS
    call names the numpy expression it stands for.
    """
    n_s = t.shape[0]
    m = anchors.shape[0]
    n_sig = 2 * N + 1
    starved = starved_box[0]
    A = np.zeros(N * N)
    Q = np.zeros(N * N)
    AP = np.empty(N * N)
    Pn = np.empty(N * N)
    B = np.empty(N * N)                        # chol((n + lambda) P), column-major
    xn = np.empty(N)
    dX = np.empty(n_sig * N)
    Ysig = np.empty(n_sig * m)                 # Y, then Y - ybar (dY)
    ybar = np.empty(m)
    WdY = np.empty(n_sig * m)
    Pyy = np.empty(m * m)
    Pxy = np.empty(N * m)
    nu = np.empty(m)
    nus = np.empty(m)
    keep = np.empty(m, dtype=np.int64)
    Ps = np.empty(m * m)                       # Pyy of the anchors kept, column-major
    KT = np.empty(m * N)                       # Pxy^T, then K^T, column-major m×6
    Pxs = np.empty(N * m)                      # Pxy of the anchors kept, row-major 6×ns
    KPxy = np.empty(N * N)
    rel = np.empty(3)
    for i in range(N):
        A[i * N + i] = 1.0
    last_dt = np.nan
    k = k0
    while k < n_s:
        if starved >= reinit_after and not (force and k == k0):
            break
        dt = t[k] - t[k - 1]
        if dt != last_dt:                      # seed003 eq. (5): A = I + dt E, G W G^T
            last_dt = dt
            A[0 * N + 3] = A[1 * N + 4] = A[2 * N + 5] = dt
            c4, c3, c2 = 0.25 * math.pow(dt, 4.0), 0.5 * math.pow(dt, 3.0), dt * dt
            for i in range(N * N):
                Q[i] = c4 * Q4[i] + c3 * Q3[i] + c2 * Q2[i]
        gemv(fp, COL, TRANS, N, N, A, N, x, xn)          # X_{k+1/k} = A X_{k/k}: A @ x
        x[:] = xn
        gemm(fp, ROW, NOTRANS, NOTRANS, N, N, N, A, N, P, N, AP, N)      # A @ P
        gemm(fp, ROW, NOTRANS, TRANS, N, N, N, AP, N, A, N, Pn, N)       # (A P) @ A.T
        for i in range(N * N):                 # A P A^T + G W G^T, seed003 eq. (8)
            P[i] = Pn[i] + Q[i]
        if n_finite[k] == 0:
            starved += 1
        else:
            lost = False
            # B = chol((n + lambda) P), seed003 eq. (7); dpotrf on a column-major copy
            for i in range(N):
                for j in range(N):
                    B[i + j * N] = scale * P[i * N + j]
            if not potrf_lower(fp, N, B):
                for i in range(N):             # P = (P + P^T)/2 + 1e-12 I, then again
                    for j in range(N):
                        Pn[i * N + j] = (0.5 * (P[i * N + j] + P[j * N + i])
                                         + (1e-12 if i == j else 0.0))
                P[:] = Pn
                for i in range(N):
                    for j in range(N):
                        B[i + j * N] = scale * P[i * N + j]
                lost = not potrf_lower(fp, N, B)
            if not lost:
                # chi_i - X = S B^T (seed003 eq. 7): S @ B.T, B.T row-major = B's buffer
                gemm(fp, ROW, NOTRANS, NOTRANS, n_sig, N, N, S, N, B, N, dX, N)
                for i in range(n_sig):         # Y_i = h(chi_i), seed003 eq. (6)
                    for a in range(m):
                        s = 0.0
                        for c in range(3):
                            e = (x[c] + dX[i * N + c]) - anchors[a, c]
                            s = e * e if c == 0 else s + e * e
                        Ysig[i * m + a] = math.sqrt(s)
                gemv(fp, ROW, TRANS, n_sig, m, Ysig, m, Wm, ybar)  # seed003 eq. (9)
                for i in range(n_sig):
                    for a in range(m):
                        Ysig[i * m + a] -= ybar[a]                    # dY
                        WdY[i * m + a] = Wc[i] * Ysig[i * m + a]
                # seed003 eq. (10): dY.T @ WdY + V, dX.T @ WdY
                gemm(fp, ROW, TRANS, NOTRANS, m, m, n_sig, Ysig, m, WdY, m, Pyy, m)
                for i in range(m * m):
                    Pyy[i] += Vm[i]
                gemm(fp, ROW, TRANS, NOTRANS, N, m, n_sig, dX, N, WdY, m, Pxy, m)
                for a in range(m):
                    nu[a] = d[k, a] - ybar[a]
                # the per-anchor gate (multipath, module notes of gaitval.track.ukf)
                n_ok = n_finite[k]
                mismatch = False
                if use_gate:
                    over = False
                    for a in range(m):
                        if nu[a] * nu[a] > gate2 * Pyy[a * m + a]:
                            over = True
                    if over:
                        n_bad = 0
                        for a in range(m):
                            z = abs(nu[a]) / math.sqrt(Pyy[a * m + a]) if used[k, a] else 0.0
                            if z * z > gate2:
                                keep[n_bad] = a
                                n_bad += 1
                        if n_bad <= max_reject:
                            for b in range(n_bad):
                                rejected[k, keep[b]] = True
                                used[k, keep[b]] = False
                            n_ok -= n_bad
                        else:
                            mismatch = True
                if n_ok > 0:                   # K = Pxy Pyy^-1, seed003 eq. (10)
                    ns = 0
                    for a in range(m):
                        if used[k, a]:
                            keep[ns] = a
                            ns += 1
                    # dposv(Pyy_s, Pxy_s.T): Pxy_s.T column-major is Pxy_s's buffer
                    for a in range(ns):
                        nus[a] = nu[keep[a]]
                        for b in range(ns):
                            Ps[a + b * ns] = Pyy[keep[a] * m + keep[b]]
                        for c in range(N):
                            KT[c * ns + a] = Pxy[c * m + keep[a]]
                    if posv_upper(fp, ns, N, Ps, KT):
                        gemv(fp, COL, TRANS, ns, N, KT, ns, nus, xn)   # nu_s @ KT
                        for c in range(N):     # X += K (d - Y), seed003 eq. (11)
                            x[c] = x[c] + xn[c]
                        for a in range(ns):
                            for c in range(N):
                                Pxs[c * ns + a] = Pxy[c * m + keep[a]]
                        # P -= K Pyy K^T = KT.T @ Pxy_s.T, seed003 eq. (11)
                        gemm(fp, ROW, NOTRANS, TRANS, N, N, ns, KT, ns, Pxs, ns, KPxy, N)
                        for i in range(N * N):
                            P[i] = P[i] - KPxy[i]
                    else:
                        lost = True
                for i in range(N):             # P = (P + P^T) / 2
                    for j in range(i, N):
                        v = (P[i * N + j] + P[j * N + i]) * 0.5
                        P[i * N + j] = v
                        P[j * N + i] = v
                if has_normal:                 # the mirror image of a planar array
                    for c in range(3):
                        rel[c] = x[c] - centre[c]
                    h = dot(fp, 3, normal, rel)
                    if h < 0.0:
                        for c in range(3):
                            x[c] -= 2.0 * h * normal[c]
                        hv = dot(fp, 3, normal, x[3:])
                        for c in range(3):
                            x[3 + c] -= 2.0 * hv * normal[c]
                        reflected[k] = True
                starved = starved + 1 if (n_ok < min_anchors or mismatch) else 0
            p00 = P[0]
            if lost or p00 != p00 or abs(x[0]) > 1e3:       # numerically lost
                starved = reinit_after
        for c in range(N):
            out_x[k, c] = x[c]
            out_P[k, c] = P[c * N + c]
        k += 1
    starved_box[0] = starved
    return k
