#!/usr/bin/env python3
"""Tabulates a concrete's tensile dynamic increase factor (DIF) as a case file's
`rate_dependence` table (docs/case-file.md, [[material]]; docs/physics.md 1.2, "Rate dependence").

Forms (f_c: the static compressive strength, f_c0 = 10 MPa):
  ceb-fip       CEB-FIP Model Code 1990, 2.1.6.4: DIF = (e/e_s)^(1.016 d) up to 30/s, then
                b (e/e_s)^(1/3); e_s = 3e-6/s, d = 1 / (10 + 6 f_c/f_c0), log10 b = 7.11 d - 2.33.
  malvar-ross   Malvar & Ross (1998), ACI Mater. J. 95(6), the same fitted to spall tests:
                DIF = (e/e_s)^d up to 1/s, then b (e/e_s)^(1/3); e_s = 1e-6/s,
                d = 1 / (1 + 8 f_c/f_c0), log10 b = 6 d - 2.
Factors below 1 (rates under e_s) are clamped to 1: the table holds dynamic increases only.

  scripts/dif_table.py --fc 48e6 [--form malvar-ross] [--from 1e-6 --to 1e4 --points 12]
"""
import argparse
import math


def dif(rate, fc, form):
    fc0 = 10e6
    if form == "ceb-fip":
        rate_s, delta = 3e-6, 1.0 / (10.0 + 6.0 * fc / fc0)
        beta, knee, exponent = 10 ** (7.11 * delta - 2.33), 30.0, 1.016 * delta
    else:
        rate_s, delta = 1e-6, 1.0 / (1.0 + 8.0 * fc / fc0)
        beta, knee, exponent = 10 ** (6.0 * delta - 2.0), 1.0, delta
    ratio = rate / rate_s
    value = ratio ** exponent if rate <= knee else beta * ratio ** (1.0 / 3.0)
    return max(1.0, value)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--fc", type=float, required=True, help="static compressive strength (Pa)")
    p.add_argument("--form", choices=["ceb-fip", "malvar-ross"], default="ceb-fip")
    p.add_argument("--from", dest="lo", type=float, default=1e-6, help="lowest rate (1/s)")
    p.add_argument("--to", dest="hi", type=float, default=1e4, help="highest rate (1/s)")
    p.add_argument("--points", type=int, default=12, help="table entries (at most 16)")
    a = p.parse_args()
    if not 2 <= a.points <= 16 or not 0 < a.lo < a.hi:
        p.error("need 2 to 16 points and 0 < --from < --to")
    step = (math.log10(a.hi) - math.log10(a.lo)) / (a.points - 1)
    rates = [10 ** (math.log10(a.lo) + k * step) for k in range(a.points)]
    factors = [dif(r, a.fc, a.form) for r in rates]
    print(f"# {a.form} tensile DIF, f_c = {a.fc / 1e6:g} MPa")
    print("rate_dependence = { strain_rate = [" + ", ".join(f"{r:.4g}" for r in rates) +
          "], strength = [" + ", ".join(f"{f:.4g}" for f in factors) + "] }")


if __name__ == "__main__":
    main()
