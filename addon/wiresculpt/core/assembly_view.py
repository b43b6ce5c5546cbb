"""What the assembly slider (Show After Step) shows: the wires added up to a step, and so the
crossing markers, cut handles, machine-preview ghosts and overlays that belong to them (bpy-free;
blend/results hides the objects, ui/overlay draws only these wires' lines)."""


def visible(wire_ids, steps, step):
    """The ids of `wire_ids` present after assembly step `step` (1-based) of `steps` (lists of wire
    ids, the design's `assembly_steps`); every id when `step` is 0 or there are no steps."""
    if step <= 0 or not steps:
        return set(wire_ids)
    return {w for s in steps[:step] for w in s}


def shown_lines(preview, ids, steps, step):
    """The entries of `preview` (one per wire, its id at the same place in `ids`) whose wire is
    visible after `step` (visible). A preview without its ids (older state) is shown whole."""
    if len(ids) != len(preview):
        return list(preview)
    keep = visible(ids, steps, step)
    return [entry for entry, wire in zip(preview, ids) if wire in keep]
