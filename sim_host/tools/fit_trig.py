#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The kernel coefficients of sim_host/src/sim_trig.h: near-minimax (Chebyshev) fits, at 60
digits, of (sin r - r) / r^3 and (cos r - 1 + r^2/2) / r^4 as degree-5 polynomials in z = r^2 on
|r| <= pi/4, and the split of pi/2 into the reduction's parts. Prints them as C hex literals with
each fit's largest error. Needs mpmath (pip install mpmath).

    python3 sim_host/tools/fit_trig.py
"""
import mpmath as mp

mp.mp.dps = 60
Z_MAX = (mp.pi / 4) ** 2
DEGREE = 5


def sin_kernel(z):
    if z == 0:
        return mp.mpf(-1) / 6
    r = mp.sqrt(z)
    return (mp.sin(r) - r) / (r * z)


def cos_kernel(z):
    if z == 0:
        return mp.mpf(1) / 24
    r = mp.sqrt(z)
    return (mp.cos(r) - 1 + z / 2) / (z * z)


def leading_bits(v, bits):
    """v rounded toward zero to its leading ``bits`` significant bits."""
    quantum = mp.mpf(2) ** (mp.floor(mp.log(abs(v), 2)) - bits + 1)
    return mp.floor(v / quantum) * quantum


def main():
    for name, f in (("s", sin_kernel), ("c", cos_kernel)):
        coeffs, err = mp.chebyfit(f, [0, Z_MAX], DEGREE + 1, error=True)
        print(f"/* {name}: largest error of the fit {mp.nstr(err, 3)} */")
        print(", ".join(f"{name}{i + 1} = {float(v).hex()}" for i, v in enumerate(reversed(coeffs))))
    rest = mp.pi / 2
    parts = []
    for exact in (True, True, False, False):  # k * part exact for |k| < 2^20: 33 bits
        part = leading_bits(rest, 33) if exact else mp.mpf(float(rest))
        parts.append(part)
        rest -= part
    print("p1, p2, p3, p3_tail = " + ", ".join(float(p).hex() for p in parts))
    print(f"two_over_pi = {float(2 / mp.pi).hex()}")


if __name__ == "__main__":
    main()
