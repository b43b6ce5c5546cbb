"""Wire materials: the paper's Table 1 (3 mm wires) plus densities and shear moduli. SI units."""

# k_b (N m^2), plastic-limit torque (N m), friction coefficient, density (kg/m^3), shear modulus
# G (Pa, for the out-of-plane deflection's twist, docs/method-forces.md §11): handbook values,
# steel 79.3 GPa (carbon spring steel; E 200 GPa, Poisson 0.29), brass 39 GPa (CuZn37 half-hard;
# E about 100 GPa, Poisson 0.34). The paper measured only k_b, the torque and μ (Table 1).
PRESETS = {
    "steel": {"name": "steel", "wire_diameter": 0.003, "bending_stiffness": 0.73,
              "max_torque": 1.77, "friction": 0.32, "density": 7850.0, "shear_modulus": 79.3e9},
    "brass": {"name": "brass", "wire_diameter": 0.003, "bending_stiffness": 0.42,
              "max_torque": 1.30, "friction": 0.23, "density": 8500.0, "shear_modulus": 39.0e9},
}

# key: (unit, lower bound exclusive, upper bound inclusive)
FIELDS = {
    "wire_diameter": ("m", 0.0, 0.05),
    "bending_stiffness": ("N m^2", 0.0, 1e4),
    "max_torque": ("N m", 0.0, 1e4),
    "friction": ("", 0.0, 10.0),
    "density": ("kg/m^3", 1.0, 1e5),  # the core's range: beyond it the load LP's numbers break GLPK
    "shear_modulus": ("Pa", 0.0, 1e12),
}
REQUIRED = ("wire_diameter", "bending_stiffness", "max_torque", "friction")
