"""Which sliced contours become wires: the `contours` rule of a plane (docs/formats.md)."""

RULES = ("largest", "all")


def pick(contours, rule="largest", plane="plane"):
    """Indices into `contours` (already sorted longest first) chosen by `rule`:
    "largest" (the first), "all", or a list of indices. ValueError names the plane and index."""
    count = len(contours)
    if rule == "largest":
        return [0] if count else []
    if rule == "all":
        return list(range(count))
    if isinstance(rule, (list, tuple)):
        chosen = []
        for k in rule:
            if isinstance(k, bool) or not isinstance(k, int):
                raise ValueError(f"plane {plane}: contour index {k!r} is not a whole number")
            if not count:  # the plane misses the mesh (moved off it since the contour was picked)
                raise ValueError(f"plane {plane} cuts no contour of the mesh now (contour index {k} does not exist)")
            if not 0 <= k < count:
                raise ValueError(f"plane {plane}: contour index {k} does not exist "
                                 f"(the plane cuts {count} contour{'s' if count != 1 else ''})")
            if k not in chosen:
                chosen.append(k)
        return chosen
    raise ValueError(f'plane {plane}: "contours" must be "largest", "all" or a list of indices, got {rule!r}')
