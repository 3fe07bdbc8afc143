"""glibc's ``exp``, inlined for the particle filter's compiled kernels (seed 002 §III.C).

:func:`libc_exp` is the C library's algorithm (ARM optimized-routines, as in glibc ≥ 2.28
and musl) written out so that numba inlines it, and its pieces (:data:`_EXP_TAB`, the
constants and the bit casts) let :mod:`gaitval.track.pf_kernels` vectorise it over the
particles; the same value as the library's ``exp`` (and ``np.exp``) on x86-64 with FMA, bit
for bit (tests/test_pf_kernel.py).  Imported only by :mod:`gaitval.track.pf_kernels` (numba
is imported by the PF only).
"""
from __future__ import annotations

import math
import struct
from fractions import Fraction

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def _fma(typingctx, a, b, c):
    """IEEE fused multiply-add a·b + c, one rounding (``llvm.fma.f64``)."""
    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]),
                                            "llvm.fma.f64")
        return builder.call(fn, args)
    return types.float64(types.float64, types.float64, types.float64), codegen


@intrinsic
def _bits(typingctx, a):
    """The bits of a float64 as uint64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.uint64(types.float64), codegen


@intrinsic
def _double(typingctx, a):
    """A uint64's bits as float64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.uint64), codegen


def _exp_table() -> np.ndarray:
    """2^(i/128) = H_i·(1 + T_i), i < 128: [bits(T_i), bits(H_i) − (i << 45)] per i, H_i the
    nearest double, T_i the nearest double to the relative rest (the table of glibc's and
    musl's exp, ``__exp_data.tab``; computed here from a 200-bit 2^(1/128))."""
    P = 200
    base = 1 << (1 + 128 * P)
    for _ in range(7):
        base = math.isqrt(base)                       # 2^(1/128)·2^P, error < 2^-190
    bits = lambda d: struct.unpack("<Q", struct.pack("<d", d))[0]   # noqa: E731
    tab, acc = np.empty(256, np.uint64), 1 << P
    for i in range(128):
        t = Fraction(acc, 1 << P)
        H = float(t)
        tab[2 * i] = bits(float((t - Fraction(H)) / Fraction(H)))
        tab[2 * i + 1] = (bits(H) - (i << 45)) % 2 ** 64
        acc = acc * base >> P
    return tab


_EXP_TAB = _exp_table()
_INVLN2N = float.fromhex("0x1.71547652b82fep0") * 128      # N/ln2, N = 128
_NEGLN2HIN = -float.fromhex("0x1.62e42fefa0000p-8")         # −ln2/N, high part
_NEGLN2LON = -float.fromhex("0x1.cf79abc9e3b3ap-47")        # −ln2/N, low part
_SHIFT = float.fromhex("0x1.8p52")
_C2, _C3, _C4, _C5 = (float.fromhex(h) for h in (
    "0x1.ffffffffffdbdp-2", "0x1.555555555543cp-3", "0x1.55555cf172b91p-5",
    "0x1.1111167a4d017p-7"))


@njit(cache=True)
def libc_exp(x):
    """exp(x), bit for bit the value of glibc ≥ 2.28's ``exp`` on x86-64 with FMA (the one
    ``np.exp`` and ``math.exp`` call here): ARM's optimized-routines algorithm, x = k ln2/128
    + r, 2^(k/128) from the table, exp(r) − 1 by a degree-5 polynomial, with glibc's fused
    multiply-adds.  Inlined, about twice as fast as the library call; |x| outside
    [2^-54, 512) and NaN go to the library (``math.exp``).  tests/test_pf_kernel.py checks it
    against ``np.exp``."""
    ax = abs(x)
    if not (ax < 512.0 and ax >= 5.551115123125783e-17):       # 2^-54 ≤ |x| < 512
        return math.exp(x)
    kd = _INVLN2N * x + _SHIFT
    ki = _bits(kd)
    kd -= _SHIFT
    r = _fma(kd, _NEGLN2LON, _fma(kd, _NEGLN2HIN, x))
    i = (ki & np.uint64(127)) << np.uint64(1)
    tail = _double(_EXP_TAB[i])
    scale = _double(_EXP_TAB[i + np.uint64(1)] + (ki << np.uint64(45)))
    r2 = r * r
    tmp = _fma(r2 * r2, _fma(r, _C5, _C4), _fma(r2, _fma(r, _C3, _C2), tail + r))
    return _fma(scale, tmp, scale)
