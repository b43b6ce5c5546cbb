"""Closure gaps as figures users read, and how to close each loop.

A closed wire is cut (its `cut`) and bent to its rest shape, whose two ends stand `closure_gap`
apart (m, the forces stage); assembling the sculpture springs them together, since the target
shape is closed. The gap is shown in mm and as a share of the wire's length, and the assembly
guide says how to join the ends (docs/user-guide.md, "Closing the loops"):

- "sleeve": gap up to SLEEVE_MAX_SHARE of the wire's length: the ends meet end to end once every
  wire is in; slide a sleeve (a crimp or brass tube whose bore fits the wire) onto one end before
  assembly and over the joint after it. The model puts no force or torque on the cut (it is a free
  end, docs/method-forces.md §4), so the sleeve only keeps the ends aligned.
- "overlap": a larger gap: the ends travel far as the last wires go in and the machine's error
  grows with the bends (the paper, Sec. 6), so leave OVERLAP_DIAMETERS wire diameters of extra
  wire past the cut, lay the ends side by side and bind or solder them. The bend program stops at
  the cut unless the machine profile's closed_overlap (m) makes it feed that much past the cut
  (fab/export.py); the advice then names that overlap instead.
"""
SLEEVE_MAX_SHARE = 0.05
OVERLAP_DIAMETERS = 10


def closure(wire):
    """(gap in m, gap / wire length) for a closed wire with a rest shape, else None."""
    if not wire.get("closed") or "closure_gap" not in wire or not wire.get("length"):
        return None
    return wire["closure_gap"], wire["closure_gap"] / wire["length"]


def closure_text(wire):
    """"116.0 mm (14.8% of its length)", or None (see closure)."""
    figures = closure(wire)
    if figures is None:
        return None
    gap, share = figures
    return f"{gap * 1000:.1f} mm ({share * 100:.1f}% of its length)"


def closure_advice(wire, wire_diameter, overlap=0.0):
    """(method, sentence) for joining the ends of a closed wire: method "sleeve" or "overlap" (see
    the module's rule), or None without a rest shape. `overlap`: m of wire the bend program feeds
    past the cut (the profile's closed_overlap, 0: it stops at the cut)."""
    figures = closure(wire)
    if figures is None:
        return None
    gap, share = figures
    if share <= SLEEVE_MAX_SHARE:
        trim = (f"trim the {overlap * 1000:.0f} mm the bend program fed past the cut, then " if overlap > 0 else "")
        return "sleeve", (f"its ends stand {gap * 1000:.1f} mm apart ({share * 100:.1f}% of its length) and close "
                          f"as the wires go in: {trim}slide a sleeve for {wire_diameter * 1000:g} mm wire onto one end "
                          "before assembly and over the joint once the ends meet")
    if overlap > 0:
        extra = (f"the bend program feeds {overlap * 1000:.0f} mm of extra wire past the cut (the machine "
                 "profile's closed_overlap)")
    else:
        extra = (f"leave {OVERLAP_DIAMETERS * wire_diameter * 1000:.0f} mm of extra wire past the cut (the bend "
                 "program stops at the cut; the machine profile's closed_overlap can feed it)")
    return "overlap", (f"its ends stand {gap * 1000:.1f} mm apart ({share * 100:.1f}% of its length) and must be "
                       f"sprung together as the last wires go in: {extra}, lay the ends side by side and bind or "
                       "solder them")
