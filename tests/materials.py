"""Config text shared by tests: materials of the ``[collision.material]`` route."""

#: a soft rubber-like material: contact time / mean free time ~ 0.1 at packing 0.1 (3D, T0 = 1)
RUBBER = """[collision.material]
young_modulus = 1e6
poisson_ratio = 0.3
dissipation_time = 1e-5
diameter = 0.01
density = 1000
speed_unit = 0.5
"""
