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
}


def defaults():
    return {key: spec[0] for key, spec in SETTINGS.items()}
