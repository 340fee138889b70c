"""Direct Simulation Monte Carlo of homogeneous granular gases.

:class:`DSMC` solves the homogeneous Enskog-Boltzmann equation for smooth
inelastic spheres (3D) or disks (2D) with the engine's collision rules
(:class:`granulargas.engine.CollisionRule`: elastic, constant eps,
viscoelastic eps(g_n) from the same restitution table and pair prefactor).
There are no positions: the algorithm is the sequential majorant process
(Kac process; Bird's no-time-counter scheme with one global bound and no
time step), see :mod:`granulargas.dsmc._loop`.
"""

from granulargas.dsmc.simulation import DSMC, collision_solid_angle

__all__ = ["DSMC", "collision_solid_angle"]
