"""The solver settings a scene file may give under "settings": one table with defaults, bounds
and units, read by the scene loader and the add-on's properties alike."""

# key: (default, minimum, maximum, unit, description)
SETTINGS = {
    "min_segment": (0.015, 0.001, 1.0, "m",
                    "Shortest distance between two bends the machine can make (l_min)"),
    "max_bend_deg": (120.0, 1.0, 180.0, "deg", "Largest bend the machine can make"),
    "min_bend_deg": (1.0, 0.0, 45.0, "deg", "Smallest bend the machine makes reliably"),
    "contact_angle_deg": (120.0, 30.0, 175.0, "deg",
                          "Angle between a wire's two edges at an interlocked crossing (the kink)"),
    "torque_fraction": (None, 0.01, 1.0, "",
                        "Share of the wire's plastic-limit torque the design may use (default: the "
                        "least that holds the load factor)"),
    "load_factor": (3.0, 0.1, 1000.0, "",
                    "Times its own weight the sculpture should hold in each of the six directions; "
                    "the least pre-stress (torque fraction) that does so is used"),
    "weld_tolerance": (None, 0.0, 0.01, "m",
                       "Mesh vertices closer than this are merged (default: 1e-7 of the mesh size)"),
    # the layering's search knobs (docs/method-layering.md); unit "bool" / "int": not a number of
    # a physical unit, parsed as such by the scene loader
    "in_plane_tiebreak": (False, None, None, "bool",
                          "Among equally good hook patterns, prefer those in which every wire balances "
                          "in its own plane (slower on boxy models)"),
    "max_nodes": (200000, 0, 100000000, "int",
                  "Layering search budget in candidate assemblies; when reached the result is "
                  "reported as \"search incomplete\" (0: no limit)"),
    "relayer_rounds": (8, 0, 100, "int",
                       "How many times to layer again after the target shape could not realise a hook, "
                       "with that hook forbidden; above 0, hooks at crossings too close along a wire to bend "
                       "are forbidden from the start (0: layer once, with every hook)"),
    "max_solve_seconds": (600.0, 0.001, 86400.0, "s",
                          "Wall-clock budget of one solve, every stage and round included; past it the "
                          "solve stops with a message naming this key"),
    # the plane assistant (plane_search/); unit "choice": one of CHOICES[key]
    "plane_search": ("off", None, None, "choice",
                     "off: the planes as given; nearby: when they give no stable design, the least change "
                     "of them that does; auto: planes proposed from the mesh alone (\"planes\" may be [])"),
    "plane_count": (5, 2, 12, "int", "How many planes plane_search \"auto\" proposes"),
}

# the allowed values of the "choice" keys
CHOICES = {"plane_search": ("off", "nearby", "auto")}

# the keys whose values are not floats
BOOLEAN = tuple(k for k, spec in SETTINGS.items() if spec[3] == "bool")
INTEGER = tuple(k for k, spec in SETTINGS.items() if spec[3] == "int")


def defaults():
    return {key: spec[0] for key, spec in SETTINGS.items()}
