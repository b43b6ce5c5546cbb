"""A figure said against the limit it breaks ("turns 60.01 deg, more than 60.00 deg"): both written
with the same precision, and with as many digits as it takes for the two to read differently, so
that a violation never reads "60.0 deg, more than 60.0 deg" or "60.01 deg, more than 60.0 deg". The
native messages do the same (native/src/figures.hpp). bpy-free.
"""
import math

# A double has at most 17 significant digits: with that many, two different numbers print differently.
MOST_DIGITS = 17


def versus(value, limit, digits=1, style="f"):
    """(value text, limit text): `value` and the `limit` it breaks written alike, `style` "f" with
    `digits` decimals or "g" with `digits` significant digits, one more digit at a time while |value|
    and |limit| would read the same (up to MOST_DIGITS). `value` keeps its sign (a bend to the right
    is negative); like the checks, the comparison is of magnitudes. Equal figures (no violation)
    keep `digits`."""
    d = digits
    while (d < MOST_DIGITS and math.isfinite(value) and math.isfinite(limit) and abs(value) != abs(limit)
           and f"{abs(value):.{d}{style}}" == f"{abs(limit):.{d}{style}}"):
        d += 1
    return f"{value:.{d}{style}}", f"{limit:.{d}{style}}"


def mass_text(grams):
    """A mass a maker reads: "136 g" below a kilogram, "37.7 kg" from one (a load capacity or a
    sculpture's weight can be either)."""
    if abs(grams) >= 999.5:  # would round to "1000 g"
        return f"{grams / 1000:.1f} kg"
    return f"{grams:.0f} g"
